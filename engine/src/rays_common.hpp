// Helpers shared by the ray query implementations (rays.cpp, rays_shape.cpp, ray_scene*.cpp).
#pragma once

#include "batchcol/rays.hpp"

#include <tbb/task_arena.h>

#include <cstddef>

namespace batchcol::detail {

/// Rays per task: large enough to amortise scheduling, small enough to balance 2-64 threads. The split does not
/// depend on the thread count (and each ray's result depends on that ray alone).
constexpr std::size_t kRayChunk = 1024;

/// Throws InputError when the arrays of the batch differ in size.
void check_ray_batch(const RayBatch& rays);
/// See the top of batchcol/rays.hpp.
bool ray_is_valid(const RayBatch& rays, std::size_t i);
/// n rays of defaults: invalid_input, no hit, NaN values; `object` sized only for scene queries; all-hit rows empty.
void size_ray_results(RayResults& r, std::size_t n, bool with_objects);

/// The ray kernels' index of an instruction set (0 scalar, 1 AVX2, 2 AVX-512: wide_traverse_for(), lane_casts_for())
/// after resolve_instruction_set(), which throws InputError when this CPU lacks the requested one.
int ray_isa_index(InstructionSet requested);

/// Runs f() in an arena of `threads` threads (0 = the caller's arena).
template <class F> void run_with_threads(int threads, const F& f) {
  if (threads <= 0 || threads == tbb::this_task_arena::max_concurrency()) {
    f();
  } else {
    tbb::task_arena arena(threads);
    arena.execute(f);
  }
}

}  // namespace batchcol::detail
