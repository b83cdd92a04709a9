#include "testkit/rays_scene.hpp"

#include "testkit/portable_random.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace batchcol::testkit {

RaysScene make_rays_scene(const RaysSceneSpec& spec) {
  PortableRandom rng(spec.seed);
  RaysScene s;
  s.table = std::make_shared<ShapeTable>();
  constexpr double kRadius = 0.5;
  if (spec.shapes == "hull") {
    for (int k = 0; k < 16; ++k) {
      std::vector<Eigen::Vector3d> points;
      for (int i = 0; i < spec.hull_vertices; ++i) points.push_back(kRadius * rng.unit_vector());
      s.table->add(Shape::convex(points));
    }
  } else {
    for (int k = 0; k < 4; ++k) {
      const double r = rng.uniform(0.3, 0.5);
      s.table->add(Shape::sphere(r));
      s.table->add(Shape::capsule(0.5 * r, r));
      s.table->add(Shape::box(rng.uniform(0.2, 0.4), rng.uniform(0.2, 0.4), rng.uniform(0.2, 0.4)));
      s.table->add(Shape::cylinder(0.7 * r, 0.7 * r));
    }
  }
  // N pi r^2 L / L^3 = fill: a ray crossing the cube (side L) meets `fill` objects on average.
  const double side = kRadius * std::sqrt(double(spec.objects) * M_PI / spec.fill);
  s.half_extent = 0.5 * side;
  s.scene = std::make_unique<Scene>(s.table);
  s.handles.reserve(static_cast<std::size_t>(spec.objects));
  for (std::int64_t i = 0; i < spec.objects; ++i) {
    const Eigen::Vector3d t(rng.uniform(-s.half_extent, s.half_extent), rng.uniform(-s.half_extent, s.half_extent),
                            rng.uniform(-s.half_extent, s.half_extent));
    s.handles.push_back(s.scene->add(static_cast<std::uint32_t>(rng.index(s.table->size())), {t, rng.rotation()}));
  }
  return s;
}

RaysScene make_rays_scene(BatchFile&& file) {
  RaysScene s;
  s.table = std::make_shared<ShapeTable>(std::move(file.shapes));
  s.scene = std::make_unique<Scene>(s.table);
  s.handles.reserve(file.objects.size());
  for (const BatchFile::Object& o : file.objects) {
    s.handles.push_back(s.scene->add(o.shape, o.pose));
    s.half_extent = std::max(s.half_extent, o.pose.translation.cwiseAbs().maxCoeff());
  }
  return s;
}

RayBatch make_crossing_rays(std::int64_t n, double half_extent, std::uint64_t seed) {
  PortableRandom rng(seed ^ 0x9e3779b97f4a7c15ull);
  RayBatch rays;
  rays.reserve(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i) {
    const Eigen::Vector3d o = 2.0 * half_extent * rng.unit_vector();
    const Eigen::Vector3d target(rng.uniform(-half_extent, half_extent), rng.uniform(-half_extent, half_extent),
                                 rng.uniform(-half_extent, half_extent));
    rays.add(o, (target - o).normalized(), INFINITY);
  }
  return rays;
}

void move_objects(RaysScene& s, double step, std::uint64_t seed) {
  PortableRandom rng(seed);
  for (ObjectHandle h : s.handles) {
    Pose p = s.scene->pose(h);
    p.translation += step * rng.unit_vector();
    const Eigen::Quaterniond dq(Eigen::AngleAxisd(step, rng.unit_vector()));
    p.rotation = (dq * p.rotation).normalized();
    s.scene->set_pose(h, p);
  }
}

}  // namespace batchcol::testkit
