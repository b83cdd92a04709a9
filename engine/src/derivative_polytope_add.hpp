// PolytopeLanes::add(), in a header so that hull_pair() (derivatives.cpp), the analytic hull pairs' path, gets it
// inlined together with StoreBlock::add_polytope() (both forced: with add() alone inline GCC kept add_polytope() out
// of line, +11 instructions a pair). Out of line, add() was 89.1 instructions per convex8 pair with its call; inlined,
// its body is 66.5 and the pair 2278.0 -> 2260.5 (callgrind AVX2, bench --case convex8-convex8 --regime distant
// --query witness --pairs 1024 --derivatives analytic, runs 8 - 5). Included by derivative_pairs.hpp, whose
// StoreBlock::add_polytope() is its one caller.
#pragma once

#include "derivative_ift.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <cstddef>

namespace batchcol::detail {

// PolytopeLanes: polytope_jacobians()'s closed forms with their case-dependent parts in P, G and W (see the header):
//   no flats: P = G = W = 0 (y = F / sd, both points rigid);   a has none: G = 0, W = I (dx_b = P F);
//   b has none: G = P [n]x, W = 0;   edge A of a, edge B of b: G = B' (A x n)^T / (A . B'), W = B A'^T / (B . A')
//   (A' = n x A, B' = n x B).
inline __attribute__((always_inline)) bool PolytopeLanes::add(std::size_t col, const PairGeometry& g) {
  const int ka = g.flats_a, kb = g.flats_b, k = ka + kb;
  const Eigen::Vector3d& nv = g.normal;
  const std::size_t l = count;
  // Each case stores the lane's 27 entries of P, G, W once, each an expression of its (i, j) that folds after
  // unrolling (zeros as stores of 0). Zeroing the 27 entries first and storing the case's over them cost ~170
  // instructions per hull pair (callgrind); building them in local arrays and copying those ~150.
  const auto put = [&](const auto& pf, const auto& gf, const auto& wf) __attribute__((always_inline)) {
#pragma GCC unroll 3
    for (int i = 0; i < 3; ++i)
#pragma GCC unroll 3
      for (int j = 0; j < 3; ++j) P[3 * i + j][l] = pf(i, j), G[3 * i + j][l] = gf(i, j), W[3 * i + j][l] = wf(i, j);
  };
  const auto zero = [](int, int) { return 0.0; };
  const auto identity = [](int i, int j) { return i == j ? 1.0 : 0.0; };
  const auto tangent = [&](int i, int j) { return (i == j ? 1.0 : 0.0) - nv(i) * nv(j); };  // I - n n^T
  if (k == 1) {  // one edge (flats are unit and orthogonal to n): P = c c^T; G = P [n]x = c (c x n)^T for a's edge
    const Eigen::Vector3d c = ka > 0 ? g.flat_a.col(0) : g.flat_b.col(0);
    const auto edge = [&](int i, int j) { return c(i) * c(j); };
    if (ka > 0) {
      const Eigen::Vector3d cn = c.cross(nv);
      put(edge, [&](int i, int j) { return c(i) * cn(j); }, zero);
    } else {
      put(edge, zero, identity);
    }
  } else if (k == 2) {  // two independent flats orthogonal to n span its tangent plane: P = I - n n^T
    if (ka == 1) {  // edge A against edge B; independent when A . (n x B) = +-|A x B| is not ~0 (polytope_jacobians'
                    // test: what is left of one unit flat after removing the other)
      const Eigen::Vector3d A = g.flat_a.col(0), B = g.flat_b.col(0);
      const Eigen::Vector3d B_perp = nv.cross(B), A_perp = nv.cross(A), An = A.cross(nv);
      const double s = A.dot(B_perp);
      if (!(std::abs(s) > 1e-6)) return false;
      const double t = B.dot(A_perp);
      put(tangent, [&](int i, int j) { return B_perp(i) * (An(j) / s); },
          [&](int i, int j) { return B(i) * (A_perp(j) / t); });
    } else if (ka == 2) {  // a's face against b's vertex: G = P [n]x = [n]x (n^T [n]x = 0)
      const double cross[9] = {0.0, -nv.z(), nv.y(), nv.z(), 0.0, -nv.x(), -nv.y(), nv.x(), 0.0};
      put(tangent, [&](int i, int j) { return cross[3 * i + j]; }, zero);
    } else {  // a's vertex against b's face
      put(tangent, zero, identity);
    }
  } else {  // no flats: both points rigid
    put(zero, zero, zero);
  }
  ++count;
  column[l] = col;
  sd[l] = g.distance;
  for (int i = 0; i < 3; ++i) n[i][l] = nv(i), xa[i][l] = g.witness_a(i), xb[i][l] = g.witness_b(i);
  return true;
}

}  // namespace batchcol::detail
