// The SIMD narrow phase compiled for scalar (one lane: the wide kernels' own scalar build).
#include "kernels/simd/isa_prelude.hpp"

#pragma GCC push_options
// baseline x86-64: no target change
#define BATCHCOL_SIMD_NS scalar
#define BATCHCOL_SIMD_BYTES 0

namespace batchcol::kernels::simd::BATCHCOL_SIMD_NS {

#include "kernels/simd/wide.hpp"
#include "kernels/simd/wide_gjk.inl"

void gjk_lanes_double(const PairSetup<double>* setups, std::size_t n, GjkResult<double>* out, Solver solver,
                      bool points) {
  WideGjk<double>::run(setups, n, out, solver, points);
}
void gjk_lanes_float(const PairSetup<float>* setups, std::size_t n, GjkResult<float>* out, Solver solver,
                     bool points) {
  WideGjk<float>::run(setups, n, out, solver, points);
}

}  // namespace batchcol::kernels::simd::BATCHCOL_SIMD_NS

#pragma GCC pop_options
