// Rays against posed spheres, boxes, capsules and hulls, W rays per register (the shape form of batchcol/rays.hpp, one pose
// per ray): the pose is read, validated and applied lane-wise straight from the batch's arrays, the exact
// intersection (the same closed forms as ray_quadrics.hpp / ray_polytopes.hpp: closest-point quadratic, slabs,
// capsule as the union of its balls and body) runs on whole registers, and the world-frame results are stored as
// registers. Compiled for AVX-512 (8 lanes), AVX2 (4 lanes) and scalar (1 lane) from one body (ray_lanes.inl); every
// lane does the same IEEE operations in the same order as the scalar build (-ffp-contract=off, correctly rounded
// sqrt), so a ray's answer does not depend on which of them ran it or on its neighbours.
#pragma once

#include "kernels/rays/ray_polytopes.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace batchcol::kernels::rays {

enum class LaneKind : std::uint8_t { none = 0, sphere, box, capsule, hull };

/// Per shape: its lane kind (none = not handled here: other types, inflated boxes and hulls) and its sizes: sphere
/// (a = radius with inflation), box (a, b, c = half extents), capsule (a = radius with inflation, b = half length),
/// hull (a = bounding radius; its planes in the precision cast: hull_d or hull_f, owned by the caller). Hulls get
/// the pose handling in registers and then, lane by lane, the scalar kernel of ray_shape.hpp (ball test, polar walk,
/// clipping fallback).
struct LaneShapeTable {
  std::vector<LaneKind> kind;
  std::vector<double> a, b, c;
  std::vector<const HullPlanes<double>*> hull_d;
  std::vector<const HullPlanes<float>*> hull_f;
};

/// The batch's arrays (SoA), read from ray index i on.
struct LaneRays {
  const double *ox, *oy, *oz, *dx, *dy, *dz, *t_max;
  const double *px, *py, *pz, *qw, *qx, *qy, *qz;
  const std::uint32_t* shape;
};

/// Result arrays: status (0 = RayStatus::ok), hit, t, world normal. Misses are written as hit 0, t and normal NaN.
struct LaneOut {
  std::uint8_t *status, *hit;
  double *t, *nx, *ny, *nz;
};

/// Casts rays [i, i + width) when every one of them is valid (finite, non-zero direction, t_max >= 0, finite
/// translation, | |q| - 1 | <= kUnitTolerance / 2 (the tighter half leaves the boundary to the general path's own
/// check) and its shape is of one lane kind; otherwise writes nothing and returns false.
using LaneCast = bool (*)(const LaneShapeTable& shapes, const LaneRays& rays, std::size_t i, LaneOut& out);

struct LaneCasts {
  LaneCast cast_double = nullptr, cast_float = nullptr;
  int width = 1;
};
/// isa: 0 scalar (width 1), 1 AVX2 (4), 2 AVX-512 (8); width 0 and null casts when the processor lacks it.
LaneCasts lane_casts_for(int isa);
/// The widest set this processor has (reads the CPU's features; no state is kept).
LaneCasts select_lane_casts();

}  // namespace batchcol::kernels::rays
