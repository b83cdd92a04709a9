// Choosing the sweep axis (variance of centres) and the grid (see sap_grid.hpp).
#include "broadphase/sap_grid.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace batchcol::broadphase {
namespace {

// Cells this many mean box widths wide: a box then spans (1 + 1/k)^2 cells on average (1.27 copies at k = 8) while
// a cell holds few enough boxes that the sweep inside it tests a handful of intervals per box. k = 6 (1.36 copies)
// swept a little less but its 28-byte records put the broad phase above 64 bytes per object (stress scene, 100k:
// 66.6 B with the float boxes); k = 8 brings it under.
constexpr double kCellWidthInExtents = 8.0;
// Fewer than this many objects per cell on average costs more in per-cell bookkeeping than it saves.
constexpr std::size_t kMinObjectsPerCell = 16;
// Bounds the cell index to 16 bits per axis (the bucketing packs cell ranges into 64 bits).
constexpr int kMaxCellsPerAxis = 4096;
// Statistics are summed per block of this many objects, then the blocks in order: the same sums for any thread count.
constexpr std::size_t kBlock = 8192;

struct BlockStats {
  double sum[3] = {0, 0, 0}, sum_sq[3] = {0, 0, 0}, extent[3] = {0, 0, 0};
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
};

int cells_for(double range, double mean_extent) {
  if (!(range > 0.0)) return 1;  // all centres on one plane: nothing to split
  const double width = kCellWidthInExtents * mean_extent;
  const double cells = width > 0.0 ? std::floor(range / width) : kMaxCellsPerAxis;  // zero-size boxes: finest grid
  return static_cast<int>(std::clamp(cells, 1.0, static_cast<double>(kMaxCellsPerAxis)));
}

}  // namespace

SapGrid choose_grid(const AabbSoa& b) {
  SapGrid g;
  const std::size_t n = b.size();
  if (n == 0) return g;
  // Centres are shifted by the first centre before squaring, so that a scene far from the origin does not lose its
  // variance to cancellation in E[c^2] - E[c]^2.
  double shift[3];
  for (int a = 0; a < 3; ++a) shift[a] = 0.5 * (static_cast<double>(b.min(a)[0]) + b.max(a)[0]);
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  std::vector<BlockStats> stats(blocks);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t k) {
    BlockStats& s = stats[k];
    const std::size_t end = std::min(n, (k + 1) * kBlock);
    for (int a = 0; a < 3; ++a) {
      const float* lo = b.min(a);
      const float* hi = b.max(a);
      for (std::size_t i = k * kBlock; i < end; ++i) {
        const double c = 0.5 * (static_cast<double>(lo[i]) + hi[i]);
        const double d = c - shift[a];
        s.sum[a] += d;
        s.sum_sq[a] += d * d;
        s.extent[a] += static_cast<double>(hi[i]) - lo[i];
        s.lo[a] = std::min(s.lo[a], c);
        s.hi[a] = std::max(s.hi[a], c);
      }
    }
  });
  BlockStats t;
  for (const BlockStats& s : stats)
    for (int a = 0; a < 3; ++a) {
      t.sum[a] += s.sum[a], t.sum_sq[a] += s.sum_sq[a], t.extent[a] += s.extent[a];
      t.lo[a] = std::min(t.lo[a], s.lo[a]), t.hi[a] = std::max(t.hi[a], s.hi[a]);
    }
  double var[3];
  for (int a = 0; a < 3; ++a) {
    const double mean = t.sum[a] / n;
    var[a] = std::max(0.0, t.sum_sq[a] / n - mean * mean);
  }
  g.axis = 0;
  for (int a = 1; a < 3; ++a)
    if (var[a] > var[g.axis]) g.axis = a;
  g.u = g.axis == 0 ? 1 : 0;
  g.v = g.axis == 2 ? 1 : 2;
  g.cells_u = cells_for(t.hi[g.u] - t.lo[g.u], t.extent[g.u] / n);
  g.cells_v = cells_for(t.hi[g.v] - t.lo[g.v], t.extent[g.v] / n);
  const std::size_t max_cells = std::max<std::size_t>(1, n / kMinObjectsPerCell);
  while (g.cell_count() > max_cells) {
    if (g.cells_u >= g.cells_v) g.cells_u = (g.cells_u + 1) / 2;
    else g.cells_v = (g.cells_v + 1) / 2;
  }
  g.origin_u = static_cast<float>(t.lo[g.u]);
  g.origin_v = static_cast<float>(t.lo[g.v]);
  g.inv_width_u = g.cells_u > 1 ? static_cast<float>(g.cells_u / (t.hi[g.u] - t.lo[g.u])) : 0.0f;
  g.inv_width_v = g.cells_v > 1 ? static_cast<float>(g.cells_v / (t.hi[g.v] - t.lo[g.v])) : 0.0f;
  return g;
}

SapGrid coarser(const SapGrid& grid) {
  SapGrid g = grid;
  if (g.cells_u > 1) { g.cells_u = (g.cells_u + 1) / 2; g.inv_width_u *= 0.5f; }
  if (g.cells_v > 1) { g.cells_v = (g.cells_v + 1) / 2; g.inv_width_v *= 0.5f; }
  if (g.cells_u == 1) g.inv_width_u = 0.0f;
  if (g.cells_v == 1) g.inv_width_v = 0.0f;
  return g;
}

}  // namespace batchcol::broadphase
