// Exact ray intervals of the curved shapes (local frame, axes along z): sphere, infinite cylinder, capsule, cylinder,
// cone, ellipsoid.
//
// Quadratics are solved in the "closest point" form (Haines, Guenther, Akenine-Moeller, "Precision improvements for
// ray/sphere intersection", Ray Tracing Gems ch. 7, 2019): t_c = -<o, d>/|d|^2 is the parameter of the point p of the
// line closest to the centre and the half chord is sqrt((r^2 - |p|^2) / |d|^2). The textbook discriminant
// b^2 - ac cancels catastrophically when the origin is far away (|o| >> r); r^2 - |p|^2 does not.
#pragma once

#include "kernels/rays/ray_interval.hpp"

#include <cmath>

namespace batchcol::kernels::rays {

/// Ball of radius r about the origin.
template <class T> RayInterval<T> ray_sphere(const Vec3<T>& o, const Vec3<T>& d, T r) {
  const T a = norm2(d);
  const T tc = -dot3(o, d) / a;
  const Vec3<T> p = o + tc * d;
  const T h2 = r * r - norm2(p);
  if (!(h2 >= T(0))) return RayInterval<T>::nothing();
  const T half = std::sqrt(h2 / a);
  RayInterval<T> in;
  in.enter = tc - half;
  in.exit = tc + half;
  in.normal = (o + in.enter * d) / r;
  return in;
}

/// Infinite solid cylinder x^2 + y^2 <= r^2 (radial normals).
template <class T> RayInterval<T> ray_infinite_cylinder(const Vec3<T>& o, const Vec3<T>& d, T r) {
  const T a = d.x() * d.x() + d.y() * d.y();
  if (a == T(0)) {  // parallel to the axis
    return o.x() * o.x() + o.y() * o.y() <= r * r ? RayInterval<T>::everything() : RayInterval<T>::nothing();
  }
  const T tc = -(o.x() * d.x() + o.y() * d.y()) / a;
  const T px = o.x() + tc * d.x(), py = o.y() + tc * d.y();
  const T h2 = r * r - (px * px + py * py);
  if (!(h2 >= T(0))) return RayInterval<T>::nothing();
  const T half = std::sqrt(h2 / a);
  RayInterval<T> in;
  in.enter = tc - half;
  in.exit = tc + half;
  in.normal = Vec3<T>(o.x() + in.enter * d.x(), o.y() + in.enter * d.y(), T(0)) / r;
  return in;
}

/// Capsule: segment z in [-h, h] swept by radius r. The solid is the union of the two end balls and the cylinder
/// between them, so its interval is the union of theirs; the balls win ties (the cylinder's flat ends are inside
/// them and are no surface of the capsule).
template <class T> RayInterval<T> ray_capsule(const Vec3<T>& o, const Vec3<T>& d, T r, T h) {
  const Vec3<T> ez(T(0), T(0), T(1));
  // Entering the body through a flat end means entering that end's ball at the same t or earlier: unite() then
  // keeps the ball (first argument wins ties) and its normal.
  const RayInterval<T> body = intersect(ray_infinite_cylinder(o, d, r), slab(o.z(), d.z(), -h, h, ez));
  const RayInterval<T> top = ray_sphere<T>(o - h * ez, d, r), bottom = ray_sphere<T>(o + h * ez, d, r);
  return unite(unite(top, bottom), body);
}

/// Cylinder: radius r, z in [-h, h].
template <class T> RayInterval<T> ray_cylinder(const Vec3<T>& o, const Vec3<T>& d, T r, T h) {
  return intersect(ray_infinite_cylinder(o, d, r), slab(o.z(), d.z(), -h, h, Vec3<T>(T(0), T(0), T(1))));
}

/// Axis-aligned ellipsoid with radii e: the unit ball after scaling by 1/e; the normal is the gradient p ./ e^2.
template <class T> RayInterval<T> ray_ellipsoid(const Vec3<T>& o, const Vec3<T>& d, const Vec3<T>& e) {
  const Vec3<T> os = o.cwiseQuotient(e), ds = d.cwiseQuotient(e);
  RayInterval<T> in = ray_sphere<T>(os, ds, T(1));
  if (in.empty()) return in;
  const Vec3<T> p = o + in.enter * d;
  const Vec3<T> g = p.cwiseQuotient(e.cwiseProduct(e));
  in.normal = g / norm3(g);
  return in;
}

/// Cone: base disc of radius r at z = -h, apex at z = +h. The lateral solid {rho <= k (h - z)}, k = r / 2h, is
/// convex: f(t) = rho(t) - k (h - z(t)) is a convex function of t, so {f <= 0} is one interval whose ends are roots of
/// the quadratic rho^2 - k^2 (h - z)^2 (which also has roots on the mirrored upper nappe, where f > 0). The roots cut
/// the line into at most three pieces; f has one sign on each, read at a point inside it. The base slab z >= -h is
/// intersected afterwards.
template <class T> RayInterval<T> ray_cone(const Vec3<T>& o, const Vec3<T>& d, T r, T h) {
  const T k = r / (T(2) * h), k2 = k * k;
  const T w0 = h - o.z();
  const T A = d.x() * d.x() + d.y() * d.y() - k2 * d.z() * d.z();
  const T B = o.x() * d.x() + o.y() * d.y() + k2 * w0 * d.z();
  const T C = o.x() * o.x() + o.y() * o.y() - k2 * w0 * w0;
  T roots[2];
  int n = 0;
  // A is a difference of squares: treat it as zero below the rounding of its terms (the line is parallel to a
  // generator of the cone and the quadratic is linear).
  const T scale = d.x() * d.x() + d.y() * d.y() + k2 * d.z() * d.z();
  if (std::fabs(A) <= T(16) * machine_epsilon<T>() * scale) {
    if (B != T(0)) roots[n++] = -C / (T(2) * B);
  } else {
    const T disc = B * B - A * C;
    if (disc >= T(0)) {
      const T q = -(B + std::copysign(std::sqrt(disc), B));  // no cancellation (Numerical Recipes' form)
      const T r1 = q / A;
      const T r2 = q != T(0) ? C / q : r1;
      roots[n++] = r1 < r2 ? r1 : r2;
      roots[n++] = r1 < r2 ? r2 : r1;
    }
  }
  const auto f = [&](T t) {
    const T x = o.x() + t * d.x(), y = o.y() + t * d.y(), z = o.z() + t * d.z();
    return std::sqrt(x * x + y * y) - k * (h - z);
  };
  RayInterval<T> lateral;
  if (n == 0) {
    lateral = f(T(0)) <= T(0) ? RayInterval<T>::everything() : RayInterval<T>::nothing();
  } else {
    // Pieces (-inf, b0), [b0, b1], (b1, inf) (the middle one only for two roots), each tested at an inner point.
    const T lo = roots[0], hi = roots[n - 1];
    const bool before = f(lo - (T(1) + std::fabs(lo))) <= T(0);
    const bool middle = n == 2 && f(T(0.5) * (lo + hi)) <= T(0);
    const bool after = f(hi + (T(1) + std::fabs(hi))) <= T(0);
    if (before) lateral.enter = -infinity<T>();
    else if (middle || (n == 2 ? false : after)) lateral.enter = lo;
    else if (after) lateral.enter = hi;
    if (after) lateral.exit = infinity<T>();
    else if (middle) lateral.exit = hi;
    else if (before) lateral.exit = lo;
    if (!lateral.empty() && std::isfinite(lateral.enter)) {
      const Vec3<T> p = o + lateral.enter * d;
      const T rho = std::sqrt(p.x() * p.x() + p.y() * p.y());
      if (rho > T(0)) {
        const Vec3<T> g(p.x() / rho, p.y() / rho, k);
        lateral.normal = g / norm3(g);
      } else {
        lateral.normal = Vec3<T>(T(0), T(0), T(1));  // the apex: any normal of its cone of normals; take the axis
      }
    }
  }
  RayInterval<T> base;  // z >= -h
  const Vec3<T> down(T(0), T(0), T(-1));
  if (d.z() == T(0)) {
    base = o.z() >= -h ? RayInterval<T>::everything() : RayInterval<T>::nothing();
  } else {
    const T tb = (-h - o.z()) / d.z();
    if (d.z() > T(0)) base = {tb, infinity<T>(), down};
    else base = {-infinity<T>(), tb, down};
  }
  return intersect(lateral, base);
}

}  // namespace batchcol::kernels::rays
