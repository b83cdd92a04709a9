#include "peers/fcl_adapter.hpp"

#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/cone.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/ellipsoid.h>
#include <fcl/geometry/shape/halfspace.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/detail/gjk_solver_indep.h>
#include <fcl/narrowphase/detail/gjk_solver_libccd.h>
#include <fcl/narrowphase/distance.h>

#include <array>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

namespace batchcol::peers {
namespace {

fcl::Transform3d to_fcl(const Pose& p) {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.linear() = p.rotation.toRotationMatrix();
  tf.translation() = p.translation;
  return tf;
}

/// A flat or solid polytope as fcl::Convex; faces are stored as [3, i, j, k, 3, ...].
std::shared_ptr<fcl::Convexd> make_convex(const std::vector<Eigen::Vector3d>& vertices,
                                          const std::vector<std::array<std::uint32_t, 3>>& faces) {
  auto v = std::make_shared<std::vector<fcl::Vector3d>>(vertices.begin(), vertices.end());
  auto f = std::make_shared<std::vector<int>>();
  for (const auto& t : faces) f->insert(f->end(), {3, int(t[0]), int(t[1]), int(t[2])});
  return std::make_shared<fcl::Convexd>(v, static_cast<int>(faces.size()), f);
}

std::shared_ptr<fcl::Convexd> triangle_as_convex(const Shape& s) {
  return make_convex({s.triangle[0], s.triangle[1], s.triangle[2]}, {{{0, 1, 2}}, {{0, 2, 1}}});
}

/// Sizes: FCL boxes take full side lengths, capsules/cylinders/cones full axis lengths (lz), centred on the
/// origin like batchcol's; the FCL cone has its apex at +lz/2 as batchcol's does.
std::shared_ptr<fcl::CollisionGeometryd> make_geometry(const Shape& s) {
  if (s.inflation != 0.0) throw std::invalid_argument("FCL adapter: inflated shapes are not supported");
  const Eigen::Vector3d& z = s.size;
  switch (s.type) {
    case ShapeType::sphere: return std::make_shared<fcl::Sphered>(z.x());
    case ShapeType::capsule: return std::make_shared<fcl::Capsuled>(z.x(), 2 * z.y());
    case ShapeType::box: return std::make_shared<fcl::Boxd>(2 * z);
    case ShapeType::cylinder: return std::make_shared<fcl::Cylinderd>(z.x(), 2 * z.y());
    case ShapeType::cone: return std::make_shared<fcl::Coned>(z.x(), 2 * z.y());
    case ShapeType::ellipsoid: return std::make_shared<fcl::Ellipsoidd>(z);
    case ShapeType::convex: return make_convex(s.hull->vertices, s.hull->faces);
    case ShapeType::triangle: return triangle_as_convex(s);
    case ShapeType::halfspace: return std::make_shared<fcl::Halfspaced>(z, s.offset);
  }
  throw std::invalid_argument("FCL adapter: unknown shape type");
}

/// Calls f with the concrete FCL shape of s (needed by the solver's templated triangle functions).
template <class F> auto visit_shape(const Shape& s, F&& f) {
  const auto g = make_geometry(s);
  switch (s.type) {
    case ShapeType::sphere: return f(static_cast<const fcl::Sphered&>(*g));
    case ShapeType::capsule: return f(static_cast<const fcl::Capsuled&>(*g));
    case ShapeType::box: return f(static_cast<const fcl::Boxd&>(*g));
    case ShapeType::cylinder: return f(static_cast<const fcl::Cylinderd&>(*g));
    case ShapeType::cone: return f(static_cast<const fcl::Coned&>(*g));
    case ShapeType::ellipsoid: return f(static_cast<const fcl::Ellipsoidd&>(*g));
    case ShapeType::halfspace: return f(static_cast<const fcl::Halfspaced&>(*g));
    case ShapeType::convex:
    case ShapeType::triangle: break;
  }
  return f(static_cast<const fcl::Convexd&>(*g));
}

template <class F> auto with_solver(FclSolver solver, double tolerance, F&& f) {
  if (solver == FclSolver::libccd) {
    fcl::detail::GJKSolver_libccd<double> s;
    s.distance_tolerance = tolerance;
    return f(s);
  }
  fcl::detail::GJKSolver_indep<double> s;
  s.gjk_tolerance = tolerance;
  return f(s);
}

fcl::GJKSolverType to_fcl(FclSolver solver) {
  return solver == FclSolver::libccd ? fcl::GST_LIBCCD : fcl::GST_INDEP;
}

/// A pair with a triangle, seen as (other shape, triangle). `swapped` is true when the triangle is shape a.
struct TrianglePair {
  const Shape& other;
  fcl::Transform3d other_tf;
  fcl::Vector3d p0, p1, p2;
  fcl::Transform3d triangle_tf;
  bool swapped;
};

TrianglePair triangle_pair(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
  const bool swapped = b.type != ShapeType::triangle;
  const Shape& tri = swapped ? a : b;
  return {swapped ? b : a, to_fcl(swapped ? pb : pa), tri.triangle[0], tri.triangle[1], tri.triangle[2],
          to_fcl(swapped ? pa : pb), swapped};
}

bool has_triangle(const Shape& a, const Shape& b) {
  return a.type == ShapeType::triangle || b.type == ShapeType::triangle;
}

// fcl::collide on two built geometries; the depth of the first contact when asked and colliding.
bool geometry_collide(const fcl::CollisionGeometryd& ga, const Pose& pa, const fcl::CollisionGeometryd& gb,
                      const Pose& pb, FclSolver solver, bool want_depth, double& depth) {
  fcl::CollisionRequestd request(1, want_depth);
  request.gjk_solver_type = to_fcl(solver);
  fcl::CollisionResultd result;
  fcl::collide(&ga, to_fcl(pa), &gb, to_fcl(pb), request, result);
  if (result.isCollision() && want_depth) depth = result.getContact(0).penetration_depth;
  return result.isCollision();
}

// fcl::distance on two built geometries: fills the distance and the nearest points.
void geometry_distance(const fcl::CollisionGeometryd& ga, const Pose& pa, const fcl::CollisionGeometryd& gb,
                       const Pose& pb, FclSolver solver, double tolerance, PeerAnswer& out) {
  fcl::DistanceRequestd request(true, true, 0.0, 0.0, tolerance, to_fcl(solver));
  fcl::DistanceResultd result;
  out.distance = fcl::distance(&ga, to_fcl(pa), &gb, to_fcl(pb), request, result);
  out.point_a = result.nearest_points[0];
  out.point_b = result.nearest_points[1];
}

}  // namespace

const char* to_string(FclSolver solver) { return solver == FclSolver::libccd ? "libccd" : "indep"; }

PeerAnswer fcl_collide(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, FclSolver solver,
                       bool want_depth) {
  PeerAnswer out;
  try {
    double depth = 0;
    if (has_triangle(a, b)) {
      const TrianglePair t = triangle_pair(a, pa, b, pb);
      fcl::Vector3d contact, normal;
      out.collide = with_solver(solver, 1e-6, [&](const auto& s) {
        return visit_shape(t.other, [&](const auto& g) {
          return s.shapeTriangleIntersect(g, t.other_tf, t.p0, t.p1, t.p2, t.triangle_tf, &contact, &depth, &normal);
        });
      });
    } else {
      out.collide = geometry_collide(*make_geometry(a), pa, *make_geometry(b), pb, solver, want_depth, depth);
    }
    if (out.collide && want_depth) out.distance = -depth;
    out.ok = true;
  } catch (const std::exception&) {
    out.ok = false;
  }
  return out;
}

PeerAnswer fcl_distance(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, FclSolver solver,
                        double tolerance) {
  PeerAnswer out;
  if (a.type == ShapeType::halfspace || b.type == ShapeType::halfspace) return out;
  try {
    if (has_triangle(a, b)) {
      const TrianglePair t = triangle_pair(a, pa, b, pb);
      double d = -1;
      fcl::Vector3d p_other, p_tri;
      const bool separated = with_solver(solver, tolerance, [&](const auto& s) {
        return visit_shape(t.other, [&](const auto& g) {
          return s.shapeTriangleDistance(g, t.other_tf, t.p0, t.p1, t.p2, t.triangle_tf, &d, &p_other, &p_tri);
        });
      });
      if (!separated) {  // FCL's triangle functions compute no penetration depth: a boolean answer only
        out.ok = true;
        out.collide = true;
        return out;
      }
      out.distance = d;
      out.point_a = t.swapped ? p_tri : p_other;
      out.point_b = t.swapped ? p_other : p_tri;
    } else {
      geometry_distance(*make_geometry(a), pa, *make_geometry(b), pb, solver, tolerance, out);
    }
    out.collide = out.distance <= 0;
    out.ok = true;
  } catch (const std::exception&) {
    out.ok = false;
  }
  return out;
}

struct FclShapeCache::Impl {
  std::vector<Shape> shapes;
  std::vector<std::shared_ptr<fcl::CollisionGeometryd>> geometries;  // null for triangles and halfspaces
};

FclShapeCache::FclShapeCache(const ShapeTable& shapes) : impl_(std::make_unique<Impl>()) {
  impl_->shapes = shapes.shapes();
  for (const Shape& s : impl_->shapes) {
    const bool simple = s.type != ShapeType::triangle && s.type != ShapeType::halfspace;
    impl_->geometries.push_back(simple ? make_geometry(s) : nullptr);
  }
}

FclShapeCache::~FclShapeCache() = default;

PeerAnswer FclShapeCache::collide(std::uint32_t a, const Pose& pa, std::uint32_t b, const Pose& pb,
                                  FclSolver solver) const {
  const auto &ga = impl_->geometries.at(a), &gb = impl_->geometries.at(b);
  if (!ga || !gb) return fcl_collide(impl_->shapes[a], pa, impl_->shapes[b], pb, solver, false);
  PeerAnswer out;
  try {
    double unused_depth = 0;
    out.collide = geometry_collide(*ga, pa, *gb, pb, solver, false, unused_depth);
    out.ok = true;
  } catch (const std::exception&) {
    out.ok = false;
  }
  return out;
}

PeerAnswer FclShapeCache::distance(std::uint32_t a, const Pose& pa, std::uint32_t b, const Pose& pb,
                                   FclSolver solver, double tolerance) const {
  const auto &ga = impl_->geometries.at(a), &gb = impl_->geometries.at(b);
  if (!ga || !gb) return fcl_distance(impl_->shapes[a], pa, impl_->shapes[b], pb, solver, tolerance);
  PeerAnswer out;
  try {
    geometry_distance(*ga, pa, *gb, pb, solver, tolerance, out);
    out.collide = out.distance <= 0;
    out.ok = true;
  } catch (const std::exception&) {
    out.ok = false;
  }
  return out;
}

}  // namespace batchcol::peers
