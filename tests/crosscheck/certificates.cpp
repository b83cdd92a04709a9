#include "crosscheck/certificates.hpp"

#include "support/generators.hpp"

#include <algorithm>
#include <cmath>

namespace batchcol::crosscheck {
namespace {

/// Distance from x to segment [p, q].
double segment_distance(const Eigen::Vector3d& x, const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const Eigen::Vector3d e = q - p;
  const double t = std::clamp((x - p).dot(e) / e.squaredNorm(), 0.0, 1.0);
  return (x - (p + t * e)).norm();
}

/// Distance from x to the (solid, flat) triangle abc.
double triangle_distance(const Eigen::Vector3d& x, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
  const Eigen::Vector3d y = x - n * n.dot(x - a);  // projection on the plane
  const bool inside = n.dot((b - a).cross(y - a)) >= 0 && n.dot((c - b).cross(y - b)) >= 0 &&
                      n.dot((a - c).cross(y - c)) >= 0;
  if (inside) return std::abs(n.dot(x - a));
  return std::min({segment_distance(x, a, b), segment_distance(x, b, c), segment_distance(x, c, a)});
}

}  // namespace

double world_extent(const Shape& s, const Pose& p, const Eigen::Vector3d& n) {
  return testing::extent(s, p.rotation.conjugate() * n) + n.dot(p.translation);
}

WorldPlane world_plane(const Shape& h, const Pose& p) {
  const Eigen::Vector3d n = p.rotation * h.size;
  return {n, h.offset + n.dot(p.translation)};
}

double halfspace_signed_distance(const WorldPlane& plane, const Shape& s, const Pose& p) {
  return -world_extent(s, p, -plane.normal) - plane.offset;
}

double certified_lower_bound(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Eigen::Vector3d n) {
  if (a.type == ShapeType::halfspace) return halfspace_signed_distance(world_plane(a, pa), b, pb);
  if (b.type == ShapeType::halfspace) return halfspace_signed_distance(world_plane(b, pb), a, pa);
  n.normalize();
  return -world_extent(b, pb, -n) - world_extent(a, pa, n);
}

double refined_lower_bound(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Eigen::Vector3d n,
                           int evaluations) {
  n.normalize();
  double best = certified_lower_bound(a, pa, b, pb, n);
  // Eight tangent directions: the maximiser often sits on a ridge (polytope edges) where four would stall.
  for (double step = 1e-3; step > 1e-13 && evaluations > 0;) {
    const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
    bool improved = false;
    for (int k = 0; k < 8 && !improved; ++k, --evaluations) {
      const double angle = k * M_PI / 4;
      const Eigen::Vector3d m = (n + step * (std::cos(angle) * t1 + std::sin(angle) * t2)).normalized();
      const double value = certified_lower_bound(a, pa, b, pb, m);
      if (value > best) { best = value; n = m; improved = true; }
    }
    if (improved) step *= 2; else step *= 0.25;
  }
  return best;
}

double signed_outside(const Shape& s, const Pose& p, const Eigen::Vector3d& world) {
  const Eigen::Vector3d x = p.rotation.conjugate() * (world - p.translation);
  const Eigen::Vector3d& z = s.size;
  const double rho = std::hypot(x.x(), x.y());
  switch (s.type) {
    case ShapeType::sphere: return x.norm() - z.x();
    case ShapeType::capsule: return segment_distance(x, {0, 0, -z.y()}, {0, 0, z.y()}) - z.x();
    case ShapeType::box: {
      const Eigen::Vector3d q = x.cwiseAbs() - z;
      return q.maxCoeff() > 0 ? q.cwiseMax(0.0).norm() : q.maxCoeff();
    }
    case ShapeType::cylinder: {
      const double er = rho - z.x(), ez = std::abs(x.z()) - z.y();
      return er > 0 || ez > 0 ? std::hypot(std::max(er, 0.0), std::max(ez, 0.0)) : std::max(er, ez);
    }
    case ShapeType::cone: {
      // In the half-plane (rho, z) the cone is the triangle apex (0, h), rim (r, -h), base centre (0, -h).
      const double h = z.y(), r = z.x();
      const Eigen::Vector3d q(rho, x.z(), 0), apex(0, h, 0), rim(r, -h, 0), base(0, -h, 0);
      const double out = triangle_distance(q, apex, rim, base);
      if (out > 0) return out;
      const double slant = (r * (h - x.z()) / (2 * h) - rho) * (2 * h) / std::hypot(2 * h, r);
      return -std::min(x.z() + h, slant);
    }
    case ShapeType::ellipsoid: {
      const double k = x.cwiseQuotient(z).norm();  // x / k lies on the surface
      return k > 1 ? (x - x / k).norm() : -(1 - k) * z.minCoeff();
    }
    case ShapeType::convex: {
      double worst = -1e300;
      const ConvexHull& hull = *s.hull;
      for (std::size_t f = 0; f < hull.faces.size(); ++f)
        worst = std::max(worst, hull.face_normals[f].dot(x - hull.vertices[hull.faces[f][0]]));
      return worst;
    }
    case ShapeType::triangle: return triangle_distance(x, s.triangle[0], s.triangle[1], s.triangle[2]);
    case ShapeType::halfspace: return z.dot(x) - s.offset;
  }
  return 0.0;
}

bool proves_overlap(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, const Eigen::Vector3d& x) {
  const double da = signed_outside(a, pa, x), db = signed_outside(b, pb, x);
  return (da >= 0 && db < -da) || (db >= 0 && da < -db) || (da < 0 && db < 0);
}

}  // namespace batchcol::crosscheck
