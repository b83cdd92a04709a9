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

}  // namespace batchcol::kernels::simd
