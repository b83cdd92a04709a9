// The SIMD narrow phase compiled for avx512 (512-bit registers).
#include "kernels/simd/isa_prelude.hpp"

#pragma GCC push_options
#pragma GCC target("avx512f,avx512dq,avx512vl,avx512bw,fma")
#define BATCHCOL_SIMD_NS avx512
#define BATCHCOL_SIMD_BYTES 64

#include "kernels/simd/isa_body.inl"

#pragma GCC pop_options
