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

/// Distance from local point x to a convex polytope given by its outward face planes: exact outside along a face
/// normal region, otherwise the max over planes (a lower bound) -- good enough as a membership test with a
/// tolerance, which is what the checks use it for.
double hull_outside(const ConvexHull& h, const Eigen::Vector3d& x) {
  double worst = -1e300;
  for (std::size_t f = 0; f < h.faces.size(); ++f)
    worst = std::max(worst, h.face_normals[f].dot(x - h.vertices[h.faces[f][0]]));
  return std::max(worst, 0.0);
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

double outside_distance(const Shape& s, const Pose& p, const Eigen::Vector3d& world) {
  const Eigen::Vector3d x = p.rotation.conjugate() * (world - p.translation);
  const Eigen::Vector3d& z = s.size;
  const double rho = std::hypot(x.x(), x.y());
  double d = 0;
  switch (s.type) {
    case ShapeType::sphere: d = std::max(x.norm() - z.x(), 0.0); break;
    case ShapeType::capsule:
      d = std::max(segment_distance(x, {0, 0, -z.y()}, {0, 0, z.y()}) - z.x(), 0.0);
      break;
    case ShapeType::box: d = (x.cwiseAbs() - z).cwiseMax(0.0).norm(); break;
    case ShapeType::cylinder: d = std::hypot(std::max(rho - z.x(), 0.0), std::max(std::abs(x.z()) - z.y(), 0.0)); break;
    case ShapeType::cone: {
      // In the half-plane (rho, z) the cone is the triangle (0, h), (r, -h), (0, -h).
      const Eigen::Vector3d q(rho, x.z(), 0), apex(0, z.y(), 0), rim(z.x(), -z.y(), 0), base(0, -z.y(), 0);
      d = triangle_distance(q, apex, rim, base);
      break;
    }
    case ShapeType::ellipsoid: {
      const double k = x.cwiseQuotient(z).norm();  // x / k lies on the surface
      d = k <= 1 ? 0.0 : (x - x / k).norm();
      break;
    }
    case ShapeType::convex: d = hull_outside(*s.hull, x); break;
    case ShapeType::triangle: d = triangle_distance(x, s.triangle[0], s.triangle[1], s.triangle[2]); break;
    case ShapeType::halfspace: d = std::max(z.dot(x) - s.offset, 0.0); break;
  }
  return d;
}

}  // namespace batchcol::crosscheck
