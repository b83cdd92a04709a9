// The body every instruction-set translation unit (isa_*.cpp) shares: the wide layer and the kernels inside the
// set's namespace, and the entry points dispatch.cpp calls. Included once per set, after `#pragma GCC target`
// and the BATCHCOL_SIMD_NS / BATCHCOL_SIMD_BYTES definitions.
//
// Each isa_*.cpp is compiled once per kernel family (kernels/CMakeLists.txt defines BATCHCOL_SIMD_UNIT_<family>),
// and each object defines only that family's entry points. Why: GCC 12 caps how much inlining may grow a whole
// translation unit (--param inline-unit-growth, 40% by default). With every kernel in one unit, that cap was
// reached (88 refusals in isa_avx512.cpp, -fopt-info-inline-missed), so the hot GJK loops called helpers such as
// hull_support_lanes(), dot() and newton_pair_type() out of line, and adding code to one kernel changed what GCC
// inlined in all the others (a boolean-path change once slowed every witness row by 8-10%). One family per unit
// keeps each unit under the cap and the families' machine code independent of each other.
namespace batchcol::kernels::simd::BATCHCOL_SIMD_NS {

#include "kernels/simd/wide.hpp"
#include "kernels/hull_support.inl"
#include "kernels/simd/wide_gjk.inl"
#include "kernels/simd/wide_pairs.inl"
#include "kernels/simd/wide_segments.inl"
#include "kernels/simd/wide_boxes.inl"
#include "kernels/simd/wide_point_solids.inl"
#include "kernels/simd/wide_gjk_pairs.inl"
#include "kernels/simd/wide_gjk_samples.inl"
#include "kernels/simd/wide_samples.inl"

#if defined(BATCHCOL_SIMD_UNIT_SETUPS)
// GJK on prepared setups (PairSetup: EPA's and the tests' entry), and the hull start-cell tables.
void gjk_lanes_double(const PairSetup<double>* setups, std::size_t n, GjkResult<double>* out, Solver solver,
                      bool points) {
  WideGjk<double>::run(setups, n, out, solver, points);
}
void gjk_lanes_float(const PairSetup<float>* setups, std::size_t n, GjkResult<float>* out, Solver solver,
                     bool points) {
  WideGjk<float>::run(setups, n, out, solver, points);
}
void start_cells_double(const double* xyz, std::size_t n, std::uint32_t* cell) {
  WideGjk<double>::start_cells_of(xyz, n, cell);
}
void start_cells_float(const float* xyz, std::size_t n, std::uint32_t* cell) { WideGjk<float>::start_cells_of(xyz, n, cell); }
#endif

// Boolean double groups answered by a float pass and a double certificate (WideGjkPairs<double>::run_certified),
// defined in their own unit so that code added to the certified path cannot move the plain double loops' code.
std::size_t gjk_pairs_certified(const PairView& in, ShapeType a, ShapeType b, const std::uint32_t* pairs,
                                std::size_t n, const QueryOptions& options, const ResultView& out,
                                std::uint32_t* fallback);

#if defined(BATCHCOL_SIMD_UNIT_PAIRS_DOUBLE)
// GJK pairs straight from the batch, double: boolean, distance and witness queries through the double loop.
std::size_t gjk_pairs_double(const PairView& in, ShapeType a, ShapeType b, const std::uint32_t* pairs, std::size_t n,
                             const QueryOptions& options, const ResultView& out, std::uint32_t* fallback) {
  if (n == 0) return 0;
  if (WideGjkPairs<double>::certifies(a, b, options))
    return gjk_pairs_certified(in, a, b, pairs, n, options, out, fallback);
  return WideGjkPairs<double>::run_plain(in, a, b, pairs, n, options, out, fallback);
}
#endif

#if defined(BATCHCOL_SIMD_UNIT_PAIRS_CERTIFIED)
std::size_t gjk_pairs_certified(const PairView& in, ShapeType a, ShapeType b, const std::uint32_t* pairs,
                                std::size_t n, const QueryOptions& options, const ResultView& out,
                                std::uint32_t* fallback) {
  return WideGjkPairs<double>::run_certified(in, a, b, pairs, n, options, out, fallback);
}
#endif

#if defined(BATCHCOL_SIMD_UNIT_PAIRS_FLOAT)
std::size_t gjk_pairs_float(const PairView& in, ShapeType a, ShapeType b, const std::uint32_t* pairs, std::size_t n,
                            const QueryOptions& options, const ResultView& out, std::uint32_t* fallback) {
  return WideGjkPairs<float>::run_plain(in, a, b, pairs, n, options, out, fallback);
}
#endif

#if defined(BATCHCOL_SIMD_UNIT_SAMPLES)
// Derivatives by randomized smoothing: the perturbed samples' GJK, their construction and their reduction.
std::size_t gjk_samples_double(const PairView& shapes, ShapeType a, ShapeType b, const SampleBatch& in,
                               const QueryOptions& options, const SampleResults& out, std::uint32_t* fallback) {
  return WideGjkSamples<double>::run(shapes, a, b, in, options, out, fallback);
}
std::size_t gjk_samples_float(const PairView& shapes, ShapeType a, ShapeType b, const SampleBatch& in,
                              const QueryOptions& options, const SampleResults& out, std::uint32_t* fallback) {
  return WideGjkSamples<float>::run(shapes, a, b, in, options, out, fallback);
}
void build_samples(const SamplePlan* const* plans, std::size_t pairs, std::size_t stride, std::uint64_t a0,
                   std::size_t count, std::size_t odd_count, const SampleArrays& even, const SampleArrays& odd) {
  WideSamples::run(plans, pairs, stride, a0, count, odd_count, even, odd);
}
void accumulate_samples(const double* values, const Status* status, const double* const* z, std::size_t count,
                        std::size_t evens, SampleSums& sums) {
  WideSamples::accumulate(values, status, z, count, evens, sums);
}
void draw_support_noise(const std::uint64_t* keys, std::size_t pairs, std::size_t draws, double* z) {
  WideSamples::support_noise(keys, pairs, draws, z);
}
#endif

#if defined(BATCHCOL_SIMD_UNIT_CLOSED_FORMS)
// The closed forms: segment pairs (sphere / capsule), point-solid pairs, box-box boolean.
std::size_t segment_pairs(const PairView& in, bool capsule_a, bool capsule_b, const std::uint32_t* pairs,
                          std::size_t n, const ClosedFormQuery& query, const ResultView& out,
                          std::uint32_t* fallback) {
  if (capsule_a && capsule_b) return WideSegments::run<true, true>(in, pairs, n, query, out, fallback);
  if (capsule_a) return WideSegments::run<true, false>(in, pairs, n, query, out, fallback);
  if (capsule_b) return WideSegments::run<false, true>(in, pairs, n, query, out, fallback);
  return WideSegments::run<false, false>(in, pairs, n, query, out, fallback);
}

std::size_t point_solid_pairs(const PairView& in, bool sphere_a, PointSolid solid, const std::uint32_t* pairs,
                              std::size_t n, const ClosedFormQuery& query, const ResultView& out,
                              std::uint32_t* fallback) {
  using S = PointSolid;
  if (sphere_a) {
    if (solid == S::box) return WidePointSolids::run<true, S::box>(in, pairs, n, query, out, fallback);
    return solid == S::cone ? WidePointSolids::run<true, S::cone>(in, pairs, n, query, out, fallback)
                            : WidePointSolids::run<true, S::cylinder>(in, pairs, n, query, out, fallback);
  }
  if (solid == S::box) return WidePointSolids::run<false, S::box>(in, pairs, n, query, out, fallback);
  return solid == S::cone ? WidePointSolids::run<false, S::cone>(in, pairs, n, query, out, fallback)
                          : WidePointSolids::run<false, S::cylinder>(in, pairs, n, query, out, fallback);
}

std::size_t box_pairs_boolean(const PairView& in, const std::uint32_t* pairs, std::size_t n, const ResultView& out,
                              std::uint32_t* fallback) {
  return WideBoxes::run(in, pairs, n, out, fallback);
}
#endif

}  // namespace batchcol::kernels::simd::BATCHCOL_SIMD_NS
