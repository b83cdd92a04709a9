// Derivatives of collision queries with respect to the shapes' poses (Part III of the seed talk; Montaut, Le Lidec,
// Bambade, Petrik, Sivic, Carpentier, "Differentiable collision detection: a randomized smoothing approach", 2023).
//
// Twist convention. A perturbation of a pose T = (R, t) is a 6-vector xi = (v, w) = (linear, angular) in the WORLD
// frame, applied on the left: T <- exp(xi) T. To first order a point p fixed on the body moves by v + w x p (w x p is
// the cross product), the rotation becomes (I + [w]x) R and the translation t + v + w x t. Every derivative below is
// d(quantity) / d(xi) at xi = 0, a row (distance) or a 3x6 matrix (points, normal) whose columns 0-2 are v and 3-5 w.
// With this convention moving both shapes by the same twist is a rigid motion of the scene, so for every pair
// J_a + J_b = [I, -[x]x] for a witness point x, [0, -[n]x] for the normal, and the distance gradients sum to zero.
//
// Methods:
//  analytic   The distance gradient by the envelope theorem (the normal times the motion of the witness points held
//             fixed on their bodies), the witness-point and normal Jacobians by the implicit function theorem on the
//             optimality condition z = S_B(-z) - S_A(z) (z = witness_b - witness_a), using the Jacobian of each
//             support map (the Hessian of the support function; a face or edge the witness lies on counts as
//             infinite curvature along it, whose limit is taken exactly). DerivativeStatus says where the
//             derivative is undefined or uninformative.
//  smoothed0  Randomized smoothing of order 0: M perturbed copies of every pair (shape b's pose perturbed by Gaussian
//             noise on se(3) about its own origin, the noise drawn in shape a's frame) run through the batched
//             SIMD GJK with the query's options (each sample answered as collide() would answer that pose, to
//             the query's tolerance); the smoothed values are the
//             sample means and their gradients the Gaussian score-function estimator, with antithetic samples
//             (sample 2k+1 uses -z of sample 2k) and the unperturbed query as baseline: grad = 1/M sum_j
//             (g(T + S z_j) - g(T)) (S^-1 z_j)^T. For even M the baseline cancels within each antithetic pair; an
//             odd M's last sample keeps it. Derivatives with respect to shape a follow from the rigid-motion
//             identity above (the noise distribution is isotropic, so the smoothed query is invariant under a
//             rigid motion of the whole scene).
//  smoothed1  Randomized smoothing of order 1 (the slide "Randomized smoothing - 1st order"): the analytic
//             implicit-function Jacobians with each support map's Jacobian replaced by its smoothed estimate
//             E[S(n + e z) z^T] / e from M antithetic support evaluations per shape and pair (no extra GJK runs;
//             symmetrised and projected onto the positive semidefinite cone, as the Hessian of a convex function
//             is). Polytopes get non-zero, informative witness Jacobians where the analytic ones are zero.
//
// Noise scale. NoiseScale::relative (the default): translation noise epsilon * r (metres) and rotation noise
// epsilon (radians), where r is the bounding radius of the perturbed shape (b for smoothed0, each shape for the
// support directions of smoothed1, whose direction noise is epsilon radians); both move the shape's surface by about
// epsilon * r. NoiseScale::absolute: epsilon is that surface motion in metres (translation epsilon, rotation and
// direction noise epsilon / r).
#pragma once

#include "batchcol/export.hpp"

#include "batchcol/batch.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <new>
#include <string>
#include <vector>

namespace batchcol {

enum class DerivativeMethod : std::uint8_t { analytic, smoothed0, smoothed1 };
enum class NoiseScale : std::uint8_t { relative, absolute };

BATCHCOL_API const char* to_string(DerivativeMethod method);
BATCHCOL_API const char* to_string(NoiseScale scale);
/// The inverses of to_string(); InputError naming "method" / "noise_scale" for an unknown name.
BATCHCOL_API DerivativeMethod parse_derivative_method(const std::string& name);
BATCHCOL_API NoiseScale parse_noise_scale(const std::string& name);

/// The most samples per pair.
constexpr int kMaxDerivativeSamples = 1 << 20;

struct DerivativeOptions {
  DerivativeMethod method = DerivativeMethod::analytic;
  int samples = 16;        // 1 <= M <= kMaxDerivativeSamples (smoothed methods only; ignored by analytic)
  double noise = 1e-2;     // epsilon > 0 and finite (smoothed methods only), see "Noise scale" above
  NoiseScale noise_scale = NoiseScale::relative;
  std::uint64_t seed = 0;  // samples come from a counter-based generator keyed by (seed, pair, sample): results
                           // depend on the seed only, never on the thread count or the batch split
  /// false: the distance gradients only (method analytic only; InputError naming "jacobians" otherwise). The six
  /// Jacobian arrays of DerivativeResults are left empty, the witness points' features are not examined, and the
  /// status is smooth (gradient computed) or no_witness. The gradient is the envelope formula, bitwise the one the
  /// full analytic derivative gives; where the witness points are not unique (face against face: the full
  /// derivative says nonsmooth) it is one subgradient. It costs a pass over the witness results and 12 stores per
  /// pair instead of the features, the implicit-function solve and 120 stores.
  bool jacobians = true;
};

/// Throws InputError naming the option when `options` is invalid (samples < 1 or too many, noise <= 0 or not
/// finite, jacobians false with a smoothed method).
BATCHCOL_API void validate(const DerivativeOptions& options);

/// Per-pair derivative status. Values are NaN when the status says nothing was computed.
enum class DerivativeStatus : std::uint8_t {
  smooth,          // exact (analytic; including a witness on a face or edge of a polytope, a capsule's, cylinder's
                   // or cone's side, whose support map jumps: taken as infinite curvature along it, the limit is
                   // exact) /
                   // computed from all samples (smoothed)
  zero_curvature,  // analytic: a witness is a vertex of a non-inflated polytope (its support map is locally
                   // constant): the derivative is exact, but that witness only moves rigidly with its body, which
                   // is the uninformative derivative smoothed1 replaces
  nonsmooth,       // analytic: the witness points are not unique (face against face, parallel edges, an edge on a
                   // face): Jacobians NaN; the distance gradient is given (its angular part is one subgradient).
  singular,        // the implicit-function system is singular (touching without curvature, some penetrating
                   // pairs): Jacobians NaN, the distance gradient is given
  partial_samples, // smoothed0: some perturbed samples had no witness (e.g. overlapping below the penetration
                   // level); the estimates average the others
  no_witness,      // the query gave the pair no witness points (invalid input, not converged, overlap below
                   // QueryLevel::penetration, a halfspace shape): nothing computed
};
BATCHCOL_API const char* to_string(DerivativeStatus status);

/// The allocator of the derivative arrays: storage that starts on a 64-byte boundary (an x86 cache line, an AVX-512
/// register). The analytic derivative writes 120 doubles per pair, eight pairs of one row a register; from a
/// malloc'd start (16 bytes into a line) every such store split over two lines, which cost about half a witness
/// query per pair (perf cpu-clock samples, AMD EPYC Zen 4, bench/results/history/derivatives-sessions.md).
template <class T> struct CacheLineAllocator {
  using value_type = T;
  static constexpr std::size_t kAlignment = 64;
  CacheLineAllocator() = default;
  template <class U> CacheLineAllocator(const CacheLineAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t{kAlignment}));
  }
  void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, std::align_val_t{kAlignment}); }
  template <class U> bool operator==(const CacheLineAllocator<U>&) const noexcept { return true; }
  template <class U> bool operator!=(const CacheLineAllocator<U>&) const noexcept { return false; }
};

/// The storage of Vec6Array and Mat36Array: a std::vector whose data() is 64-byte aligned.
using LineAlignedDoubles = std::vector<double, CacheLineAllocator<double>>;

/// Structure-of-arrays storage of one 6-vector per pair: component k of pair i at data[k * size + i]. `data`
/// starts on a 64-byte boundary, and so does every row when the pair count is a multiple of 8.
struct BATCHCOL_API Vec6Array {
  LineAlignedDoubles data;
  std::size_t size() const { return data.size() / 6; }
  void resize(std::size_t n, double value) { data.assign(6 * n, value); }
  double& at(std::size_t i, int k) { return data[k * size() + i]; }
  Eigen::Matrix<double, 1, 6> operator[](std::size_t i) const;
  void set(std::size_t i, const Eigen::Matrix<double, 1, 6>& g);
};

/// Structure-of-arrays storage of one 3x6 matrix per pair: entry (r, c) of pair i at data[(6 r + c) * size + i].
/// `data` starts on a 64-byte boundary (as Vec6Array's).
struct BATCHCOL_API Mat36Array {
  LineAlignedDoubles data;
  std::size_t size() const { return data.size() / 18; }
  void resize(std::size_t n, double value) { data.assign(18 * n, value); }
  Eigen::Matrix<double, 3, 6> operator[](std::size_t i) const;
  void set(std::size_t i, const Eigen::Matrix<double, 3, 6>& m);
};

/// Derivatives per pair in input order. `_wrt_a` / `_wrt_b`: with respect to the twist of shape a / b.
struct BATCHCOL_API DerivativeResults {
  std::vector<DerivativeStatus> status;
  Vec6Array distance_gradient_a, distance_gradient_b;  // d(signed distance) / d(xi)
  Mat36Array witness_a_wrt_a, witness_a_wrt_b;         // d(witness_a) / d(xi)
  Mat36Array witness_b_wrt_a, witness_b_wrt_b;         // d(witness_b) / d(xi)
  Mat36Array normal_wrt_a, normal_wrt_b;               // d(normal) / d(xi); all six empty when jacobians is false
  /// smoothed0 only (empty otherwise): the smoothed values, means over the samples (the mean normal is not unit).
  std::vector<double> smoothed_distance;
  Vec3Array smoothed_witness_a, smoothed_witness_b, smoothed_normal;

  std::size_t size() const { return status.size(); }
  /// n pairs of no_witness and NaN; the smoothed arrays only when `smoothed` is true.
  void resize(std::size_t n, bool smoothed);
};

/// Runs collide(shapes, batch, query, results) and the derivatives of every pair. query.level must be witness or
/// penetration (InputError naming "level" otherwise); derivative options are validated as by validate(). smoothed0
/// runs the M perturbed copies of every pair through the SIMD GJK in blocks of 1024 samples with the same query
/// options, each started from the direction the analytic normal Jacobian predicts for its perturbation (pairs with
/// a curved side) or from the unperturbed query's. Results are bitwise identical for any thread count.
BATCHCOL_API void differentiate(const ShapeTable& shapes, const PairBatch& batch, const QueryOptions& query,
                   const DerivativeOptions& options, PairResults& results, DerivativeResults& derivatives);

/// The analytic or smoothed1 derivatives from an existing witness-level (or penetration) query `results` of
/// `batch` (no new GJK run). smoothed0 needs new queries: use differentiate(). Throws InputError when sizes differ,
/// the witness arrays are empty or the method is smoothed0.
BATCHCOL_API void differentiate_results(const ShapeTable& shapes, const PairBatch& batch, const PairResults& results,
                           const DerivativeOptions& options, int threads, DerivativeResults& derivatives);

}  // namespace batchcol
