// The SIMD narrow phase compiled for avx2 (256-bit registers).
#include "kernels/simd/isa_prelude.hpp"

#pragma GCC push_options
#pragma GCC target("avx2,fma")
#define BATCHCOL_SIMD_NS avx2
#define BATCHCOL_SIMD_BYTES 32

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
