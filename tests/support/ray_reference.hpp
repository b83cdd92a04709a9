// An independent reference for ray queries: a 1-Lipschitz lower bound phi of the signed distance to each shape (exact
// on the surface: phi = 0 there, phi < 0 inside), written from the shape definitions without the ray kernels, and
// sphere tracing on it (Hart 1996): stepping by phi never crosses the surface, so the first t where phi falls below
// a threshold is the first hit up to that threshold.
#pragma once

#include "batchcol/batchcol.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

namespace batchcol::testing {

/// phi in the shape's local frame (inflation included). Outside inflated shapes it is the exact distance minus the
/// inflation (hulls: to the nearest face triangle; cones: to the revolved 2-D triangle; ellipsoids: Eberly's
/// bisection), so that its zero set is the inflated surface.
double shape_phi(const Shape& shape, const Eigen::Vector3d& p);

struct TraceResult {
  bool hit = false;
  double t = 0.0;
  bool converged = true;  // false: the step budget ran out (a grazing ray); the caller skips the ray
};
/// First t in [0, t_max] with phi(o + t d) <= eps (unit-speed steps phi / |d|).
TraceResult sphere_trace(const Shape& shape, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_max,
                         double eps = 1e-12, int max_steps = 2000000);

/// The exact entry of the segment o + t d, t in [0, t_max], into the closed box [lo, hi], in double (slabs; a zero
/// direction component keeps the box only when o lies within that slab); +inf when the segment misses the box.
inline double exact_box_entry(const double o[3], const double d[3], const double lo[3], const double hi[3],
                              double t_max = INFINITY) {
  double t0 = 0.0, t1 = t_max;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0.0) {
      if (o[k] < lo[k] || o[k] > hi[k]) return INFINITY;
      continue;
    }
    double a = (lo[k] - o[k]) / d[k], c = (hi[k] - o[k]) / d[k];
    if (a > c) std::swap(a, c);
    t0 = std::max(t0, a), t1 = std::min(t1, c);
  }
  return t0 <= t1 ? t0 : INFINITY;
}

}  // namespace batchcol::testing
