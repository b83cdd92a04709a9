// Support function of the Minkowski difference D = A - B of two shape cores, evaluated in the local frame of A
// (working relative to A keeps coordinates small for shapes far from the world origin).
// s_D(d) = s_A(d) - s_B(-d)  (Montaut, "Collision detection: an optimization perspective", talk part I).
#pragma once

#include "kernels/support.hpp"

namespace batchcol::kernels {

/// A support point of D together with the points of A and B it came from (all in A's frame).
template <class T> struct SupportPoint {
  Vec3<T> w, a, b;  // w = a - b
};

template <class T> struct MinkowskiDifference {
  const ShapeCore<T>* A;
  const ShapeCore<T>* B;
  Transform<T> b_in_a;  // pose of B's frame in A's frame
  mutable SupportHint hint_a, hint_b;

  /// Support point of D in direction d: maximises <w, d> over D.
  SupportPoint<T> support(const Vec3<T>& d) const {
    SupportPoint<T> p;
    p.a = kernels::support(*A, d, hint_a);
    const Vec3<T> d_in_b = mul_transposed<T>(b_in_a.R, -d);
    p.b = b_in_a.apply(kernels::support(*B, d_in_b, hint_b));
    p.w = p.a - p.b;
    return p;
  }

  /// A point of D's interior-ish: centre of A minus centre of B (seeds the first direction).
  Vec3<T> center() const { return A->center() - b_in_a.apply(B->center()); }
};

}  // namespace batchcol::kernels
