// Names, validation and storage of the derivative API (derivatives.hpp).
#include "batchcol/derivatives.hpp"

#include <cmath>
#include <limits>
#include <string>

namespace batchcol {

const char* to_string(DerivativeMethod method) {
  switch (method) {
    case DerivativeMethod::analytic: return "analytic";
    case DerivativeMethod::smoothed0: return "smoothed0";
    case DerivativeMethod::smoothed1: return "smoothed1";
  }
  return "?";
}

const char* to_string(NoiseScale scale) { return scale == NoiseScale::relative ? "relative" : "absolute"; }

DerivativeMethod parse_derivative_method(const std::string& name) {
  for (DerivativeMethod m : {DerivativeMethod::analytic, DerivativeMethod::smoothed0, DerivativeMethod::smoothed1})
    if (name == to_string(m)) return m;
  throw InputError("method: unknown derivative method '" + name + "' (analytic, smoothed0 or smoothed1)");
}

NoiseScale parse_noise_scale(const std::string& name) {
  for (NoiseScale n : {NoiseScale::relative, NoiseScale::absolute})
    if (name == to_string(n)) return n;
  throw InputError("noise_scale: unknown noise scale '" + name + "' (relative or absolute)");
}

const char* to_string(DerivativeStatus status) {
  switch (status) {
    case DerivativeStatus::smooth: return "smooth";
    case DerivativeStatus::zero_curvature: return "zero_curvature";
    case DerivativeStatus::nonsmooth: return "nonsmooth";
    case DerivativeStatus::singular: return "singular";
    case DerivativeStatus::partial_samples: return "partial_samples";
    case DerivativeStatus::no_witness: return "no_witness";
  }
  return "?";
}

void validate(const DerivativeOptions& o) {
  if (o.samples < 1) throw InputError("samples must be >= 1, got " + std::to_string(o.samples));
  // One pair's samples must fit one collide() call of the smoothed0 chunking (derivative_smoothed0.cpp).
  if (o.samples > kMaxDerivativeSamples)
    throw InputError("samples must be <= " + std::to_string(kMaxDerivativeSamples) + ", got " +
                     std::to_string(o.samples));
  if (!std::isfinite(o.noise) || !(o.noise > 0.0))
    throw InputError("noise must be a finite number > 0, got " + std::to_string(o.noise));
  if (o.method != DerivativeMethod::analytic && o.method != DerivativeMethod::smoothed0 &&
      o.method != DerivativeMethod::smoothed1)
    throw InputError("method must be analytic, smoothed0 or smoothed1");
  if (o.noise_scale != NoiseScale::relative && o.noise_scale != NoiseScale::absolute)
    throw InputError("noise_scale must be relative or absolute");
  // smoothed1's distance gradient is the analytic one (the envelope theorem does not involve the curvature), and
  // smoothed0 estimates every output from the same samples: gradients alone are only a separate path for analytic.
  if (!o.jacobians && o.method != DerivativeMethod::analytic)
    throw InputError(std::string("jacobians: false (distance gradients only) needs method analytic, got ") +
                     to_string(o.method));
}

Eigen::Matrix<double, 1, 6> Vec6Array::operator[](std::size_t i) const {
  Eigen::Matrix<double, 1, 6> g;
  for (int k = 0; k < 6; ++k) g(k) = data[k * size() + i];
  return g;
}

void Vec6Array::set(std::size_t i, const Eigen::Matrix<double, 1, 6>& g) {
  for (int k = 0; k < 6; ++k) data[k * size() + i] = g(k);
}

Eigen::Matrix<double, 3, 6> Mat36Array::operator[](std::size_t i) const {
  Eigen::Matrix<double, 3, 6> m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 6; ++c) m(r, c) = data[(6 * r + c) * size() + i];
  return m;
}

void Mat36Array::set(std::size_t i, const Eigen::Matrix<double, 3, 6>& m) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 6; ++c) data[(6 * r + c) * size() + i] = m(r, c);
}

void DerivativeResults::resize(std::size_t n, bool smoothed) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  status.assign(n, DerivativeStatus::no_witness);
  distance_gradient_a.resize(n, nan);
  distance_gradient_b.resize(n, nan);
  for (Mat36Array* m : {&witness_a_wrt_a, &witness_a_wrt_b, &witness_b_wrt_a, &witness_b_wrt_b, &normal_wrt_a,
                        &normal_wrt_b})
    m->resize(n, nan);
  smoothed_distance.assign(smoothed ? n : 0, nan);
  for (Vec3Array* v : {&smoothed_witness_a, &smoothed_witness_b, &smoothed_normal}) {
    v->x.clear(), v->y.clear(), v->z.clear();
    v->resize(smoothed ? n : 0, nan);
  }
}

}  // namespace batchcol
