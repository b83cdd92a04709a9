// The SIMD narrow phase compiled for avx2 (256-bit registers).
#include "kernels/simd/isa_prelude.hpp"

#pragma GCC push_options
#pragma GCC target("avx2,fma")
#define BATCHCOL_SIMD_NS avx2
#define BATCHCOL_SIMD_BYTES 32

#include "kernels/simd/isa_body.inl"

#pragma GCC pop_options
