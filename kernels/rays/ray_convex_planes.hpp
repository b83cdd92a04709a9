// The clipping loop of a ray against a hull's face planes (Cyrus-Beck), compiled for AVX-512, AVX2 and the baseline
// (`#pragma GCC target` regions in ray_convex_planes.cpp, picked per call by __builtin_cpu_supports). Every version
// keeps the same 8 independent lanes (face i goes to lane i mod 8) and does the same operations per lane in the same
// order under -ffp-contract=off, so the result is bitwise the same on every instruction set (tested,
// RayConvexPlanes.EveryInstructionSetGivesTheSameBits).
#pragma once

#include <cstddef>

namespace batchcol::kernels::rays {

/// Result of the clipping: the latest entry (t = enter) through face `face`, the earliest exit, and whether a plane
/// parallel to the ray has the line outside it.
template <class T> struct PlaneClip {
  T enter, exit;
  unsigned face;  // meaningful when enter > -inf
  bool outside;
};

/// n is a multiple of 8; planes <(nx, ny, nz)_i, x> <= c_i; o, d the ray in the hull's frame. `isa` caps the
/// instruction set (0 baseline, 1 AVX2, 2 AVX-512: RayOptions::isa through ray_isa_index()); the loop of the highest
/// set at most `isa` that the processor runs is used (select_clip_planes()). Every set gives the same bits.
PlaneClip<double> clip_planes(const double* nx, const double* ny, const double* nz, const double* c, std::size_t n,
                              const double* o, const double* d, int isa = 2);
PlaneClip<float> clip_planes(const float* nx, const float* ny, const float* nz, const float* c, std::size_t n,
                             const float* o, const float* d, int isa = 2);

/// One instruction set's loop, for the tests: isa 0 baseline, 1 AVX2, 2 AVX-512; null when the processor lacks it.
struct ClipPlaneVariants {
  PlaneClip<double> (*d)(const double*, const double*, const double*, const double*, std::size_t, const double*,
                         const double*) = nullptr;
  PlaneClip<float> (*f)(const float*, const float*, const float*, const float*, std::size_t, const float*,
                        const float*) = nullptr;
};
ClipPlaneVariants clip_planes_for(int isa);
/// The loops clip_planes() runs for the cap `isa`: those of the highest set <= isa this processor has.
ClipPlaneVariants select_clip_planes(int isa);

}  // namespace batchcol::kernels::rays
