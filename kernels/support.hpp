// Support functions of the shape cores in their local frame: support(d) = argmax_{x in core} <x, d>.
// Frank-Wolfe / GJK only ever touches a shape through this function (Gilbert, Johnson, Keerthi 1988).
// Ties (d orthogonal to a face) may return any maximiser; every branch below returns a point of the core and
// never divides by a quantity that can be zero.
#pragma once

#include "kernels/shape_core.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace batchcol::kernels {

/// Hulls with at least this many vertices use hill climbing over the vertex adjacency instead of a linear scan.
/// A scan costs one dot product per vertex; a climb costs ~ (path length x valence) dot products, which wins
/// once the hull is larger than a few dozen vertices (32: the crossover found when the climb was added).
constexpr std::size_t kHillClimbMinVertices = 32;

/// Per-query state of a support function: the last vertex found on a hull, where the next climb starts
/// (none yet: the climb starts from the hull's direction table, see start_cell).
struct SupportHint {
  std::uint32_t vertex = kNoHullVertex;
};

// start_cell() and hull_support(): compiled here for the scalar paths (EPA, the test reference) and once more
// inside each SIMD instruction set's namespace (kernels/simd/isa_body.inl), where the wide GJK's large-hull lanes
// call them with that set's vector instructions. One text, the same arithmetic, the same bits.
#include "kernels/hull_support.inl"

template <class T> Vec3<T> sign_or_plus(const Vec3<T>& d) {
  return Vec3<T>(d.x() < T(0) ? T(-1) : T(1), d.y() < T(0) ? T(-1) : T(1), d.z() < T(0) ? T(-1) : T(1));
}

/// Support point of the core (radius excluded) in direction d (local frame). Halfspaces have no support
/// function (unbounded) and are handled by closed forms before GJK is reached.
template <class T> Vec3<T> support(const ShapeCore<T>& s, const Vec3<T>& d, SupportHint& hint) {
  switch (s.type) {
    case ShapeType::sphere: return Vec3<T>::Zero();
    case ShapeType::capsule: return Vec3<T>(T(0), T(0), d.z() < T(0) ? -s.size.y() : s.size.y());
    case ShapeType::box: return sign_or_plus(d).cwiseProduct(s.size);
    case ShapeType::cylinder: {
      const T rho = std::sqrt(d.x() * d.x() + d.y() * d.y());
      const T z = d.z() < T(0) ? -s.size.y() : s.size.y();
      // rho == 0: d is along the axis and every point of the cap is a maximiser; return the cap centre.
      if (rho == T(0)) return Vec3<T>(T(0), T(0), z);
      const T k = s.size.x() / rho;
      return Vec3<T>(d.x() * k, d.y() * k, z);
    }
    case ShapeType::cone: {
      const T rho = std::sqrt(d.x() * d.x() + d.y() * d.y());
      const T h = s.size.y();
      // Apex (0,0,h) against the best point of the base rim (r d_xy / rho, -h).
      if (h * d.z() >= -h * d.z() + s.size.x() * rho) return Vec3<T>(T(0), T(0), h);
      if (rho == T(0)) return Vec3<T>(T(0), T(0), -h);
      const T k = s.size.x() / rho;
      return Vec3<T>(d.x() * k, d.y() * k, -h);
    }
    case ShapeType::ellipsoid: {
      // argmax <x,d> on {x : |x ./ r| <= 1} is r.^2 .* d / |r .* d|.
      const Vec3<T> rd = s.size.cwiseProduct(d);
      const T n = norm3(rd);
      if (n == T(0)) return Vec3<T>::Zero();  // d == 0: every point maximises <x, 0>
      return s.size.cwiseProduct(rd) / n;
    }
    case ShapeType::convex: return hull_support(*s.hull, d, hint);
    case ShapeType::triangle: {
      const T d0 = dot3(s.triangle[0], d), d1 = dot3(s.triangle[1], d), d2 = dot3(s.triangle[2], d);
      if (d0 >= d1 && d0 >= d2) return s.triangle[0];
      return d1 >= d2 ? s.triangle[1] : s.triangle[2];
    }
    case ShapeType::halfspace: break;
  }
  return Vec3<T>::Zero();
}

}  // namespace batchcol::kernels
