// The SIMD narrow phase compiled for scalar (one lane: the wide kernels' own scalar build).
#include "kernels/simd/isa_prelude.hpp"

#pragma GCC push_options
// baseline x86-64: no target change
#define BATCHCOL_SIMD_NS scalar
#define BATCHCOL_SIMD_BYTES 0

#include "kernels/simd/isa_body.inl"

#pragma GCC pop_options
