// An independent reference for ray queries: a 1-Lipschitz lower bound phi of the signed distance to each shape (exact
// on the surface: phi = 0 there, phi < 0 inside), written from the shape definitions without the ray kernels, and
// sphere tracing on it (Hart 1996): stepping by phi never crosses the surface, so the first t where phi falls below
// a threshold is the first hit up to that threshold.
#pragma once

#include "batchcol/batchcol.hpp"

#include <optional>

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

}  // namespace batchcol::testing
