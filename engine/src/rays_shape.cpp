// cast_rays(): rays against one posed shape each. Spheres, boxes, capsules and (uninflated) hulls run W rays per
// register straight from the batch's arrays (kernels/rays/ray_lanes.hpp; hulls only for the pose, then one lane at a
// time through the scalar hull kernel); a group of W rays that are not all valid and of one of those
// kinds goes ray by ray: through the same lane kernel with one lane (same bits), or, for the other shapes (and
// invalid rays), moved into the shape's local frame (x_local = R^T (x - t)), intersected by the kernel of
// kernels/rays/ray_shape.hpp, and its normal rotated back.
#include "rays_common.hpp"

#include "kernels/rays/ray_lanes.hpp"
#include "ray_prepared.hpp"
#include "shape_table_access.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <string>
#include <type_traits>
#include <vector>

namespace batchcol {
namespace {

using kernels::Mat3;
using kernels::Vec3;

template <class T> using PreparedShapes = detail::PreparedRayShapes<T>;

namespace kr = kernels::rays;

template <class T> kr::LaneShapeTable lane_shapes(const ShapeTable& table, const PreparedShapes<T>& prepared) {
  kr::LaneShapeTable t;
  t.hull_d.assign(table.size(), nullptr);
  t.hull_f.assign(table.size(), nullptr);
  for (std::size_t s = 0; s < table.size(); ++s) {
    const Shape& shape = table[s];
    const OwnedShapeView view(shape);  // the core is read here only
    const kernels::ShapeCore<double> core = kernels::make_core<double>(view.view);
    kr::LaneKind kind = kr::LaneKind::none;
    double a = 0, b = 0, c = 0;
    if (shape.type == ShapeType::sphere) kind = kr::LaneKind::sphere, a = core.radius;
    if (shape.type == ShapeType::capsule) kind = kr::LaneKind::capsule, a = core.radius, b = core.size.y();
    if (shape.type == ShapeType::box && shape.inflation == 0.0)
      kind = kr::LaneKind::box, a = core.size.x(), b = core.size.y(), c = core.size.z();
    if (shape.type == ShapeType::convex && shape.inflation == 0.0) {
      kind = kr::LaneKind::hull, a = shape.bounding_radius();
      if constexpr (std::is_same_v<T, double>) t.hull_d[s] = &prepared.planes[s];
      else t.hull_f[s] = &prepared.planes[s];
    }
    t.kind.push_back(kind), t.a.push_back(a), t.b.push_back(b), t.c.push_back(c);
  }
  return t;
}

struct LaneContext {
  kr::LaneShapeTable shapes;
  kr::LaneRays rays;
  kr::LaneCast wide, single;  // W lanes, 1 lane (same arithmetic)
  int width;
};

template <class T>
void cast_range(const PreparedShapes<T>& prepared, const ShapeRayBatch& b, const kernels::rays::RayGjkSettings& gjk,
                const LaneContext& lanes, int isa, std::size_t begin, std::size_t end, RayResults& r) {
  const RayBatch& rays = b.rays;
  kr::LaneOut out{reinterpret_cast<std::uint8_t*>(r.status.data()), r.hit.data(), r.t.data(), r.normal.x.data(),
                  r.normal.y.data(), r.normal.z.data()};
  const std::size_t w = static_cast<std::size_t>(lanes.width);
  for (std::size_t i = begin; i < end; ++i) {
    if (w > 1 && i + w <= end && lanes.wide(lanes.shapes, lanes.rays, i, out)) {
      i += w - 1;
      continue;
    }
    if (lanes.single(lanes.shapes, lanes.rays, i, out)) continue;
    if (!detail::ray_is_valid(rays, i) || b.shape[i] >= prepared.shapes.size()) continue;
    const Eigen::Quaterniond q(b.rotation.w[i], b.rotation.x[i], b.rotation.y[i], b.rotation.z[i]);
    const Eigen::Vector3d p(b.translation.x[i], b.translation.y[i], b.translation.z[i]);
    if (!is_unit_quaternion(q) || !p.allFinite()) continue;
    const double qn = q.norm();
    const Mat3<T> R = kernels::rotation_matrix<T>(T(q.w() / qn), T(q.x() / qn), T(q.y() / qn), T(q.z() / qn));
    const Vec3<T> o(T(rays.origin.x[i] - p.x()), T(rays.origin.y[i] - p.y()), T(rays.origin.z[i] - p.z()));
    const Vec3<T> d(T(rays.direction.x[i]), T(rays.direction.y[i]), T(rays.direction.z[i]));
    const Vec3<T> ol = kernels::mul_transposed(R, o), dl = kernels::mul_transposed(R, d);
    // t_max rounded up to T, so that no hit inside the requested range is lost.
    T t_max = T(rays.t_max[i]);
    if (double(t_max) < rays.t_max[i]) t_max = std::nextafter(t_max, kernels::rays::infinity<T>());
    const kernels::rays::LocalHit<T> h = kernels::rays::ray_local(prepared.shapes[b.shape[i]], ol, dl, t_max, gjk,
                                                                        kernels::quiet_nan<T>(), isa);
    r.status[i] = h.status == kernels::rays::LocalStatus::converged ? RayStatus::ok : RayStatus::max_iterations;
    if (!h.hit) continue;
    r.hit[i] = 1;
    r.t[i] = double(h.t);
    r.normal.set(i, kernels::mul(R, h.normal).template cast<double>());
  }
}

// The lane kernels of instruction set `isa` (ray_isa_index()), or of the next lower one this build's checks accept
// (resolve_instruction_set() and the kernels' own feature tests agree on this CPU; the fallback only guards a mismatch).
kr::LaneCasts lane_casts_at_most(int isa) {
  for (; isa > 0; --isa)
    if (const kr::LaneCasts c = kr::lane_casts_for(isa); c.width > 0) return c;
  return kr::lane_casts_for(0);
}

template <class T> void cast_all(const ShapeTable& shapes, const ShapeRayBatch& b, const RayOptions& o, RayResults& r) {
  const PreparedShapes<T> prepared(shapes);
  const kernels::rays::RayGjkSettings gjk{o.tolerance, o.max_iterations};
  const int isa = detail::ray_isa_index(o.isa);
  const kr::LaneCasts wide = lane_casts_at_most(isa), single = kr::lane_casts_for(0);
  const bool dbl = std::is_same_v<T, double>;
  const LaneContext lanes{lane_shapes(shapes, prepared),
                          {b.rays.origin.x.data(), b.rays.origin.y.data(), b.rays.origin.z.data(),
                           b.rays.direction.x.data(), b.rays.direction.y.data(), b.rays.direction.z.data(),
                           b.rays.t_max.data(), b.translation.x.data(), b.translation.y.data(),
                           b.translation.z.data(), b.rotation.w.data(), b.rotation.x.data(), b.rotation.y.data(),
                           b.rotation.z.data(), b.shape.data()},
                          dbl ? wide.cast_double : wide.cast_float,
                          dbl ? single.cast_double : single.cast_float,
                          wide.width};
  const std::size_t n = b.size(), chunks = (n + detail::kRayChunk - 1) / detail::kRayChunk;
  detail::run_with_threads(o.threads, [&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks), [&](const tbb::blocked_range<std::size_t>& range) {
      for (std::size_t c = range.begin(); c != range.end(); ++c) {
        const std::size_t begin = c * detail::kRayChunk, end = std::min(n, begin + detail::kRayChunk);
        cast_range(prepared, b, gjk, lanes, isa, begin, end, r);
      }
    });
  });
}

}  // namespace

void cast_rays(const ShapeTable& shapes, const ShapeRayBatch& b, const RayOptions& options, RayResults& results) {
  validate(options);
  detail::check_ray_batch(b.rays);
  const std::size_t n = b.size();
  if (b.shape.size() != n || b.translation.size() != n || b.translation.y.size() != n ||
      b.translation.z.size() != n || b.rotation.size() != n || b.rotation.x.size() != n ||
      b.rotation.y.size() != n || b.rotation.z.size() != n) {
    throw InputError("ShapeRayBatch: shape, translation and rotation must have one entry per ray (" +
                     std::to_string(n) + " rays)");
  }
  detail::size_ray_results(results, n, false);
  if (options.precision == Precision::float32) cast_all<float>(shapes, b, options, results);
  else cast_all<double>(shapes, b, options, results);
}

}  // namespace batchcol
