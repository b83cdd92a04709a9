// Everything an instruction-set translation unit (isa_*.cpp) includes BEFORE its `#pragma GCC target` region:
// headers included here are compiled for the baseline CPU, so no inline function of the standard library, Eigen
// or the scalar kernels can be emitted with AVX-512 instructions and picked by the linker for baseline code.
#pragma once

#include "kernels/closed_forms.hpp"
#include "kernels/narrowphase.hpp"
#include "kernels/simd/wide_closed_forms.hpp"
#include "kernels/simd/wide_gjk.hpp"

#include <immintrin.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <algorithm>
#include <limits>
#include <type_traits>
