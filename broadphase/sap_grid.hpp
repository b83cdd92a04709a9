// The sweep axis and the grid of cells over the two other axes that the sweep-and-prune buckets objects into.
//
// Why a grid: a single sweep along one axis tests every pair whose intervals overlap on that axis. For n uniform
// boxes in a cube with a fixed number of true overlaps per box, that is about n^(2/3) interval overlaps per box
// (7000 per box at 1M objects), which no SIMD width rescues. Bucketing objects into a 2-D grid over the two other
// axes and sweeping each cell separately (Terdiman's "multi box pruning" idea) brings it back to a few tests per
// box. A pair is reported only in the cell holding the lower corner of the pair's overlap on the grid axes, which
// lies in both objects' cell ranges, so every pair is reported exactly once.
#pragma once

#include "broadphase/aabb_soa.hpp"

#include <cstddef>

namespace batchcol::broadphase {

struct SapGrid {
  int axis = 0, u = 1, v = 2;  // sweep axis; grid axes u < v
  int cells_u = 1, cells_v = 1;
  float origin_u = 0.0f, origin_v = 0.0f, inv_width_u = 0.0f, inv_width_v = 0.0f;

  std::size_t cell_count() const { return static_cast<std::size_t>(cells_u) * static_cast<std::size_t>(cells_v); }
  int cell_u(float x) const { return cell_of(x, origin_u, inv_width_u, cells_u); }
  int cell_v(float x) const { return cell_of(x, origin_v, inv_width_v, cells_v); }

  /// Cell index of a coordinate: floor((x - origin) / width) clamped to [0, cells). Every step (a rounded
  /// subtraction, a rounded product by a positive constant, a clamp, a truncation of a non-negative value) is
  /// monotone in x, so x <= y implies cell(x) <= cell(y) whatever the rounding: that is all exactness needs.
  /// Branch-free so that loops over many boxes vectorise. t is NaN only when inv_width = 0 (one cell) and x - origin
  /// overflowed to +-inf; the first select maps it to 0, the right cell. +-inf for coordinates near the float range
  /// (several cells) clamp to the border cells.
  static int cell_of(float x, float origin, float inv_width, int cells) {
    float t = (x - origin) * inv_width;
    t = t > 0.0f ? t : 0.0f;
    const float last = static_cast<float>(cells - 1);
    t = t < last ? t : last;
    return static_cast<int>(t);
  }

  /// Calls f(cell) for every cell of the span [u0, u1] x [v0, v1] (cell = v * cells_u + u); a one-cell span, the
  /// common case, skips the loops.
  template <class F> void for_each_cell(int u0, int u1, int v0, int v1, F&& f) const {
    if (u0 == u1 && v0 == v1) {
      f(static_cast<std::size_t>(v0) * cells_u + u0);
      return;
    }
    for (int v = v0; v <= v1; ++v)
      for (int u = u0; u <= u1; ++u) f(static_cast<std::size_t>(v) * cells_u + u);
  }
};

/// Sweep axis = the axis of largest variance of the box centres (ties: the lower axis); the grid over the two other
/// axes spans the range of the centres with cells about kCellWidthInExtents mean box widths wide, at most
/// max(1, n / kMinObjectsPerCell) cells and at most kMaxCellsPerAxis per axis. The statistics come from a fixed
/// sample of at most kSampleCount boxes spread over the input (sap_grid.cpp): deterministic for any thread count.
SapGrid choose_grid(const AabbSoa& boxes);

/// Cell spans of the boxes [begin, begin + k) on both grid axes: box begin + j spans cells [u0[j], u1[j]] x
/// [v0[j], v1[j]]. One branch-free loop (vectorised); the bucketing passes call it per block of kSpanBlock boxes.
constexpr std::size_t kSpanBlock = 256;
void cell_spans(const SapGrid& grid, const AabbSoa& boxes, std::size_t begin, std::size_t k, int* u0, int* u1,
                int* v0, int* v1);

/// The same grid with half as many cells per axis (rounded up); used when big boxes span too many cells.
SapGrid coarser(const SapGrid& grid);

}  // namespace batchcol::broadphase
