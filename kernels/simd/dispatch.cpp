// Run-time choice of the instruction set: the CPU's best (cpuid through __builtin_cpu_supports), lowered by the
// environment variable BATCHCOL_ISA, or an explicit request checked against the CPU.
#include "kernels/simd/wide_closed_forms.hpp"
#include "kernels/simd/wide_gjk.hpp"

#include <cstdlib>
#include <stdexcept>
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
  std::size_t gjk_pairs_double(const PairView&, ShapeType, ShapeType, const std::uint32_t*, std::size_t,           \
                               const QueryOptions&, const ResultView&, std::uint32_t*);                            \
  std::size_t gjk_pairs_float(const PairView&, ShapeType, ShapeType, const std::uint32_t*, std::size_t,            \
                              const QueryOptions&, const ResultView&, std::uint32_t*);                             \
  }
BATCHCOL_DECLARE_ISA(scalar)
BATCHCOL_DECLARE_ISA(avx2)
BATCHCOL_DECLARE_ISA(avx512)
#undef BATCHCOL_DECLARE_ISA

bool cpu_has(InstructionSet isa) {
  switch (isa) {
    case InstructionSet::avx512:
      return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
             __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512bw") &&
             __builtin_cpu_supports("fma");
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

template <>
void gjk_lanes<double>(InstructionSet isa, const PairSetup<double>* s, std::size_t n, GjkResult<double>* out,
                       Solver solver, bool points) {
  if (solver == Solver::automatic) throw std::invalid_argument("gjk_lanes: resolve the solver first (resolve_solver)");
  switch (isa) {
    case InstructionSet::avx512: return avx512::gjk_lanes_double(s, n, out, solver, points);
    case InstructionSet::avx2: return avx2::gjk_lanes_double(s, n, out, solver, points);
    default: return scalar::gjk_lanes_double(s, n, out, solver, points);
  }
}

template <>
void gjk_lanes<float>(InstructionSet isa, const PairSetup<float>* s, std::size_t n, GjkResult<float>* out,
                      Solver solver, bool points) {
  if (solver == Solver::automatic) throw std::invalid_argument("gjk_lanes: resolve the solver first (resolve_solver)");
  switch (isa) {
    case InstructionSet::avx512: return avx512::gjk_lanes_float(s, n, out, solver, points);
    case InstructionSet::avx2: return avx2::gjk_lanes_float(s, n, out, solver, points);
    default: return scalar::gjk_lanes_float(s, n, out, solver, points);
  }
}

std::size_t segment_pairs(InstructionSet isa, const PairView& in, bool capsule_a, bool capsule_b,
                          const std::uint32_t* pairs, std::size_t n, const ClosedFormQuery& query,
                          const ResultView& out, std::uint32_t* fallback) {
  switch (isa) {
    case InstructionSet::avx512: return avx512::segment_pairs(in, capsule_a, capsule_b, pairs, n, query, out, fallback);
    case InstructionSet::avx2: return avx2::segment_pairs(in, capsule_a, capsule_b, pairs, n, query, out, fallback);
    default: return scalar::segment_pairs(in, capsule_a, capsule_b, pairs, n, query, out, fallback);
  }
}

std::size_t box_pairs_boolean(InstructionSet isa, const PairView& in, const std::uint32_t* pairs, std::size_t n,
                              const ResultView& out, std::uint32_t* fallback) {
  switch (isa) {
    case InstructionSet::avx512: return avx512::box_pairs_boolean(in, pairs, n, out, fallback);
    case InstructionSet::avx2: return avx2::box_pairs_boolean(in, pairs, n, out, fallback);
    default: return scalar::box_pairs_boolean(in, pairs, n, out, fallback);
  }
}

template <>
std::size_t gjk_pairs<double>(InstructionSet isa, const PairView& in, ShapeType a, ShapeType b,
                              const std::uint32_t* pairs, std::size_t n, const QueryOptions& options,
                              const ResultView& out, std::uint32_t* fallback) {
  if (options.solver == Solver::automatic) throw std::invalid_argument("gjk_pairs: resolve the solver first (resolve_solver)");
  switch (isa) {
    case InstructionSet::avx512: return avx512::gjk_pairs_double(in, a, b, pairs, n, options, out, fallback);
    case InstructionSet::avx2: return avx2::gjk_pairs_double(in, a, b, pairs, n, options, out, fallback);
    default: return scalar::gjk_pairs_double(in, a, b, pairs, n, options, out, fallback);
  }
}

template <>
std::size_t gjk_pairs<float>(InstructionSet isa, const PairView& in, ShapeType a, ShapeType b,
                             const std::uint32_t* pairs, std::size_t n, const QueryOptions& options,
                             const ResultView& out, std::uint32_t* fallback) {
  if (options.solver == Solver::automatic) throw std::invalid_argument("gjk_pairs: resolve the solver first (resolve_solver)");
  switch (isa) {
    case InstructionSet::avx512: return avx512::gjk_pairs_float(in, a, b, pairs, n, options, out, fallback);
    case InstructionSet::avx2: return avx2::gjk_pairs_float(in, a, b, pairs, n, options, out, fallback);
    default: return scalar::gjk_pairs_float(in, a, b, pairs, n, options, out, fallback);
  }
}

}  // namespace batchcol::kernels::simd

namespace batchcol {

InstructionSet resolve_instruction_set(InstructionSet requested) {
  using kernels::simd::cpu_has;
  if (requested == InstructionSet::automatic) {
    InstructionSet best = kernels::simd::detected_instruction_set();
    if (const char* env = std::getenv("BATCHCOL_ISA"); env != nullptr && *env != '\0') {
      InstructionSet cap = InstructionSet::automatic;
      for (const InstructionSet isa : {InstructionSet::scalar, InstructionSet::avx2, InstructionSet::avx512})
        if (std::string(env) == to_string(isa)) cap = isa;
      if (cap == InstructionSet::automatic)
        throw InputError("environment variable BATCHCOL_ISA='" + std::string(env) +
                         "' names no instruction set (valid: scalar, avx2, avx512)");
      if (static_cast<int>(cap) < static_cast<int>(best)) best = cap;
    }
    return best;
  }
  if (!cpu_has(requested))
    throw InputError(std::string("instruction set ") + to_string(requested) + " is not supported by this CPU (best: " +
                     to_string(kernels::simd::detected_instruction_set()) + ")");
  return requested;
}

}  // namespace batchcol
