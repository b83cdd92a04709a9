// World AABBs of all objects as a structure of float arrays: the broad phase's input.
//
// Float, not double: the broad phase only has to be conservative. Boxes given in double are rounded OUTWARD to
// float (min down, max up), so the float box always contains the double box; a pair whose double boxes touch or
// overlap is always reported, and at most a few extra pairs within one float ulp appear (the narrow phase rejects
// them). Every producer and the brute-force reference work on this same float data, so "equal to brute force" is
// an exact statement.
#pragma once

#include "batchcol/shapes.hpp"

#include <cstddef>
#include <vector>

namespace batchcol::broadphase {

struct AabbSoa {
  std::vector<float> min_x, min_y, min_z, max_x, max_y, max_z;

  std::size_t size() const { return min_x.size(); }
  void resize(std::size_t n);
  void clear() { resize(0); }
  const float* min(int axis) const { return axis == 0 ? min_x.data() : axis == 1 ? min_y.data() : min_z.data(); }
  const float* max(int axis) const { return axis == 0 ? max_x.data() : axis == 1 ? max_y.data() : max_z.data(); }

  /// Stores box i inflated by `margin` (>= 0), rounded outward to float. Throws InputError naming object i when a
  /// coordinate is not finite (halfspaces have infinite boxes: they do not belong in the broad phase), leaves the
  /// float range, or min > max.
  void set(std::size_t i, const Aabb& box, double margin = 0.0);
  /// Replaces the contents with `boxes`, each inflated by `margin`; same checks as set().
  void assign(const std::vector<Aabb>& boxes, double margin = 0.0);
};

/// Throws InputError naming the lowest bad object index unless all arrays have the same size, every coordinate is
/// finite and min <= max on every axis. Used at the boundary for callers that fill the arrays directly.
void validate_aabbs(const AabbSoa& boxes);

/// float_down: the largest float <= x; float_up: the smallest float >= x (x within the float range); -0 becomes +0.
float float_down(double x);
float float_up(double x);

}  // namespace batchcol::broadphase
