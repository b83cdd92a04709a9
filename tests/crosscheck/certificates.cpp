#include "crosscheck/certificates.hpp"

#include "support/generators.hpp"

#include <algorithm>
#include <array>
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
      // Inside, the depth is the smallest distance to a face plane; outside, the distance to the nearest face.
      const ConvexHull& hull = *s.hull;
      double excess = -1e300;
      for (std::size_t f = 0; f < hull.faces.size(); ++f)
        excess = std::max(excess, hull.face_normals[f].dot(x - hull.vertices[hull.faces[f][0]]));
      if (excess <= 0) return excess;
      double d = 1e300;
      for (const auto& f : hull.faces)
        d = std::min(d, triangle_distance(x, hull.vertices[f[0]], hull.vertices[f[1]], hull.vertices[f[2]]));
      return d;
    }
    case ShapeType::triangle: return triangle_distance(x, s.triangle[0], s.triangle[1], s.triangle[2]);
    case ShapeType::halfspace: return z.dot(x) - s.offset;
  }
  return 0.0;
}

namespace {

/// Segment pq crosses the interior of triangle t: the endpoints are strictly on both sides of its plane and the
/// crossing point strictly inside its edges (relative margins well above rounding).
bool segment_crosses(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const std::array<Eigen::Vector3d, 3>& t) {
  constexpr double kMargin = 1e-9;
  const Eigen::Vector3d n = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
  const double dp = n.dot(p - t[0]), dq = n.dot(q - t[0]);
  const double scale = (q - p).norm();
  if (!(dp * dq < 0) || std::min(std::abs(dp), std::abs(dq)) <= kMargin * scale) return false;
  const Eigen::Vector3d x = p + dp / (dp - dq) * (q - p);
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d e = t[(i + 1) % 3] - t[i];
    if (n.dot(e.cross(x - t[i])) <= kMargin * e.norm() * scale) return false;
  }
  return true;
}

std::array<Eigen::Vector3d, 3> world_triangle(const Shape& s, const Pose& p) {
  return {p.rotation * s.triangle[0] + p.translation, p.rotation * s.triangle[1] + p.translation,
          p.rotation * s.triangle[2] + p.translation};
}

}  // namespace

bool triangles_cross(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
  if (a.type != ShapeType::triangle || b.type != ShapeType::triangle) return false;
  const auto ta = world_triangle(a, pa), tb = world_triangle(b, pb);
  for (int i = 0; i < 3; ++i)
    if (segment_crosses(ta[i], ta[(i + 1) % 3], tb) || segment_crosses(tb[i], tb[(i + 1) % 3], ta)) return true;
  return false;
}

bool proves_overlap(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, const Eigen::Vector3d& x) {
  const double da = signed_outside(a, pa, x), db = signed_outside(b, pb, x);
  return (da >= 0 && db < -da) || (db >= 0 && da < -db) || (da < 0 && db < 0);
}

}  // namespace batchcol::crosscheck
