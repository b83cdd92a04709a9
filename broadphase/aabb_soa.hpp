// World AABBs of all objects as a structure of float arrays: the broad phase's input.
//
// Float, not double: the broad phase only has to be conservative. Boxes given in double are rounded OUTWARD to
// float (min down, max up), so the float box always contains the double box; a pair whose double boxes touch or
// overlap is always reported, and at most a few extra pairs within one float ulp appear (the narrow phase rejects
// them). Every producer and the brute-force reference work on this same float data, so "equal to brute force" is
// an exact statement.
#pragma once

#include "batchcol/types.hpp"

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
  void set(std::size_t i, const PlainAabb& box, double margin = 0.0);
  /// The same for any box type with min[k] and max[k] (the engine's batchcol::Aabb): the broad phase does not see
  /// the public shape model, its callers convert here.
  template <class Box>
  void set(std::size_t i, const Box& box, double margin = 0.0) {
    PlainAabb plain;
    for (int a = 0; a < 3; ++a) plain.min[a] = box.min[a], plain.max[a] = box.max[a];
    set(i, plain, margin);
  }
  /// Replaces the contents with `boxes`, each inflated by `margin`; same checks as set().
  template <class Box>
  void assign(const std::vector<Box>& boxes, double margin = 0.0) {
    resize(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i) set(i, boxes[i], margin);
  }
};

/// Throws InputError naming the lowest bad object index unless all arrays have the same size, every coordinate is
/// finite and min <= max on every axis. Used at the boundary for callers that fill the arrays directly.
void validate_aabbs(const AabbSoa& boxes);

/// float_down: the largest float <= x; float_up: the smallest float >= x (x within the float range); -0 becomes +0.
float float_down(double x);
float float_up(double x);

}  // namespace batchcol::broadphase
