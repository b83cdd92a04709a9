// Entry points of the derivative API and the analytic / first-order-smoothed derivatives (derivatives.hpp).
#include "batchcol/derivatives.hpp"

#include "derivative_ift.hpp"
#include "derivative_pairs.hpp"
#include "derivative_support.hpp"
#include "shape_table_access.hpp"

#include <cmath>
#include <limits>
#include <string>

namespace batchcol {
namespace detail {

bool nominal_geometry(const ShapeTable& shapes, const PairBatch& batch, const PairResults& results, std::size_t i,
                      PairGeometry& g, Eigen::Matrix3d& R_a, Eigen::Matrix3d& R_b) {
  if (results.status[i] != Status::converged) return false;
  const std::uint32_t a = batch.shape_a[i], b = batch.shape_b[i];
  if (a >= shapes.size() || b >= shapes.size()) return false;
  const auto& types = ShapeTableAccess::types(shapes);
  if (types[a] == ShapeType::halfspace || types[b] == ShapeType::halfspace) return false;
  g.witness_a = results.witness_a[i];
  g.witness_b = results.witness_b[i];
  g.normal = results.normal[i];
  g.distance = results.distance[i];
  if (!g.witness_a.allFinite() || !g.witness_b.allFinite() || !g.normal.allFinite() || !std::isfinite(g.distance))
    return false;
  R_a = batch.rotation_a[i].normalized().toRotationMatrix();
  R_b = batch.rotation_b[i].normalized().toRotationMatrix();
  g.scale = ShapeTableAccess::bounding_radii(shapes)[a] + ShapeTableAccess::bounding_radii(shapes)[b];
  return true;
}

void StoreBlock::add(std::size_t i, const PairJacobians& J) {
  if (count_ > 0 && i != first_ + count_) flush();
  if (count_ == 0) first_ = i;
  J_[count_++] = J;
  if (count_ == kPairs) flush();
}

void StoreBlock::flush() {
  if (count_ == 0) return;
  const std::size_t n = d.status.size(), c = count_;
  const auto put6 = [&](Vec6Array& a, Row6 PairJacobians::*row) {
    for (int k = 0; k < 6; ++k) {
      double* p = a.data.data() + k * n + first_;
      for (std::size_t j = 0; j < c; ++j) p[j] = (J_[j].*row)(k);
    }
  };
  const auto put36 = [&](Mat36Array& a, Mat36 PairJacobians::*m) {
    for (int r = 0; r < 3; ++r)
      for (int col = 0; col < 6; ++col) {
        double* p = a.data.data() + (6 * r + col) * n + first_;
        for (std::size_t j = 0; j < c; ++j) p[j] = (J_[j].*m)(r, col);
      }
  };
  put6(d.distance_gradient_a, &PairJacobians::distance_a);
  put6(d.distance_gradient_b, &PairJacobians::distance_b);
  put36(d.witness_a_wrt_a, &PairJacobians::witness_a_a);
  put36(d.witness_a_wrt_b, &PairJacobians::witness_a_b);
  put36(d.witness_b_wrt_a, &PairJacobians::witness_b_a);
  put36(d.witness_b_wrt_b, &PairJacobians::witness_b_b);
  put36(d.normal_wrt_a, &PairJacobians::normal_a);
  put36(d.normal_wrt_b, &PairJacobians::normal_b);
  count_ = 0;
}

void store_nothing(StoreBlock& out, std::size_t i) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  PairJacobians J;
  J.distance_a.setConstant(nan);
  J.distance_b.setConstant(nan);
  for (Mat36* m : {&J.witness_a_a, &J.witness_a_b, &J.witness_b_a, &J.witness_b_b, &J.normal_a, &J.normal_b})
    m->setConstant(nan);
  out.add(i, J);
  DerivativeResults& d = out.d;
  d.status[i] = DerivativeStatus::no_witness;
  if (!d.smoothed_distance.empty()) {
    d.smoothed_distance[i] = nan;
    const Eigen::Vector3d v = Eigen::Vector3d::Constant(nan);
    d.smoothed_witness_a.set(i, v);
    d.smoothed_witness_b.set(i, v);
    d.smoothed_normal.set(i, v);
  }
}

void size_for(DerivativeResults& d, std::size_t n, bool smoothed) {
  d.status.resize(n);
  for (Vec6Array* v : {&d.distance_gradient_a, &d.distance_gradient_b}) v->data.resize(6 * n);
  for (Mat36Array* m : {&d.witness_a_wrt_a, &d.witness_a_wrt_b, &d.witness_b_wrt_a, &d.witness_b_wrt_b,
                        &d.normal_wrt_a, &d.normal_wrt_b})
    m->data.resize(18 * n);
  d.smoothed_distance.resize(smoothed ? n : 0);
  for (Vec3Array* v : {&d.smoothed_witness_a, &d.smoothed_witness_b, &d.smoothed_normal}) v->resize(smoothed ? n : 0);
}

namespace {

// One pair, analytic or smoothed1. The support directions are n for a and -n for b, taken to each local frame.
void differentiate_pair(const ShapeTable& shapes, const PairBatch& batch, const PairResults& results,
                        const DerivativeOptions& o, std::size_t i, StoreBlock& out) {
  DerivativeResults& d = out.d;
  PairGeometry g;
  Eigen::Matrix3d R_a, R_b;
  if (!nominal_geometry(shapes, batch, results, i, g, R_a, R_b)) {
    store_nothing(out, i);
    return;
  }
  const Shape& a = shapes[batch.shape_a[i]];
  const Shape& b = shapes[batch.shape_b[i]];
  const Eigen::Vector3d u_a = R_a.transpose() * g.normal, u_b = -(R_b.transpose() * g.normal);
  DerivativeStatus status = DerivativeStatus::smooth;
  if (o.method == DerivativeMethod::analytic) {
    const Eigen::Vector3d p_a = R_a.transpose() * (g.witness_a - batch.translation_a[i]);
    const Eigen::Vector3d p_b = R_b.transpose() * (g.witness_b - batch.translation_b[i]);
    const SupportJacobian J_a = support_jacobian(a, u_a, p_a), J_b = support_jacobian(b, u_b, p_b);
    g.H_a = R_a * J_a.H * R_a.transpose();
    g.H_b = R_b * J_b.H * R_b.transpose();
    g.flats_a = J_a.flats;
    g.flats_b = J_b.flats;
    g.flat_a = R_a * J_a.flat;
    g.flat_b = R_b * J_b.flat;
    if (J_a.approximate || J_b.approximate) {
      status = DerivativeStatus::nonsmooth;
    } else if (J_a.zero || J_b.zero) {
      status = DerivativeStatus::zero_curvature;
    }
  } else {
    const auto direction_noise = [&](const Shape& s) {
      return o.noise_scale == NoiseScale::relative ? o.noise : o.noise / s.bounding_radius();
    };
    g.H_a = R_a * smoothed_support_jacobian(a, u_a, direction_noise(a), o.samples, o.seed, i, 1) * R_a.transpose();
    g.H_b = R_b * smoothed_support_jacobian(b, u_b, direction_noise(b), o.samples, o.seed, i, 2) * R_b.transpose();
  }
  const PairJacobians J = implicit_jacobians(g);
  store(out, i, J);
  d.status[i] = J.dependent ? DerivativeStatus::nonsmooth : J.singular ? DerivativeStatus::singular : status;
}

void check_sizes(const PairBatch& batch, const PairResults& results) {
  const std::size_t n = batch.size();
  if (results.size() != n || results.distance.size() != n || results.witness_a.size() != n ||
      results.witness_b.size() != n || results.normal.size() != n)
    throw InputError("results: need one witness-level result per pair of the batch (" + std::to_string(n) +
                     " pairs; run collide() at QueryLevel::witness or penetration)");
}

}  // namespace
}  // namespace detail

void differentiate_results(const ShapeTable& shapes, const PairBatch& batch, const PairResults& results,
                           const DerivativeOptions& options, int threads, DerivativeResults& derivatives) {
  validate(options);
  if (options.method == DerivativeMethod::smoothed0)
    throw InputError("method: smoothed0 runs new queries; call differentiate() instead of differentiate_results()");
  if (threads < 0) throw InputError("threads must be >= 0 (0 = all cores)");
  detail::check_sizes(batch, results);
  detail::size_for(derivatives, batch.size(), false);  // every pair writes all its entries
  detail::for_pairs(threads, batch.size(), [&](std::size_t begin, std::size_t end) {
    detail::StoreBlock out(derivatives);
    for (std::size_t i = begin; i < end; ++i) detail::differentiate_pair(shapes, batch, results, options, i, out);
  });
}

void differentiate(const ShapeTable& shapes, const PairBatch& batch, const QueryOptions& query,
                   const DerivativeOptions& options, PairResults& results, DerivativeResults& derivatives) {
  validate(options);
  validate(query);
  if (query.level < QueryLevel::witness)
    throw InputError(std::string("level: derivatives need witness points (QueryLevel::witness or penetration), got ") +
                     to_string(query.level));
  collide(shapes, batch, query, results);
  if (options.method == DerivativeMethod::smoothed0) {
    detail::smoothed0(shapes, batch, query, options, results, derivatives);
  } else {
    differentiate_results(shapes, batch, results, options, query.threads, derivatives);
  }
}

}  // namespace batchcol
