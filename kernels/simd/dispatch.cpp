// The CPU's best instruction set (cpuid through __builtin_cpu_supports) and the table of each set's entry points.
// Lowering it by the environment variable BATCHCOL_ISA, or checking a request against it, is the engine's
// (engine/src/instruction_set.cpp).
#include "kernels/simd/wide_closed_forms.hpp"
#include "kernels/simd/wide_gjk.hpp"
#include "kernels/support.hpp"  // kHillClimbMinVertices

#include "batchcol/errors.hpp"

#include <string>

namespace batchcol::kernels::simd {

// One entry point per instruction set and precision, defined in isa_*.cpp.
#define BATCHCOL_DECLARE_ISA(ns)                                                                             \
  namespace ns {                                                                                             \
  void gjk_lanes_double(const PairSetup<double>*, std::size_t, GjkResult<double>*, Solver, bool);                \
  void gjk_lanes_float(const PairSetup<float>*, std::size_t, GjkResult<float>*, Solver, bool);                   \
  std::size_t segment_pairs(const PairView&, bool, bool, const std::uint32_t*, std::size_t,                       \
                            const ClosedFormQuery&, const ResultView&, std::uint32_t*);                          \
  std::size_t box_pairs_boolean(const PairView&, const std::uint32_t*, std::size_t, const ResultView&,             \
                                std::uint32_t*);                                                                 \
  std::size_t point_solid_pairs(const PairView&, bool, PointSolid, const std::uint32_t*, std::size_t,              \
                                const ClosedFormQuery&, const ResultView&, std::uint32_t*);                      \
  std::size_t gjk_pairs_double(const PairView&, ShapeType, ShapeType, const std::uint32_t*, std::size_t,           \
                               const QueryOptions&, const ResultView&, std::uint32_t*);                            \
  std::size_t gjk_pairs_float(const PairView&, ShapeType, ShapeType, const std::uint32_t*, std::size_t,            \
                              const QueryOptions&, const ResultView&, std::uint32_t*);                             \
  std::size_t gjk_samples_double(const PairView&, ShapeType, ShapeType, const SampleBatch&, const QueryOptions&,    \
                                 const SampleResults&, std::uint32_t*);                                            \
  std::size_t gjk_samples_float(const PairView&, ShapeType, ShapeType, const SampleBatch&, const QueryOptions&,     \
                                const SampleResults&, std::uint32_t*);                                             \
  void build_samples(const SamplePlan* const*, std::size_t, std::size_t, std::uint64_t, std::size_t, std::size_t, \
                     const SampleArrays&, const SampleArrays&);                                                    \
  void draw_support_noise(const std::uint64_t*, std::size_t, std::size_t, double*);                               \
  void accumulate_samples(const double*, const Status*, const double* const*, std::size_t, std::size_t,            \
                          SampleSums&);                                                                            \
  void start_cells_double(const double*, std::size_t, std::uint32_t*);                                             \
  void start_cells_float(const float*, std::size_t, std::uint32_t*);                                               \
  }
BATCHCOL_DECLARE_ISA(scalar)
BATCHCOL_DECLARE_ISA(avx2)
BATCHCOL_DECLARE_ISA(avx512)
#undef BATCHCOL_DECLARE_ISA

bool cpu_has(InstructionSet isa) {
  switch (isa) {
    case InstructionSet::avx512:
      // AVX2 too: code of the avx512 set may run AVX2 paths (the derivatives' exposed_mask_avx2()), and a VM's
      // CPUID could hide AVX2 while exposing AVX-512.
      return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
             __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512bw") &&
             __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    case InstructionSet::avx2: return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
    default: return true;
  }
}

InstructionSet detected_instruction_set() {
  if (cpu_has(InstructionSet::avx512)) return InstructionSet::avx512;
  if (cpu_has(InstructionSet::avx2)) return InstructionSet::avx2;
  return InstructionSet::scalar;
}

int lane_count(InstructionSet isa, Precision precision) {
  const int bytes = isa == InstructionSet::avx512 ? 64 : isa == InstructionSet::avx2 ? 32 : 0;
  if (bytes == 0) return 1;
  return precision == Precision::float32 ? bytes / 4 : bytes / 8;
}

namespace {

/// The entry points of one instruction set's build. One table per set, filled at compile time; a call indexes it
/// with the already resolved set (no per-call switch, no cpuid).
struct IsaKernels {
  decltype(&scalar::gjk_lanes_double) gjk_lanes_double;
  decltype(&scalar::gjk_lanes_float) gjk_lanes_float;
  decltype(&scalar::segment_pairs) segment_pairs;
  decltype(&scalar::box_pairs_boolean) box_pairs_boolean;
  decltype(&scalar::point_solid_pairs) point_solid_pairs;
  decltype(&scalar::gjk_pairs_double) gjk_pairs_double;
  decltype(&scalar::gjk_pairs_float) gjk_pairs_float;
  decltype(&scalar::gjk_samples_double) gjk_samples_double;
  decltype(&scalar::gjk_samples_float) gjk_samples_float;
  decltype(&scalar::build_samples) build_samples;
  decltype(&scalar::accumulate_samples) accumulate_samples;
  decltype(&scalar::start_cells_double) start_cells_double;
  decltype(&scalar::start_cells_float) start_cells_float;
  decltype(&scalar::draw_support_noise) draw_support_noise;
};
#define BATCHCOL_ISA_TABLE(ns)                                                                               \
  IsaKernels { &ns::gjk_lanes_double, &ns::gjk_lanes_float, &ns::segment_pairs, &ns::box_pairs_boolean,      \
               &ns::point_solid_pairs, &ns::gjk_pairs_double, &ns::gjk_pairs_float, &ns::gjk_samples_double,   \
               &ns::gjk_samples_float, &ns::build_samples, &ns::accumulate_samples,                           \
               &ns::start_cells_double, &ns::start_cells_float, &ns::draw_support_noise }
// Indexed by InstructionSet: automatic (never passed once resolved; the scalar build, as any set would give the
// same bits), scalar, avx2, avx512.
constexpr IsaKernels kIsaKernels[] = {BATCHCOL_ISA_TABLE(scalar), BATCHCOL_ISA_TABLE(scalar), BATCHCOL_ISA_TABLE(avx2),
                                      BATCHCOL_ISA_TABLE(avx512)};
#undef BATCHCOL_ISA_TABLE
static_assert(int(InstructionSet::avx512) == 3, "kIsaKernels is indexed by InstructionSet");

const IsaKernels& kernels_of(InstructionSet isa) { return kIsaKernels[static_cast<int>(isa) & 3]; }

void require_resolved(Solver solver) {
  if (solver == Solver::automatic)
    throw InputError("QueryOptions::solver: 'automatic' reached the GJK kernels unresolved (resolve_solver() first)");
}

}  // namespace

template <>
void gjk_lanes<double>(InstructionSet isa, const PairSetup<double>* s, std::size_t n, GjkResult<double>* out,
                       Solver solver, bool points) {
  require_resolved(solver);
  kernels_of(isa).gjk_lanes_double(s, n, out, solver, points);
}

template <> void start_cells_lanes<double>(InstructionSet isa, const double* xyz, std::size_t n, std::uint32_t* cell) {
  kernels_of(isa).start_cells_double(xyz, n, cell);
}
template <> void start_cells_lanes<float>(InstructionSet isa, const float* xyz, std::size_t n, std::uint32_t* cell) {
  kernels_of(isa).start_cells_float(xyz, n, cell);
}

template <>
void gjk_lanes<float>(InstructionSet isa, const PairSetup<float>* s, std::size_t n, GjkResult<float>* out,
                      Solver solver, bool points) {
  require_resolved(solver);
  kernels_of(isa).gjk_lanes_float(s, n, out, solver, points);
}

std::size_t segment_pairs(InstructionSet isa, const PairView& in, bool capsule_a, bool capsule_b,
                          const std::uint32_t* pairs, std::size_t n, const ClosedFormQuery& query,
                          const ResultView& out, std::uint32_t* fallback) {
  return kernels_of(isa).segment_pairs(in, capsule_a, capsule_b, pairs, n, query, out, fallback);
}

std::size_t box_pairs_boolean(InstructionSet isa, const PairView& in, const std::uint32_t* pairs, std::size_t n,
                              const ResultView& out, std::uint32_t* fallback) {
  return kernels_of(isa).box_pairs_boolean(in, pairs, n, out, fallback);
}

std::size_t point_solid_pairs(InstructionSet isa, const PairView& in, bool sphere_a, PointSolid solid,
                              const std::uint32_t* pairs, std::size_t n, const ClosedFormQuery& query,
                              const ResultView& out, std::uint32_t* fallback) {
  return kernels_of(isa).point_solid_pairs(in, sphere_a, solid, pairs, n, query, out, fallback);
}

template <>
std::size_t gjk_pairs<double>(InstructionSet isa, const PairView& in, ShapeType a, ShapeType b,
                              const std::uint32_t* pairs, std::size_t n, const QueryOptions& options,
                              const ResultView& out, std::uint32_t* fallback) {
  require_resolved(options.solver);
  return kernels_of(isa).gjk_pairs_double(in, a, b, pairs, n, options, out, fallback);
}

template <>
std::size_t gjk_samples<double>(InstructionSet isa, const PairView& shapes, ShapeType a, ShapeType b,
                                const SampleBatch& in, const QueryOptions& options, const SampleResults& out,
                                std::uint32_t* fallback) {
  require_resolved(options.solver);
  return kernels_of(isa).gjk_samples_double(shapes, a, b, in, options, out, fallback);
}

template <>
std::size_t gjk_samples<float>(InstructionSet isa, const PairView& shapes, ShapeType a, ShapeType b,
                               const SampleBatch& in, const QueryOptions& options, const SampleResults& out,
                               std::uint32_t* fallback) {
  require_resolved(options.solver);
  return kernels_of(isa).gjk_samples_float(shapes, a, b, in, options, out, fallback);
}

void build_samples(InstructionSet isa, const SamplePlan* const* plans, std::size_t pairs, std::size_t stride,
                   std::uint64_t a0, std::size_t count, std::size_t odd_count, const SampleArrays& even,
                   const SampleArrays& odd) {
  kernels_of(isa).build_samples(plans, pairs, stride, a0, count, odd_count, even, odd);
}

void accumulate_samples(InstructionSet isa, const double* values, const Status* status, const double* const* z,
                        std::size_t count, std::size_t evens, SampleSums& sums) {
  kernels_of(isa).accumulate_samples(values, status, z, count, evens, sums);
}

void draw_support_noise(InstructionSet isa, const std::uint64_t* keys, std::size_t pairs, std::size_t draws,
                        double* z) {
  kernels_of(isa).draw_support_noise(keys, pairs, draws, z);
}

namespace {

/// Whether at least half of the pairs have a hull that GJK climbs (>= kHillClimbMinVertices vertices) on a convex side.
bool mostly_large_hulls(const PairView& in, ShapeType a, ShapeType b, const std::uint32_t* pairs, std::size_t n) {
  const auto large = [&](const std::uint32_t* shape, std::uint32_t pair) {
    return in.shape_hull[shape[pair]].vertex_count >= kHillClimbMinVertices;
  };
  std::size_t count = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const bool la = a == ShapeType::convex && large(in.shape_a, pairs[k]);
    const bool lb = b == ShapeType::convex && large(in.shape_b, pairs[k]);
    count += (la || lb) ? 1 : 0;
  }
  return 2 * count >= n;
}

}  // namespace

template <>
std::size_t gjk_pairs<float>(InstructionSet isa, const PairView& in, ShapeType a, ShapeType b,
                             const std::uint32_t* pairs, std::size_t n, const QueryOptions& options,
                             const ResultView& out, std::uint32_t* fallback) {
  require_resolved(options.solver);
  // Large hulls climb lane by lane, so 16 float lanes gain nothing over 8 in the climb, and the 32 hulls in flight
  // probably crowd the cache: measured faster on the AVX2 build's 8 lanes (numbers in the commit that made this
  // choice). Every instruction set gives the same bits, so such groups run there.
  if (isa == InstructionSet::avx512 && (a == ShapeType::convex || b == ShapeType::convex) &&
      mostly_large_hulls(in, a, b, pairs, n))
    isa = InstructionSet::avx2;
  return kernels_of(isa).gjk_pairs_float(in, a, b, pairs, n, options, out, fallback);
}

}  // namespace batchcol::kernels::simd
