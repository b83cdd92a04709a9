#include "testkit/analytic_reference.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace batchcol::testkit {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// Below this core distance (metres) a sphere centre sits on its core point / capsule axis and the direction of the
// normal is undefined: such pairs fall back to the numeric reference. Far below every regime of the bench (cores
// are >= 1 cm apart in every placement with depth <= 1 cm).
constexpr double kUndefinedNormal = 1e-9;

double clamp01(double v) { return std::min(1.0, std::max(0.0, v)); }

// Nearest point to x on the 2D segment [p, q].
Vector2d nearest_on_segment(const Vector2d& x, const Vector2d& p, const Vector2d& q) {
  const Vector2d d = q - p;
  return p + clamp01((x - p).dot(d) / d.squaredNorm()) * d;
}

std::optional<BoundaryPoint> outside(const Vector3d& p, const Vector3d& nearest) {
  const Vector3d v = p - nearest;
  const double s = v.norm();
  if (!(s > 0)) return std::nullopt;  // on the boundary itself: the normal needs the face; none of the bench's pairs
  return BoundaryPoint{s, nearest, v / s};
}

std::optional<BoundaryPoint> to_segment(const Vector3d& p, double half_length, double radius) {
  const Vector3d on_axis(0, 0, std::clamp(p.z(), -half_length, half_length));
  const Vector3d v = p - on_axis;
  const double s = v.norm();
  if (s < kUndefinedNormal) return std::nullopt;
  const Vector3d n = v / s;
  return BoundaryPoint{s - radius, on_axis + radius * n, n};
}

std::optional<BoundaryPoint> to_box(const Vector3d& p, const Vector3d& h) {
  const Vector3d q = p.cwiseMax(-h).cwiseMin(h);
  if (q != p) return outside(p, q);
  // Inside: leave through the nearest face.
  int axis = 0;
  const Vector3d room = h - p.cwiseAbs();
  for (int i = 1; i < 3; ++i) {
    if (room[i] < room[axis]) axis = i;
  }
  Vector3d n = Vector3d::Zero(), on_face = p;
  n[axis] = p[axis] < 0 ? -1.0 : 1.0;
  on_face[axis] = n[axis] * h[axis];
  return BoundaryPoint{-room[axis], on_face, n};
}

// Solids of revolution about z: (rho, z) coordinates in the meridian half-plane through p, u its radial direction.
struct Meridian {
  Vector2d x;
  Vector3d u;
};

Meridian meridian(const Vector3d& p) {
  const double rho = std::hypot(p.x(), p.y());
  const Vector3d u = rho > 0 ? Vector3d(p.x() / rho, p.y() / rho, 0) : Vector3d::UnitX();
  return {{rho, p.z()}, u};
}

Vector3d lift(const Meridian& m, const Vector2d& v) { return v.x() * m.u + Vector3d(0, 0, v.y()); }

std::optional<BoundaryPoint> to_cylinder(const Vector3d& p, double radius, double h) {
  const Meridian m = meridian(p);
  const double rho = m.x.x(), z = m.x.y();
  if (rho > radius || std::abs(z) > h) return outside(p, lift(m, {std::min(rho, radius), std::clamp(z, -h, h)}));
  const double side = radius - rho, cap = h - std::abs(z);
  if (side < cap) return BoundaryPoint{-side, lift(m, {radius, z}), m.u};
  const double sign = z < 0 ? -1.0 : 1.0;
  return BoundaryPoint{-cap, lift(m, {rho, sign * h}), Vector3d(0, 0, sign)};
}

// Cone: apex (0, h), rim (R, -h), base centre (0, -h) in the meridian half-plane.
std::optional<BoundaryPoint> to_cone(const Vector3d& p, double radius, double h) {
  const Meridian m = meridian(p);
  const Vector2d apex(0, h), rim(radius, -h), base_centre(0, -h);
  const Vector2d lateral_normal = Vector2d(2 * h, radius).normalized();  // outward, perpendicular to apex -> rim
  const double lateral = (m.x - apex).dot(lateral_normal), base = -h - m.x.y();  // signed distances to the face lines
  if (lateral > 0 || base > 0) {
    const Vector2d on_lateral = nearest_on_segment(m.x, apex, rim), on_base = nearest_on_segment(m.x, base_centre, rim);
    const bool lateral_nearer = (m.x - on_lateral).squaredNorm() <= (m.x - on_base).squaredNorm();
    return outside(p, lift(m, lateral_nearer ? on_lateral : on_base));
  }
  if (lateral >= base) {
    return BoundaryPoint{lateral, lift(m, m.x - lateral * lateral_normal), lift(m, lateral_normal)};
  }
  return BoundaryPoint{base, lift(m, {m.x.x(), -h}), Vector3d(0, 0, -1)};
}

std::optional<BoundaryPoint> core_point(const Shape& s, const Vector3d& p) {
  switch (s.type) {
    case ShapeType::sphere: return to_segment(p, 0.0, s.size.x());
    case ShapeType::capsule: return to_segment(p, s.size.y(), s.size.x());
    case ShapeType::box: return to_box(p, s.size);
    case ShapeType::cylinder: return to_cylinder(p, s.size.x(), s.size.y());
    case ShapeType::cone: return to_cone(p, s.size.x(), s.size.y());
    default: return std::nullopt;
  }
}

Vector3d to_world(const Pose& pose, const Vector3d& local) { return pose.rotation * local + pose.translation; }
Vector3d to_local(const Pose& pose, const Vector3d& world) {
  return pose.rotation.conjugate() * (world - pose.translation);
}

// Sphere `sphere` (at pose_s) against `other` (at pose_o); the normal points from the sphere to the other shape
// when sphere_is_a, from the other shape to the sphere otherwise.
std::optional<ReferencePair> sphere_against(const Shape& sphere, const Pose& pose_s, const Shape& other,
                                            const Pose& pose_o, bool sphere_is_a) {
  const Vector3d centre = to_local(pose_o, pose_s.translation);
  const auto bp = point_to_shape(other, centre);
  if (!bp) return std::nullopt;
  const double r = sphere.size.x() + sphere.inflation;
  const Vector3d n_out = pose_o.rotation * bp->normal;  // outward normal of `other` at its witness point
  const Vector3d on_other = to_world(pose_o, bp->point);
  const Vector3d on_sphere = pose_s.translation - r * n_out;
  ReferencePair ref;
  ref.distance = bp->signed_distance - r;
  ref.normal = sphere_is_a ? Vector3d(-n_out) : n_out;
  ref.witness_a = sphere_is_a ? on_sphere : on_other;
  ref.witness_b = sphere_is_a ? on_other : on_sphere;
  ref.certified = ref.analytic = true;
  return ref;
}

std::optional<ReferencePair> capsule_capsule(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b) {
  const Vector3d ha(0, 0, a.size.y()), hb(0, 0, b.size.y());
  Vector3d ca, cb;
  closest_points_of_segments(to_world(pose_a, -ha), to_world(pose_a, ha), to_world(pose_b, -hb),
                             to_world(pose_b, hb), ca, cb);
  const double core = (cb - ca).norm();
  if (core < kUndefinedNormal) return std::nullopt;  // crossing axes: the depth is not ra + rb - core
  const double ra = a.size.x() + a.inflation, rb = b.size.x() + b.inflation;
  ReferencePair ref;
  ref.normal = (cb - ca) / core;
  ref.distance = core - ra - rb;
  ref.witness_a = ca + ra * ref.normal;
  ref.witness_b = cb - rb * ref.normal;
  ref.certified = ref.analytic = true;
  return ref;
}

bool point_like(ShapeType t) { return t == ShapeType::sphere; }
bool has_point_form(ShapeType t) {
  return t == ShapeType::sphere || t == ShapeType::capsule || t == ShapeType::box || t == ShapeType::cylinder ||
         t == ShapeType::cone;
}

}  // namespace

std::optional<BoundaryPoint> point_to_shape(const Shape& shape, const Vector3d& p) {
  auto bp = core_point(shape, p);
  if (!bp) return bp;
  bp->signed_distance -= shape.inflation;
  bp->point += shape.inflation * bp->normal;
  return bp;
}

void closest_points_of_segments(const Vector3d& p0, const Vector3d& p1, const Vector3d& q0, const Vector3d& q1,
                                Vector3d& on_p, Vector3d& on_q) {
  // f(s, t) = |p0 + s d1 - q0 - t d2|^2 is a convex quadratic on [0, 1]^2: its minimum is the interior stationary
  // point when that lies in the square, else the best of the minima along the four edges.
  const Vector3d d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), b = d1.dot(d2), e = d2.squaredNorm(), c = d1.dot(r), f = d2.dot(r);
  const auto value = [&](double s, double t) { return (r + s * d1 - t * d2).squaredNorm(); };
  std::array<std::array<double, 2>, 5> candidates{};
  int count = 0;
  const double det = a * e - b * b;
  if (det > 1e-12 * a * e) {  // not parallel (sin^2 of the angle > 1e-12); parallel segments use the edges only
    const double s = (b * f - c * e) / det, t = (a * f - b * c) / det;
    if (s >= 0 && s <= 1 && t >= 0 && t <= 1) candidates[count++] = {s, t};
  }
  for (double t : {0.0, 1.0}) candidates[count++] = {a > 0 ? clamp01((t * b - c) / a) : 0.0, t};
  for (double s : {0.0, 1.0}) candidates[count++] = {s, e > 0 ? clamp01((s * b + f) / e) : 0.0};
  int best = 0;
  for (int i = 1; i < count; ++i) {
    if (value(candidates[i][0], candidates[i][1]) < value(candidates[best][0], candidates[best][1])) best = i;
  }
  on_p = p0 + candidates[best][0] * d1;
  on_q = q0 + candidates[best][1] * d2;
}

bool has_closed_form(ShapeType a, ShapeType b) {
  if (a == ShapeType::capsule && b == ShapeType::capsule) return true;
  return (point_like(a) && has_point_form(b)) || (point_like(b) && has_point_form(a));
}

std::optional<ReferencePair> analytic_reference(const Shape& a, const Pose& pose_a, const Shape& b,
                                                const Pose& pose_b) {
  if (!has_closed_form(a.type, b.type)) return std::nullopt;
  if (a.type == ShapeType::capsule && b.type == ShapeType::capsule) return capsule_capsule(a, pose_a, b, pose_b);
  if (point_like(a.type)) return sphere_against(a, pose_a, b, pose_b, true);
  return sphere_against(b, pose_b, a, pose_a, false);
}

}  // namespace batchcol::testkit
