// Choosing the sweep axis (variance of centres) and the grid (see sap_grid.hpp).
#include "broadphase/sap_grid.hpp"

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
// Bounds the grid (4096^2 cells at most) and keeps cell indices well inside int.
constexpr int kMaxCellsPerAxis = 4096;
// The statistics come from at most kSampleCount boxes spread evenly over the input (all of them in smaller scenes): the
// axis and the cell width need the variance and the mean extent only roughly (the relative error of a variance from
// 2048 samples is about 3%), and the grid is exact for any origin and width (cell_of clamps), while summing every
// box in double is a sizeable part of a small scene's rebuild. A fixed sample: the same grid for any thread count.
constexpr std::size_t kSampleCount = 2048;

// Sample k of `samples` from n boxes: one per stretch of n / samples boxes, at a position inside the stretch that
// varies with k (a multiplicative hash), so that an input repeating with the stretch's period (every 64th box tiny,
// say) is not sampled in phase with it. k * n < 2^43; the offset stays below the stretch, so i < n.
std::size_t sample_index(std::size_t k, std::size_t n, std::size_t samples) {
  const std::size_t stretch = n / samples;
  const std::size_t offset = stretch > 1 ? (k * 2654435761u) % stretch : 0;
  return k * n / samples + offset;
}

struct Stats {
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
  const std::size_t samples = std::min(n, kSampleCount);
  Stats t;
  for (int a = 0; a < 3; ++a) {
    const float* lo = b.min(a);
    const float* hi = b.max(a);
    for (std::size_t k = 0; k < samples; ++k) {
      const std::size_t i = sample_index(k, n, samples);
      const double c = 0.5 * (static_cast<double>(lo[i]) + hi[i]);
      const double d = c - shift[a];
      t.sum[a] += d;
      t.sum_sq[a] += d * d;
      t.extent[a] += static_cast<double>(hi[i]) - lo[i];
      t.lo[a] = std::min(t.lo[a], c);
      t.hi[a] = std::max(t.hi[a], c);
    }
  }
  double var[3];
  for (int a = 0; a < 3; ++a) {
    const double mean = t.sum[a] / samples;
    var[a] = std::max(0.0, t.sum_sq[a] / samples - mean * mean);
  }
  g.axis = 0;
  for (int a = 1; a < 3; ++a)
    if (var[a] > var[g.axis]) g.axis = a;
  g.u = g.axis == 0 ? 1 : 0;
  g.v = g.axis == 2 ? 1 : 2;
  g.cells_u = cells_for(t.hi[g.u] - t.lo[g.u], t.extent[g.u] / samples);
  g.cells_v = cells_for(t.hi[g.v] - t.lo[g.v], t.extent[g.v] / samples);
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

void cell_spans(const SapGrid& grid, const AabbSoa& boxes, std::size_t begin, std::size_t k, int* u0, int* u1,
                int* v0, int* v1) {
  const SapGrid g = grid;  // a local copy: the int stores below cannot alias it, so the loop vectorises
  const float *lu = boxes.min(g.u) + begin, *hu = boxes.max(g.u) + begin;
  const float *lv = boxes.min(g.v) + begin, *hv = boxes.max(g.v) + begin;
  for (std::size_t j = 0; j < k; ++j) {
    u0[j] = g.cell_u(lu[j]);
    u1[j] = g.cell_u(hu[j]);
    v0[j] = g.cell_v(lv[j]);
    v1[j] = g.cell_v(hv[j]);
  }
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
