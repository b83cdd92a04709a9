// Randomized smoothing of order 0 (Montaut et al. 2023, sec. III; the slides "Randomized smoothing" and "- 0th
// order"): the M perturbed copies of every pair go through collide() as one batch (per chunk of 2^20 samples), so
// the SIMD lanes, the type grouping and the thread pool serve the samples exactly as they serve user pairs, and each
// copy starts GJK from the unperturbed query's final direction.
#include "counter_rng.hpp"
#include "derivative_pairs.hpp"
#include "shape_table_access.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace batchcol::detail {
namespace {

// Samples per collide() call: bounds the temporary batch and results (~250 bytes per sample) to ~250 MB.
constexpr std::size_t kSamplesPerCall = static_cast<std::size_t>(kMaxDerivativeSamples);

struct Noise {
  double translation = 0.0, rotation = 0.0;  // standard deviations: metres, radians
};

Noise noise_of(const ShapeTable& shapes, std::uint32_t b, const DerivativeOptions& o) {
  const double r = b < shapes.size() ? ShapeTableAccess::bounding_radii(shapes)[b] : 1.0;
  if (!std::isfinite(r) || !(r > 0.0)) return {0.0, 0.0};  // halfspace b: the pair is not differentiated
  return o.noise_scale == NoiseScale::relative ? Noise{o.noise * r, o.noise} : Noise{o.noise, o.noise / r};
}

// Shape b's pose perturbed about its own origin: t + s_t z_v, q R with q = exp(s_w z_w).
void perturb(const PairBatch& batch, std::size_t i, const Noise& s, const double z[6], const Eigen::Quaterniond& q,
             PairBatch& out, std::size_t k) {
  out.shape_a[k] = batch.shape_a[i];
  out.shape_b[k] = batch.shape_b[i];
  out.translation_a.set(k, batch.translation_a[i]);
  out.rotation_a.set(k, batch.rotation_a[i]);
  out.translation_b.set(k, batch.translation_b[i] + s.translation * Eigen::Vector3d(z[0], z[1], z[2]));
  out.rotation_b.set(k, (q * batch.rotation_b[i]).normalized());
}

// Fills the samples of pairs [first, first + count) and their standard normal noise (6 per sample, in `noise`).
// Sample 2k draws z from the key (seed, pair, k); sample 2k+1 is its antithetic copy -z, whose rotation is the
// inverse (conjugate) of sample 2k's: one draw and one exponential serve both.
void build_samples(const ShapeTable& shapes, const PairBatch& batch, const PairResults& results,
                   const DerivativeOptions& o, int threads, std::size_t first, std::size_t count, PairBatch& out,
                   std::vector<double>& noise) {
  const std::size_t M = static_cast<std::size_t>(o.samples), total = count * M;
  out.shape_a.resize(total);
  out.shape_b.resize(total);
  for (Vec3Array* v : {&out.translation_a, &out.translation_b, &out.warm_start}) v->resize(total);
  out.rotation_a.resize(total);
  out.rotation_b.resize(total);
  noise.resize(6 * total);
  const bool warm = results.direction.size() == batch.size();
  if (!warm) out.warm_start = Vec3Array();
  for_pairs(threads, count, [&](std::size_t begin, std::size_t end) {
    for (std::size_t p = begin; p < end; ++p) {
      const std::size_t i = first + p;
      const Noise s = noise_of(shapes, batch.shape_b[i], o);
      for (std::size_t j = 0; j < M; j += 2) {
        double* z = &noise[6 * (p * M + j)];
        gaussian_vector<6>(o.seed, i, j / 2, 0, z);
        const Eigen::Vector3d w = s.rotation * Eigen::Vector3d(z[3], z[4], z[5]);
        const double angle = w.norm();
        const Eigen::Quaterniond q = angle > 0.0 ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, w / angle))
                                                 : Eigen::Quaterniond::Identity();
        perturb(batch, i, s, z, q, out, p * M + j);
        if (j + 1 < M) {
          double* minus = z + 6;
          for (int k = 0; k < 6; ++k) minus[k] = -z[k];
          perturb(batch, i, s, minus, q.conjugate(), out, p * M + j + 1);
        }
      }
      if (warm)
        for (std::size_t j = 0; j < M; ++j) out.warm_start.set(p * M + j, results.direction[i]);
    }
  });
}

using Values = Eigen::Matrix<double, 10, 1>;  // signed distance, witness a, witness b, normal

bool sample_values(const PairResults& r, std::size_t k, Values& v) {
  if (r.status[k] != Status::converged) return false;
  v << r.distance[k], r.witness_a[k], r.witness_b[k], r.normal[k];
  return v.allFinite();
}

void reduce_pair(const ShapeTable& shapes, const PairBatch& batch, const PairResults& results,
                 const DerivativeOptions& o, std::size_t i, const PairResults& samples, std::size_t first_sample,
                 const double* noise, StoreBlock& out) {
  DerivativeResults& d = out.d;
  PairGeometry g;
  Eigen::Matrix3d R_a, R_b;
  if (!nominal_geometry(shapes, batch, results, i, g, R_a, R_b)) return store_nothing(out, i);
  const Noise s = noise_of(shapes, batch.shape_b[i], o);
  if (!(s.translation > 0.0)) return store_nothing(out, i);
  Values g0, v, mean = Values::Zero();
  g0 << g.distance, g.witness_a, g.witness_b, g.normal;
  Eigen::Matrix<double, 10, 6> G = Eigen::Matrix<double, 10, 6>::Zero();
  int valid = 0;
  for (int j = 0; j < o.samples; ++j) {
    if (!sample_values(samples, first_sample + j, v)) continue;
    const double* z = noise + 6 * j;
    Eigen::Matrix<double, 1, 6> score;  // S^-1 z: the score of the Gaussian over the noise scale
    score << z[0] / s.translation, z[1] / s.translation, z[2] / s.translation, z[3] / s.rotation,
        z[4] / s.rotation, z[5] / s.rotation;
    mean += v;
    G += (v - g0) * score;
    ++valid;
  }
  if (valid == 0) return store_nothing(out, i);
  mean /= valid;
  G /= valid;
  // The noise moved b about its own origin t_b: a world twist (v, w) is the noise coordinates (v - [t_b]x w, w).
  const Eigen::Vector3d t_b = batch.translation_b[i];
  G.rightCols<3>() -= G.leftCols<3>() * skew(t_b);
  PairJacobians J;
  J.distance_b = G.row(0);
  J.distance_a = -J.distance_b;
  J.witness_a_b = G.middleRows<3>(1);
  J.witness_b_b = G.middleRows<3>(4);
  J.normal_b = G.middleRows<3>(7);
  const Eigen::Vector3d xa = mean.segment<3>(1), xb = mean.segment<3>(4), n = mean.segment<3>(7);
  J.witness_a_a = rigid_motion(xa) - J.witness_a_b;
  J.witness_b_a = rigid_motion(xb) - J.witness_b_b;
  J.normal_a = (Mat36() << Eigen::Matrix3d::Zero(), -skew(n)).finished() - J.normal_b;
  store(out, i, J);
  d.smoothed_distance[i] = mean(0);
  d.smoothed_witness_a.set(i, xa);
  d.smoothed_witness_b.set(i, xb);
  d.smoothed_normal.set(i, n);
  d.status[i] = valid == o.samples ? DerivativeStatus::smooth : DerivativeStatus::partial_samples;
}

}  // namespace

void smoothed0(const ShapeTable& shapes, const PairBatch& batch, const QueryOptions& query,
               const DerivativeOptions& o, const PairResults& results, DerivativeResults& d) {
  const std::size_t n = batch.size(), M = static_cast<std::size_t>(o.samples);
  size_for(d, n, true);  // every pair writes all its entries
  const std::size_t chunk = std::max<std::size_t>(1, kSamplesPerCall / M);
  PairBatch samples;
  PairResults sample_results;
  std::vector<double> noise;
  for (std::size_t first = 0; first < n; first += chunk) {
    const std::size_t count = std::min(chunk, n - first);
    build_samples(shapes, batch, results, o, query.threads, first, count, samples, noise);
    collide(shapes, samples, query, sample_results);
    for_pairs(query.threads, count, [&](std::size_t begin, std::size_t end) {
      StoreBlock out(d);
      for (std::size_t p = begin; p < end; ++p)
        reduce_pair(shapes, batch, results, o, first + p, sample_results, p * M, &noise[6 * p * M], out);
    });
  }
}

}  // namespace batchcol::detail
