// Support functions of the shape cores in their local frame: support(d) = argmax_{x in core} <x, d>.
// Frank-Wolfe / GJK only ever touches a shape through this function (Gilbert, Johnson, Keerthi 1988).
// Ties (d orthogonal to a face) may return any maximiser; every branch below returns a point of the core and
// never divides by a quantity that can be zero.
#pragma once

#include "kernels/shape_core.hpp"

#include <cstdint>

namespace batchcol::kernels {

/// Hulls with at least this many vertices use hill climbing over the vertex adjacency instead of a linear scan.
/// A scan costs one dot product per vertex; a climb costs ~ (path length x valence) dot products, which wins
/// once the hull is larger than a few dozen vertices (measured in the wide-kernel issue; 32 is the scalar choice).
constexpr std::size_t kHillClimbMinVertices = 32;

/// Per-query state of a support function: the last vertex found on a hull, where the next climb starts
/// (none yet: the climb starts from the hull's direction table, see start_cell).
struct SupportHint {
  std::uint32_t vertex = kNoHullVertex;
};

/// The cell of the hull's direction table (ConvexHull::start_vertices) that direction d falls in, or kNoHullVertex
/// when d has no direction (zero, NaN). The table is a cube map: d's largest component picks one of 6 faces, the
/// other two divided by it pick one of kHullStartGrid^2 cells. A climb started from the support vertex of the
/// cell's centre direction is a few moves from the answer; started from vertex 0 it crossed half the hull (measured:
/// hull_support was two thirds of a 250-vertex hull pair's instructions).
template <class T> inline std::uint32_t start_cell(const Vec3<T>& d) {
  const T x = d.x(), y = d.y(), z = d.z();
  const T ax = std::abs(x), ay = std::abs(y), az = std::abs(z);
  // The face: the largest |component| (first of equals), its sign; u, v: the next two components cyclically.
  std::uint32_t face = ay > ax ? 2u : 0u;
  T major = ay > ax ? ay : ax, u = ay > ax ? z : y, v = ay > ax ? x : z;
  if (az > major) face = 4u, major = az, u = x, v = y;
  if (!(major > T(0))) return kNoHullVertex;  // zero, or NaN (every comparison false)
  face += (face == 0u ? x : face == 2u ? y : z) < T(0) ? 1u : 0u;
  const T k = T(0.5 * kHullStartGrid) / major, half = T(0.5 * kHullStartGrid);
  const auto cell = [&](T c) {  // c / major in [-1, 1] -> [0, kHullStartGrid); NaN -> 0
    const T f = c * k + half;
    return f >= T(1) ? (f < T(kHullStartGrid) ? std::uint32_t(f) : kHullStartGrid - 1) : 0u;
  };
  return (face * kHullStartGrid + cell(u)) * kHullStartGrid + cell(v);
}

template <class T> Vec3<T> sign_or_plus(const Vec3<T>& d) {
  return Vec3<T>(d.x() < T(0) ? T(-1) : T(1), d.y() < T(0) ? T(-1) : T(1), d.z() < T(0) ? T(-1) : T(1));
}

template <class T> Vec3<T> hull_support(const ConvexHull& hull, const Vec3<T>& d, SupportHint& hint) {
  const auto& v = hull.vertices;
  const auto dot = [&](std::uint32_t i) { return dot3<T>(v[i].template cast<T>(), d); };
  std::uint32_t best = 0;
  if (v.size() < kHillClimbMinVertices) {
    T best_dot = dot(0);
    for (std::uint32_t i = 1; i < v.size(); ++i) {
      const T di = dot(i);
      if (di > best_dot) { best_dot = di; best = i; }
    }
  } else {
    // Hill climbing: on a convex polytope a vertex no neighbour improves on is a global maximiser. The strict
    // '>' guarantees termination (the dot product increases at every move).
    // Start from the better of the previous support vertex and the direction table's vertex: GJK's directions
    // swing by up to 180 degrees in the first iterations, and a climb from the previous vertex then crosses the
    // hull (measured: ~500 instructions per support on 250 vertices), while the table's vertex is within a cell
    // (~14 degrees) of the answer.
    best = hint.vertex < v.size() ? hint.vertex : 0;
    T best_dot = dot(best);
    if (hull.start_vertices.size() == kHullStartCells) {
      const std::uint32_t c = start_cell(d);
      if (c != kNoHullVertex && hull.start_vertices[c] < v.size()) {
        const std::uint32_t t = hull.start_vertices[c];
        const T dt = dot(t);
        if (hint.vertex >= v.size() || dt > best_dot) best = t, best_dot = dt;
      }
    }
    constexpr std::uint32_t B = ConvexHull::kNeighborBlock;
    if (hull.neighbor_block_offsets.size() == v.size() + 1) {
      // The same steepest-ascent steps, a block of neighbours at a time: the first neighbour with the largest dot
      // product, taken when it beats the current vertex strictly (as the loop below), with one branch per block
      // instead of one unpredictable branch per neighbour.
      const std::uint32_t* offsets = hull.neighbor_block_offsets.data();
      const std::uint32_t* index = hull.neighbor_block_index.data();
      const double* xyz = hull.neighbor_block_xyz.data();
      for (bool moved = true; moved;) {
        moved = false;
        const std::uint32_t from = best;
        for (std::uint32_t b = offsets[from]; b < offsets[from + 1]; ++b) {
          const double* p = xyz + 3 * B * b;
          T dots[B];
          for (std::uint32_t j = 0; j < B; ++j)
            dots[j] = (T(p[j]) * d.x() + T(p[B + j]) * d.y()) + T(p[2 * B + j]) * d.z();
          T top = dots[0];
          for (std::uint32_t j = 1; j < B; ++j) top = dots[j] > top ? dots[j] : top;
          if (!(top > best_dot)) continue;
          std::uint32_t j = 0;
          while (!(dots[j] == top)) ++j;  // top is one of dots[] and not NaN (it beat best_dot)
          best_dot = top;
          best = index[B * b + j];
          moved = true;
        }
      }
      hint.vertex = best;
      return v[best].template cast<T>();
    }
    for (bool moved = true; moved;) {
      moved = false;
      const std::uint32_t from = best;  // the loop bounds must not follow `best` while it moves
      for (std::uint32_t k = hull.neighbor_offsets[from]; k < hull.neighbor_offsets[from + 1]; ++k) {
        const std::uint32_t n = hull.neighbors[k];
        const T dn = dot(n);
        if (dn > best_dot) { best_dot = dn; best = n; moved = true; }
      }
    }
    hint.vertex = best;
  }
  return v[best].template cast<T>();
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
