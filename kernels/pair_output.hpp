// What a narrow-phase kernel returns for one pair, in the local frame of shape A.
#pragma once

#include "batchcol/types.hpp"
#include "kernels/math.hpp"

namespace batchcol::kernels {

template <class T> struct PairOutput {
  Status status = Status::converged;
  bool collide = false;
  T distance = quiet_nan<T>();                                  // signed; NaN when not computed
  Vec3<T> witness_a = Vec3<T>::Constant(quiet_nan<T>());
  Vec3<T> witness_b = Vec3<T>::Constant(quiet_nan<T>());
  Vec3<T> normal = Vec3<T>::Constant(quiet_nan<T>());           // unit, from A to B
  Vec3<T> direction = Vec3<T>::Constant(quiet_nan<T>());        // GJK's last search direction (warm start)
  int iterations = 0;
};

}  // namespace batchcol::kernels
