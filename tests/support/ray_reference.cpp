#include "support/ray_reference.hpp"

#include <algorithm>
#include <cmath>

namespace batchcol::testing {
namespace {

double box_sdf(const Eigen::Vector3d& p, const Eigen::Vector3d& h) {
  const Eigen::Vector3d q = p.cwiseAbs() - h;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

double segment_distance(const Eigen::Vector3d& p, double h) {
  const double z = std::clamp(p.z(), -h, h);
  return (p - Eigen::Vector3d(0, 0, z)).norm();
}

double cylinder_sdf(const Eigen::Vector3d& p, double r, double h) {
  const Eigen::Vector2d q(std::hypot(p.x(), p.y()) - r, std::abs(p.z()) - h);
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

// Distance from p to triangle abc (closest point by region tests on the barycentric coordinates).
double triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double area2 = n.squaredNorm();
  // Projection onto the plane; inside the triangle when all three sub-areas have the sign of n.
  const Eigen::Vector3d q = p - n * (n.dot(p - a) / area2);
  const double u = n.dot((b - q).cross(c - q)), v = n.dot((c - q).cross(a - q)), w = n.dot((a - q).cross(b - q));
  if (u >= 0 && v >= 0 && w >= 0) return (p - q).norm();
  const auto seg = [&](const Eigen::Vector3d& s, const Eigen::Vector3d& e) {
    const double t = std::clamp((p - s).dot(e - s) / (e - s).squaredNorm(), 0.0, 1.0);
    return (p - (s + t * (e - s))).norm();
  };
  return std::min({seg(a, b), seg(b, c), seg(c, a)});
}

double hull_phi(const ConvexHull& hull, const Eigen::Vector3d& p, bool exact_outside) {
  double m = -INFINITY;
  for (std::size_t f = 0; f < hull.faces.size(); ++f)
    m = std::max(m, hull.face_normals[f].dot(p - hull.vertices[hull.faces[f][0]]));
  if (m <= 0.0 || !exact_outside) return m;
  double d = INFINITY;
  for (const auto& f : hull.faces)
    d = std::min(d, triangle_distance(p, hull.vertices[f[0]], hull.vertices[f[1]], hull.vertices[f[2]]));
  return d;
}

// Distance from a point outside the ellipsoid with radii e: the closest point is e_i^2 y_i / (s + e_i^2) for the root
// s >= 0 of sum (e_i y_i / (s + e_i^2))^2 = 1 (a decreasing function of s), found by bisection to the last bit
// (Eberly, "Distance from a point to an ellipse, an ellipsoid, or a hyperellipsoid", 2013).
double ellipsoid_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& e) {
  const Eigen::Vector3d y = p.cwiseAbs();
  const auto g = [&](double s) {
    double sum = 0.0;
    for (int i = 0; i < 3; ++i) sum += std::pow(e[i] * y[i] / (s + e[i] * e[i]), 2);
    return sum - 1.0;
  };
  double lo = 0.0, hi = y.norm() * e.maxCoeff() + 1.0;
  for (int it = 0; it < 2000 && lo < hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (mid == lo || mid == hi) break;
    (g(mid) > 0.0 ? lo : hi) = mid;
  }
  Eigen::Vector3d q;
  for (int i = 0; i < 3; ++i) q[i] = e[i] * e[i] * y[i] / (lo + e[i] * e[i]);
  return (y - q).norm();
}

}  // namespace

bool has_exact_surface(const Shape&) { return true; }

double shape_phi(const Shape& s, const Eigen::Vector3d& p) {
  const double r = s.inflation;
  switch (s.type) {
    case ShapeType::sphere: return p.norm() - s.size.x() - r;
    case ShapeType::capsule: return segment_distance(p, s.size.y()) - s.size.x() - r;
    case ShapeType::box: return box_sdf(p, s.size) - r;
    case ShapeType::cylinder: return cylinder_sdf(p, s.size.x(), s.size.y()) - r;
    case ShapeType::cone: {
      const double h = s.size.y(), k = s.size.x() / (2 * h);
      const double rho = std::hypot(p.x(), p.y());
      const double lateral = (rho - k * (h - p.z())) / std::sqrt(1 + k * k);
      const double inside = std::max(-h - p.z(), lateral);
      if (inside <= 0.0 || r == 0.0) return inside - r;
      // Outside an inflated cone: the exact distance, to the triangle the cone revolves in the (rho, z) half-plane.
      return triangle_distance(Eigen::Vector3d(rho, 0, p.z()), Eigen::Vector3d(0, 0, -h),
                               Eigen::Vector3d(s.size.x(), 0, -h), Eigen::Vector3d(0, 0, h)) - r;
    }
    case ShapeType::ellipsoid: {
      const Eigen::Vector3d e = s.size;
      const double inside = (p.cwiseQuotient(e).norm() - 1.0) * e.minCoeff();
      if (inside <= 0.0 || r == 0.0) return inside - r;
      return ellipsoid_distance(p, e) - r;  // outside an inflated ellipsoid: the exact distance
    }
    case ShapeType::convex: return hull_phi(*s.hull, p, r > 0.0) - r;
    case ShapeType::triangle: return triangle_distance(p, s.triangle[0], s.triangle[1], s.triangle[2]) - r;
    case ShapeType::halfspace: return s.size.dot(p) - s.offset - r;
  }
  return NAN;
}

TraceResult sphere_trace(const Shape& shape, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_max,
                         double eps, int max_steps) {
  TraceResult r;
  const double speed = d.norm();
  double t = 0.0;
  for (int step = 0; step < max_steps; ++step) {
    const double phi = shape_phi(shape, o + t * d);
    if (phi <= eps) {
      r.hit = t <= t_max;
      r.t = t;
      return r;
    }
    t += phi / speed;
    // Past t_max, or so far that the ray has left every test shape for good (they lie within 1e3 m of the origin
    // in the tests; a ray moving away from a halfspace would otherwise step forever).
    if (t > t_max || t * speed > 1e6 + 1e3 * o.norm()) return r;
  }
  r.converged = false;
  return r;
}

}  // namespace batchcol::testing
