// Penetration depth of a segment core (a capsule) overlapping a cylinder or cone core, in closed form (issue #16,
// item 10): EPA ended max_iterations with depth errors of ~1e-5 x the size, as for a sphere centred inside
// (kernels/point_depth.hpp), because the minimum lies on a curved part of the boundary.
//
// The depth is min over unit n of f(n) = h_A(n) + h_S(-n), with h the support functions of the core A and the
// segment S = [p0, p1] (the smallest translation of S that separates it from A). With d = p1 - p0,
// h_S(-n) = max(-n.p0, -n.p1), so f = g0 = h_A - n.p0 on the hemisphere n.d >= 0 and f = g1 = h_A - n.p1 on the
// other one. The minimum of g_i over its closed hemisphere is either a local minimum of g_i on the sphere (an
// interior point) or lies on the great circle n.d = 0, where g0 = g1. NOTE: this is why the depth is not the
// larger endpoint depth: on the great circle the segment moves sideways, as a whole.
//  - A local minimum of g_i with a positive value has A's support point in n at p_i + g_i(n) n on a smooth face
//    of A (at a rim or the apex, the value along the normal cone, n.(x - p_i), is largest at the direction of
//    x - p_i, so a positive critical point there is no minimum): the caps' normals and the side's normals in the
//    half-plane of p_i through the axis and the opposite one.
//  - On the great circle, g0(n) is the support function of the projection P of A along d, at the projection q
//    of p0: its minimum is the distance from q to the boundary of P (q is inside: the line of S meets A). P is the
//    convex hull of the projected rims (ellipses; and the apex): the minimum is at the normal of a straight edge
//    (the projection of a side line whose normal is orthogonal to d, or of a cap seen edge-on) or at the normal
//    of a foot of a perpendicular from q to a rim ellipse (kernels/ellipse_normals.hpp).
// f is evaluated exactly at every candidate (each is an upper bound of the depth); the smallest is the depth, the
// minimiser being among them. Candidates that are no local minimum (a far cap, a foot on the hidden arc of an
// ellipse) only cost an evaluation.
#pragma once

#include "kernels/ellipse_normals.hpp"
#include "kernels/point_depth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

namespace batchcol::kernels {

template <class T> struct SegmentDepth {
  T depth = T(0);
  Vec3<T> normal = Vec3<T>::UnitX();  // unit, outward from A: S leaves A along it
  Vec3<T> on_a = Vec3<T>::Zero();     // contact point on A; on_a - depth * normal is on S
};

namespace detail {

/// Support function of a cylinder or cone core (axis z, half length h, radius R).
template <class T> T axial_core_support(bool cone, T R, T h, const Vec3<T>& n) {
  const T rho = std::sqrt(n.x() * n.x() + n.y() * n.y());
  if (!cone) return R * rho + h * std::abs(n.z());
  return std::max(h * n.z(), R * rho - h * n.z());
}

}  // namespace detail

/// Where S + depth n touches A (A's frame), for the minimising direction n: the segment's lowest point along n
/// when that is an endpoint; when S is parallel to the supporting plane, a point common to A's face there (a cap,
/// a side line, or a single rim point or the apex) and the translated segment.
template <class T>
Vec3<T> segment_contact_on_core(bool cone, T R, T h, const Vec3<T>& p0, const Vec3<T>& p1, T depth, const Vec3<T>& n) {
  const Vec3<T> shift = depth * n, d = p1 - p0;
  const T d_len = d.norm(), nd = n.dot(d);
  // Directions within ~1000 eps of a face normal are that face's (the candidates are exact to a few ulps).
  const T flat = T(1000) * machine_epsilon<T>();
  if (!(std::abs(nd) <= flat * d_len)) return (nd > T(0) ? p0 : p1) + shift;
  const auto on_segment = [&](const Vec3<T>& x) {  // the point of S + shift closest to x
    const T t = d_len > T(0) ? std::clamp((x - p0 - shift).dot(d) / (d_len * d_len), T(0), T(1)) : T(0);
    return Vec3<T>(p0 + shift + t * d);
  };
  const T n_rho = std::sqrt(n.x() * n.x() + n.y() * n.y());
  const Vec3<T> r = n_rho > T(0) ? Vec3<T>(n.x() / n_rho, n.y() / n_rho, T(0)) : Vec3<T>::UnitX();
  const Vec3<T> apex(T(0), T(0), h);
  if (n_rho <= flat) {  // a cap (a cone's +z: its apex): S's point nearest to the cap's centre, pulled into the disc
    if (cone && n.z() > T(0)) return apex;
    const Vec3<T> x = on_segment(Vec3<T>(T(0), T(0), n.z() > T(0) ? h : -h));
    const T rho = std::sqrt(x.x() * x.x() + x.y() * x.y());
    return rho > R ? Vec3<T>(x.x() * (R / rho), x.y() * (R / rho), x.z()) : x;
  }
  const T L = std::sqrt(R * R + T(4) * h * h);
  const Vec3<T> s0(R * r.x(), R * r.y(), -h);  // the side line from the bottom rim, in n's half-plane
  if (cone ? std::abs(T(2) * h * n.z() - R * n_rho) <= flat * L : std::abs(n.z()) <= flat) {
    // A side line: the point of it closest to the translated segment's line (both lie in the supporting plane).
    const Vec3<T> g = (cone ? apex : Vec3<T>(s0.x(), s0.y(), h)) - s0, w0 = s0 - p0 - shift;
    const T gg = g.dot(g), gd = g.dot(d), dd = d.dot(d), gw = g.dot(w0), dw = d.dot(w0);
    const T denom = gg * dd - gd * gd;
    // Parallel lines (or a point segment): the point facing the segment's middle.
    const T t = denom > T(1e-6) * gg * dd ? (gd * dw - dd * gw) / denom : (p0 + shift + d / T(2) - s0).dot(g) / gg;
    return s0 + std::clamp(t, T(0), T(1)) * g;
  }
  // A single support point: a rim point or the apex.
  if (cone) return h * n.z() >= R * n_rho - h * n.z() ? apex : s0;
  return Vec3<T>(s0.x(), s0.y(), n.z() > T(0) ? h : -h);
}

/// Depth of the segment [p0, p1] (core frame) in a cylinder or cone core; false for other core types. Only for
/// overlapping cores (GJK's overlap status): the result is clamped at 0.
template <class T>
bool segment_depth_in_core(const ShapeCore<T>& core, const Vec3<T>& p0, const Vec3<T>& p1, SegmentDepth<T>& out) {
  if (core.type != ShapeType::cylinder && core.type != ShapeType::cone) return false;
  if constexpr (std::is_same_v<T, float>) {
    // Solved in double on the float inputs: in float, candidates whose values tie within rounding can have contacts
    // far apart (measured: 26 of 20000 random pairs had the segment's witness 1e-4..1e-3 m off; 0 in double).
    ShapeCore<double> wide;
    wide.type = core.type;
    wide.size = core.size.template cast<double>();
    SegmentDepth<double> d;
    const Vec3<double> q0 = p0.template cast<double>(), q1 = p1.template cast<double>();
    if (!segment_depth_in_core(wide, q0, q1, d)) return false;
    out.depth = float(d.depth);
    out.normal = d.normal.cast<float>();
    out.on_a = d.on_a.cast<float>();
    return true;
  }
  const bool cone = core.type == ShapeType::cone;
  const T R = core.size.x(), h = core.size.y();
  const Vec3<T> z = Vec3<T>::UnitZ(), d = p1 - p0;
  T best = std::numeric_limits<T>::infinity();
  Vec3<T> best_n = Vec3<T>::UnitX();
  const auto consider = [&](Vec3<T> n) {
    const T len = n.norm();
    if (!(len > T(0)) || !std::isfinite(len)) return;
    n /= len;
    const T f = detail::axial_core_support(cone, R, h, n) + std::max(-n.dot(p0), -n.dot(p1));
    if (f < best) best = f, best_n = n;
  };
  const Vec3<T> d_xy(d.x(), d.y(), T(0));
  for (int i = 0; i < 2; ++i) {
    const Vec3<T>& p = i ? p1 : p0;
    const Vec3<T> p_xy(p.x(), p.y(), T(0));
    // On the axis every radial direction is as good for the point: take the one along the segment (inside
    // the hemisphere where f = g_i when there is one).
    Vec3<T> radial = p_xy.norm() > T(0) ? p_xy : d_xy.norm() > T(0) ? (i ? Vec3<T>(-d_xy) : d_xy) : Vec3<T>::UnitX();
    radial.normalize();
    consider(-z);
    if (!cone) {
      consider(z);
      consider(radial);
      consider(-radial);
    } else {
      consider(T(2) * h * radial + R * z);
      consider(-T(2) * h * radial + R * z);
    }
  }
  const T d_len = d.norm();
  if (d_len > T(0)) {
    const Vec3<T> u = d / d_len;
    // e1 is orthogonal to the axis and to d, e2 = u x e1 is z's projection on the plane orthogonal to d (d along
    // the axis: any e1, the rims are seen as circles).
    Vec3<T> e1 = z.cross(u);
    const T e1_len = e1.norm();
    e1 = e1_len > T(0) ? Vec3<T>(e1 / e1_len) : Vec3<T>::UnitX();
    const Vec3<T> e2 = u.cross(e1);
    consider(e2);
    consider(-e2);
    if (!cone) {
      consider(e1);  // side lines whose normal is orthogonal to d
      consider(-e1);
    } else if (e1_len > T(0)) {
      // Side normals (2h r + R z) / L orthogonal to d: 2h r.u_xy = -R u_z, r a unit radial vector.
      const T u_xy = std::sqrt(u.x() * u.x() + u.y() * u.y());
      const T c = -R * u.z() / (T(2) * h * u_xy);
      if (std::abs(c) <= T(1)) {
        const T s = std::sqrt(T(1) - c * c);
        const Vec3<T> along(u.x() / u_xy, u.y() / u_xy, T(0)), across(-u.y() / u_xy, u.x() / u_xy, T(0));
        consider(T(2) * h * (c * along + s * across) + R * z);
        consider(T(2) * h * (c * along - s * across) + R * z);
      }
    }
    // Rim circles, seen along u: ellipses with semi-axes R along e1 and R |u.z| along e2.
    const T b = R * std::abs(u.z());
    for (T zc : {-h, h}) {
      if (cone && zc > T(0)) continue;
      const Vec3<T> c(T(0), T(0), zc);
      const EllipseNormals<T> feet = ellipse_normals(R, b, (p0 - c).dot(e1), (p0 - c).dot(e2));
      for (int k = 0; k < feet.count; ++k) consider(feet.nx[k] * e1 + feet.ny[k] * e2);
    }
  }
  if (!std::isfinite(best)) return false;
  out.depth = std::max(best, T(0));
  out.normal = best_n;
  out.on_a = segment_contact_on_core(cone, R, h, p0, p1, out.depth, best_n);
  return true;
}

}  // namespace batchcol::kernels
