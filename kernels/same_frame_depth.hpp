// Penetration depth of two ellipsoid cores in the same frame (the same centre and axes: e.g. two bodies placed at
// one pose), in closed form (issue #16, item 10): D = A + B is then nearly a ball for sphere-like ellipsoids, whose
// minimal directions form a (near) continuum that EPA must refine everywhere; it ended max_iterations.
//
// With the same centre and axes, radii a and b, the depth is min over unit n of |a .* n| + |b .* n|. As a
// function of (n_x^2, n_y^2, n_z^2) on the simplex each term is the square root of a linear function, concave, so
// the sum is concave and its minimum is at a vertex: an axis i, depth a_i + b_i.
// A relative pose (R, t) off the identity changes every h_D(n) = h_A(n) + h_B(-R^T n) - n.t by at most
// |t| + max(b) |R - I| (2-norm, bounded by Frobenius'), so the closed form is used when that bound is within half
// the tolerance: the depth is then certified, as EPA's would be.
#pragma once

#include "kernels/epa.hpp"

#include <cmath>

namespace batchcol::kernels {

template <class T>
bool same_frame_ellipsoids_depth(const ShapeCore<T>& A, const ShapeCore<T>& B, const Transform<T>& X, T tolerance,
                                 EpaResult<T>& e) {
  if (A.type != ShapeType::ellipsoid || B.type != ShapeType::ellipsoid) return false;
  T frobenius = T(0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const T dev = X.R(i, j) - (i == j ? T(1) : T(0));
      frobenius += dev * dev;
    }
  const T deviation = norm3(X.t) + B.size.maxCoeff() * std::sqrt(frobenius);
  if (!(deviation <= tolerance / T(2))) return false;
  int axis = 0;
  e.depth = (A.size + B.size).minCoeff(&axis);
  e.normal = Vec3<T>::Unit(axis);
  e.witness_a = A.size[axis] * e.normal;
  e.witness_b = e.witness_a - e.depth * e.normal;  // -b_i e_i: B's point, in A's frame up to the deviation
  e.status = EpaStatus::converged;
  e.iterations = 0;
  return true;
}

}  // namespace batchcol::kernels
