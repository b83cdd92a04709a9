#include "crosscheck/crosscheck_pairs.hpp"

#include "crosscheck/certificates.hpp"

#include <algorithm>
#include <cmath>

namespace batchcol::crosscheck {
namespace {

using testing::uniform;

Pose random_pose(testing::Rng& rng) {
  return {Eigen::Vector3d(uniform(rng, -0.5, 0.5), uniform(rng, -0.5, 0.5), uniform(rng, -0.5, 0.5)),
          testing::random_rotation(rng)};
}

double draw_gap(testing::Rng& rng, double width_a, double width_b) {
  if (uniform(rng, 0, 1) < 0.5) return std::exp(uniform(rng, std::log(1e-5), std::log(0.2)));
  return -uniform(rng, 0.0, 0.5) * (width_a + width_b);
}

}  // namespace

CrossPairs make_pairs(std::uint64_t seed, ShapeType primary, const std::vector<ShapeType>& partners,
                      std::size_t count) {
  testing::Rng rng(seed);
  CrossPairs out;
  out.batch.reserve(count);
  out.plane_gap.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    Shape a = testing::random_shape(rng, primary);
    Shape b = testing::random_shape(rng, partners[rng.index(partners.size())]);
    if (uniform(rng, 0, 1) < 0.5) std::swap(a, b);
    Pose pa = random_pose(rng);
    Pose pb{Eigen::Vector3d::Zero(), testing::random_rotation(rng)};
    double gap = 0;
    if (a.type == ShapeType::halfspace || b.type == ShapeType::halfspace) {
      // Put the bounded shape at signed distance `gap` from the plane, anywhere along it.
      const bool a_is_plane = a.type == ShapeType::halfspace;
      const Shape& plane_shape = a_is_plane ? a : b;
      const Shape& body = a_is_plane ? b : a;
      Pose& plane_pose = a_is_plane ? pa : pb;
      Pose& body_pose = a_is_plane ? pb : pa;
      plane_pose = random_pose(rng);
      body_pose.translation.setZero();
      const WorldPlane plane = world_plane(plane_shape, plane_pose);
      const double width = world_extent(body, body_pose, plane.normal) + world_extent(body, body_pose, -plane.normal);
      gap = draw_gap(rng, width, width);
      const Eigen::Vector3d along = plane_pose.translation + 0.3 * testing::random_unit_vector(rng);
      body_pose.translation = along + (gap - halfspace_signed_distance(plane, body, {along, body_pose.rotation})) *
                                          plane.normal;
    } else {
      const Eigen::Vector3d u = testing::random_unit_vector(rng);
      const double width_a = world_extent(a, pa, u) + world_extent(a, pa, -u);
      const double width_b = world_extent(b, pb, u) + world_extent(b, pb, -u);
      gap = draw_gap(rng, width_a, width_b);
      // Start b at a's position, where min_{y in b} <u, y> = -world_extent(b, pb, -u), then shift it along u so
      // that this minimum becomes max_{x in a} <u, x> + gap.
      pb.translation = pa.translation;
      pb.translation += (world_extent(a, pa, u) + gap + world_extent(b, pb, -u)) * u;
    }
    const auto ia = out.shapes.add(a), ib = out.shapes.add(b);
    out.batch.add(ia, pa, ib, pb);
    out.plane_gap.push_back(gap);
  }
  return out;
}

}  // namespace batchcol::crosscheck
