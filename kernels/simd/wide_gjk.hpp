// Entry points of the SIMD narrow phase: GJK for many pairs of one shape-pair type, one pair per lane, compiled
// once per instruction set (isa_scalar.cpp, isa_avx2.cpp, isa_avx512.cpp) and chosen at run time from the CPU.
#pragma once

#include "batchcol/types.hpp"
#include "kernels/narrowphase.hpp"
#include "kernels/simd/pair_views.hpp"

#include <cstddef>

namespace batchcol::kernels::simd {

/// (batchcol::resolve_instruction_set() in batch.hpp turns a request into one of these.)
/// The best instruction set of this CPU among those batchcol is compiled for (scalar, avx2, avx512).
InstructionSet detected_instruction_set();
/// True when this CPU can run `isa`.
bool cpu_has(InstructionSet isa);
/// Lanes per register for precision T in instruction set `isa` (1 for scalar).
int lane_count(InstructionSet isa, Precision precision);

/// Runs GJK on setups[0 .. n) with results in out[0 .. n): every setup must need GJK (done == false) and all must
/// have the same shape types. Each result is bitwise the test reference's (tests/support/reference_gjk.hpp) on the same setup. With `points` false
/// the simplex keeps only w = a - b (enough below QueryLevel::witness, and cheaper): its a and b come back NaN.
/// `solver` is the one the setups were made with (resolve_solver's answer; `automatic` throws).
template <class T>
void gjk_lanes(InstructionSet isa, const PairSetup<T>* setups, std::size_t n, GjkResult<T>* out, Solver solver,
               bool points = true);

template <>
void gjk_lanes<double>(InstructionSet, const PairSetup<double>*, std::size_t, GjkResult<double>*, Solver, bool);
template <>
void gjk_lanes<float>(InstructionSet, const PairSetup<float>*, std::size_t, GjkResult<float>*, Solver, bool);

/// The large-hull supports' direction-table cells (WideGjk::start_cells) of directions xyz[3 i .. 3 i + 3),
/// i < n, computed W at a time as the GJK loop does: for the tests, which check them against start_cell().
template <class T> void start_cells_lanes(InstructionSet isa, const T* xyz, std::size_t n, std::uint32_t* cell);
template <> void start_cells_lanes<double>(InstructionSet, const double*, std::size_t, std::uint32_t*);
template <> void start_cells_lanes<float>(InstructionSet, const float*, std::size_t, std::uint32_t*);

/// GJK pairs of one shape-pair type (A of type_a, B of type_b) straight from the batch arrays into the result
/// arrays: pose validation, B's pose in A's frame, setup, GJK, completion and the world-frame output, with the
/// executor's scalar path's bits. Preconditions: neither type is triangle or halfspace, no closed form applies to
/// the type pair under `options`, options.level < penetration, no warm start; pairs[0 .. n) ascending. Returns how
/// many pairs it left to the scalar path (invalid input, a float stall redone in double), listed in
/// fallback[0 .. count) (room for n); every field of the others is written. options.solver must be resolved
/// (collide() does it; `automatic` throws, as for gjk_lanes).
template <class T>
std::size_t gjk_pairs(InstructionSet isa, const PairView& in, ShapeType type_a, ShapeType type_b,
                      const std::uint32_t* pairs, std::size_t n, const QueryOptions& options, const ResultView& out,
                      std::uint32_t* fallback);
template <>
std::size_t gjk_pairs<double>(InstructionSet, const PairView&, ShapeType, ShapeType, const std::uint32_t*, std::size_t,
                              const QueryOptions&, const ResultView&, std::uint32_t*);
template <>
std::size_t gjk_pairs<float>(InstructionSet, const PairView&, ShapeType, ShapeType, const std::uint32_t*, std::size_t,
                             const QueryOptions&, const ResultView&, std::uint32_t*);

/// Perturbed copies ("samples") of pairs of one shape-pair type (the smoothed0 derivatives' M copies of a pair,
/// engine/src/derivative_smoothed0.cpp): sample s has the shapes shape_a[s], shape_b[s] (a pair's samples are
/// consecutive: the cores are read once per run of equal shapes), B's pose in A's frame (R row-major, t) and the
/// first GJK direction in A's frame (not finite or zero: the cores' centres' difference, as without warm start).
/// A hull pair's starting simplex for its samples (convex-convex only): `count` (0: none; 1-3) vertex pairs,
/// vertex a[m] of A's hull minus vertex b[m] of B's under the sample's pose; the samples' GJK starts from the
/// origin's projection on them instead of one support point.
struct WarmSimplex {
  std::uint32_t count = 0;
  std::uint32_t a[3] = {}, b[3] = {};
};
struct SampleBatch {
  const std::uint32_t* shape_a = nullptr;
  const std::uint32_t* shape_b = nullptr;
  std::size_t samples = 0;
  const double* R[9] = {};
  const double* t[3] = {};
  const double* direction[3] = {};
  /// Per sample, its pair's WarmSimplex or null (a null array: none); read for convex-convex runs only.
  const WarmSimplex* const* warm = nullptr;
};
/// Each sample's answer in A's frame (written for every sample not handed back).
struct SampleResults {
  Status* status = nullptr;
  double* distance = nullptr;
  double* witness_a[3] = {};
  double* witness_b[3] = {};
  double* normal[3] = {};
  /// Sample s's entries are at [s * stride]: 1 for arrays, more for one record per sample (smoothed0's reduction
  /// reads a sample's 10 values as one contiguous row).
  std::size_t stride = 1;
};

/// GJK on every sample of `in` (kernels/simd/wide_gjk_samples.inl): the answer setup_pair_into(), the SIMD GJK and
/// complete_pair() give on the sample's relative pose and first direction, with the same bits, without a PairSetup
/// per sample. Preconditions as for gjk_pairs (shapes of types type_a, type_b, neither triangle nor halfspace, no
/// closed form for the pair under `options`, options.solver resolved), but options.level is witness or
/// penetration. Returns how many samples it left to the caller (overlap at the penetration level, a float stall
/// redone in double, a double stall above the certified floor), listed in fallback[0 .. count) (room for
/// in.samples); their results are not written. Only `shapes`' per-shape arrays are read.
template <class T>
std::size_t gjk_samples(InstructionSet isa, const PairView& shapes, ShapeType type_a, ShapeType type_b,
                        const SampleBatch& in, const QueryOptions& options, const SampleResults& out,
                        std::uint32_t* fallback);
template <>
std::size_t gjk_samples<double>(InstructionSet, const PairView&, ShapeType, ShapeType, const SampleBatch&,
                                const QueryOptions&, const SampleResults&, std::uint32_t*);
template <>
std::size_t gjk_samples<float>(InstructionSet, const PairView&, ShapeType, ShapeType, const SampleBatch&,
                               const QueryOptions&, const SampleResults&, std::uint32_t*);

/// What the samples of one pair share, for build_samples(): the counter key's per-pair half
/// splitmix64(splitmix64(seed) ^ pair) (engine/src/counter_rng.hpp), B's pose in A's frame, the noise scales
/// (metres, radians), and the first GJK direction: -(n0 + P z) when `predict`, else `first`.
struct SamplePlan {
  std::uint64_t key = 0;
  double R0[9] = {}, t0[3] = {}, n0[3] = {}, first[3] = {}, P[18] = {};
  double translation = 0.0, rotation = 0.0;
  bool predict = false;
};
/// Per-sample arrays build_samples() writes: B's pose in A's frame (row-major R, t), the first direction and z.
struct SampleArrays {
  double* R[9] = {};
  double* t[3] = {};
  double* direction[3] = {};
  double* z[6] = {};
};
/// Antithetic pairs k = a0 .. a0 + count - 1 of each plan plans[q], q < pairs (kernels/simd/wide_samples.inl): z
/// = engine/src/counter_rng.hpp's sample_noise(key, k), sample 2k (E R0, t0 + s_t z, z) at index q stride + k - a0 of `even`, its
/// antithetic copy (E^T R0, t0 - s_t z, -z) at the same index of `odd` for the first odd_count pairs (several
/// plans: odd_count == count). Several plans share registers when count < W; the same bits on every instruction
/// set, whatever a plan shares a register with.
void build_samples(InstructionSet isa, const SamplePlan* const* plans, std::size_t pairs, std::size_t stride,
                   std::uint64_t a0, std::size_t count, std::size_t odd_count, const SampleArrays& even,
                   const SampleArrays& odd);
/// One pair's running sums of the smoothed0 estimator (engine/src/derivative_smoothed0.cpp), in A's frame: over the
/// samples that entered (`valid` of them), the sum of their 10 values v (distance, witness a, witness b, normal) and
/// the estimator's sums for the 6 noise coordinates f over the antithetic pairs: (v_2e - v_2e+1) z_2e,f when both
/// samples entered, (v - g0) z_f for a lone one. Rows of 12 (two padding entries) for whole registers.
struct SampleSums {
  double mean[12] = {};
  double G[6][12] = {};
  double g0[12] = {};  // the unperturbed answer; padding 0
  int valid = 0;
};
/// Adds `count` samples to `sums` (sample 2e at index e, 2e+1 at evens + e): the values in sample order, the noise
/// sums by antithetic pair in order (blocks end on antithetic pairs, so a pair split over calls gives the same bits): sample k's values are
/// values[12 k .. 12 k + 9] (padding 0), its noise z[f][k]; a sample whose status is not converged or with a
/// non-finite value adds nothing. The same bits on every set (elementwise IEEE operations, no contraction).
void accumulate_samples(InstructionSet isa, const double* values, const Status* status, const double* const* z,
                        std::size_t count, std::size_t evens, SampleSums& sums);
/// engine/src/counter_rng.hpp's support_noise_pair(keys[p], j) for j < 3 draws into z[6 draws p + 2 j] and the
/// next entry, pairs p < `pairs` (smoothed1's noise of a block of pairs, W pairs per register). The same bits on
/// every set.
void draw_support_noise(InstructionSet isa, const std::uint64_t* keys, std::size_t pairs, std::size_t draws,
                        double* z);

}  // namespace batchcol::kernels::simd
