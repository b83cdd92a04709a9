// SweepAndPrune::update() without re-bucketing: the records of the previous frame are refreshed in place and the
// objects that left their cells go to a small overflow bucketed afresh every frame (see sweep_and_prune.hpp).
//
// Why this is exact: a pair is reported in the cell C holding the lower corner of its overlap on the grid axes, and C
// lies in the cell range of each box's CURRENT extent (cell_of is monotone). A record may stay in its cell as long as
// its object's current cell range is inside the range it had when the record was last refreshed, because then it is
// inside the range the object was bucketed with: every cell of the current range still holds a record of the object.
// An object whose range grew past that leaves all its cells (its records become tombstones, sap_cell.hpp) and is
// bucketed into the overflow by its current range, so every cell of its current range holds an overflow record.
#include "broadphase/sweep_and_prune.hpp"

#include "batchcol/errors.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <string>

namespace batchcol::broadphase {
namespace {

// Records ahead whose boxes are prefetched: enough misses in flight to cover memory latency, few enough to stay in L1.
constexpr std::ptrdiff_t kPrefetchDistance = 12;
// Records refreshed per block: the local arrays (12 x 64 x 4 bytes) stay in L1.
constexpr std::size_t kRefreshBlock = 64;

}  // namespace

void SweepAndPrune::refresh(const AabbSoa& boxes) {
  const std::size_t groups = first_cell_.size() - 1;
  const SapGrid g = grid_;
  const float *lx = boxes.min(g.axis), *hx = boxes.max(g.axis);
  const float *lu = boxes.min(g.u), *hu = boxes.max(g.u), *lv = boxes.min(g.v), *hv = boxes.max(g.v);
  Entry* all = entries_.data();
  const Entry* end_of_all = all + entries_.size();
  tbb::parallel_for(std::size_t{0}, groups, [&](std::size_t group) {
    std::vector<std::uint32_t>& movers = group_movers_[group];
    movers.clear();
    // Per block of records: the new boxes gathered into local arrays (scalar loads by object index), then the stay
    // test of every record in one branch-free loop (8 cell_of each, vectorised), then the records written.
    float nx0[kRefreshBlock], nx1[kRefreshBlock], nu0[kRefreshBlock], nu1[kRefreshBlock], nv0[kRefreshBlock],
        nv1[kRefreshBlock], ou0[kRefreshBlock], ou1[kRefreshBlock], ov0[kRefreshBlock], ov1[kRefreshBlock];
    int stays[kRefreshBlock], lowest[kRefreshBlock];
    for (std::size_t cell = first_cell_[group]; cell < first_cell_[group + 1]; ++cell) {
      const int cu = static_cast<int>(cell % g.cells_u), cv = static_cast<int>(cell / g.cells_u);
      Entry* const cell_end = all + cell_start_[cell + 1];
      for (Entry* b = all + cell_start_[cell]; b < cell_end; b += kRefreshBlock) {
        const std::size_t m = std::min<std::size_t>(kRefreshBlock, static_cast<std::size_t>(cell_end - b));
        for (std::size_t j = 0; j < m; ++j) {
          // In random object order the six loads below miss the cache; asking kPrefetchDistance records ahead
          // overlaps those misses.
          if (end_of_all - (b + j) > kPrefetchDistance) {
            const std::uint32_t ahead = b[j + kPrefetchDistance].id;
            if (ahead < object_count_) {
              for (const float* a : {lx, hx, lu, hu, lv, hv}) __builtin_prefetch(a + ahead);
            }
          }
          const std::uint32_t i = b[j].id;  // tombstones keep a valid id: their loads are harmless
          nx0[j] = lx[i], nx1[j] = hx[i], nu0[j] = lu[i], nu1[j] = hu[i], nv0[j] = lv[i], nv1[j] = hv[i];
          ou0[j] = b[j].u0, ou1[j] = b[j].u1, ov0[j] = b[j].v0, ov1[j] = b[j].v1;
        }
        for (std::size_t j = 0; j < m; ++j) {
          const int old_u0 = g.cell_u(ou0[j]), old_u1 = g.cell_u(ou1[j]), old_v0 = g.cell_v(ov0[j]),
                    old_v1 = g.cell_v(ov1[j]);
          stays[j] = (g.cell_u(nu0[j]) >= old_u0) & (g.cell_u(nu1[j]) <= old_u1) & (g.cell_v(nv0[j]) >= old_v0) &
                     (g.cell_v(nv1[j]) <= old_v1);
          lowest[j] = (old_u0 == cu) & (old_v0 == cv);
        }
        for (std::size_t j = 0; j < m; ++j) {
          Entry& r = b[j];
          if (!(ou0[j] <= ou1[j])) continue;  // a tombstone
          if (stays[j]) {
            r = Entry{nx0[j], nx1[j], nu0[j], nu1[j], nv0[j], nv1[j], r.id};
            continue;
          }
          // Every copy of the object takes this branch (they hold the same box); the one in the lowest cell of the
          // old range reports the object once.
          if (lowest[j]) movers.push_back(r.id);
          make_tombstone(r);
        }
      }
    }
  });
  for (const auto& m : group_movers_) overflow_ids_.insert(overflow_ids_.end(), m.begin(), m.end());
}

void SweepAndPrune::bucket_overflow(const AabbSoa& boxes) {
  const std::size_t cells = grid_.cell_count();
  const SapGrid g = grid_;
  const float *lx = boxes.min(g.axis), *hx = boxes.max(g.axis);
  const float *lu = boxes.min(g.u), *hu = boxes.max(g.u), *lv = boxes.min(g.v), *hv = boxes.max(g.v);
  overflow_start_.assign(cells + 1, 0);
  if (overflow_ids_.empty()) return;
  // Counting sort by cell, serial: the overflow is at most n / kOverflowFraction objects and usually a few percent.
  std::uint32_t* count = overflow_start_.data() + 1;
  for (const std::uint32_t i : overflow_ids_) {
    g.for_each_cell(g.cell_u(lu[i]), g.cell_u(hu[i]), g.cell_v(lv[i]), g.cell_v(hv[i]),
                    [&](std::size_t cell) { ++count[cell]; });
  }
  for (std::size_t c = 0; c < cells; ++c) overflow_start_[c + 1] += overflow_start_[c];
  overflow_entries_.resize(overflow_start_[cells]);
  // Write offsets: count[c - 1] runs from the start of cell c; restored below by shifting back.
  std::uint32_t* offset = overflow_start_.data();
  for (const std::uint32_t i : overflow_ids_) {
    const Entry e{lx[i], hx[i], lu[i], hu[i], lv[i], hv[i], i};
    g.for_each_cell(g.cell_u(e.u0), g.cell_u(e.u1), g.cell_v(e.v0), g.cell_v(e.v1),
                    [&](std::size_t cell) { overflow_entries_[offset[cell]++] = e; });
  }
  // offset[c] now equals the old start of cell c + 1: shift right by one to get the starts back.
  for (std::size_t c = cells; c > 0; --c) overflow_start_[c] = overflow_start_[c - 1];
  overflow_start_[0] = 0;
  // Each overflow cell is sorted by x0 in sort_and_sweep(), in parallel with the cells.
}

void SweepAndPrune::spatial_order(std::vector<std::uint32_t>& order) const {
  order.clear();
  if (!have_order_ || !stats_.rebucketed) return;
  const SapGrid g = grid_;
  const std::size_t cells = g.cell_count();
  for (std::size_t cell = 0; cell < cells; ++cell) {
    const int cu = static_cast<int>(cell % g.cells_u), cv = static_cast<int>(cell / g.cells_u);
    for (std::uint32_t k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
      const Entry& r = entries_[k];
      if (g.cell_u(r.u0) == cu && g.cell_v(r.v0) == cv) order.push_back(r.id);  // the object's lowest cell
    }
  }
  if (order.size() != object_count_) order.clear();  // cannot happen after a re-bucketing; never a partial order
}

void SweepAndPrune::renumber(const std::vector<std::uint32_t>& new_index) {
  if (new_index.size() != object_count_)
    throw InputError("broadphase: renumber() needs one new index per object (" + std::to_string(object_count_) +
                     "), got " + std::to_string(new_index.size()));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, entries_.size(), 65536),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t k = r.begin(); k < r.end(); ++k) entries_[k].id = new_index[entries_[k].id];
                    });
  for (Entry& r : overflow_entries_) r.id = new_index[r.id];
  for (std::uint32_t& id : overflow_ids_) id = new_index[id];
}

}  // namespace batchcol::broadphase
