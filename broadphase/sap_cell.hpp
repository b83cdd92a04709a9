// One grid cell of the sweep-and-prune: its records, their sort along the sweep axis and the box-pruning sweep.
// Reference: P. Terdiman, "box pruning" (codercorner.com, 2002-2017): sort the boxes by their minimum on one axis,
// then each box only meets the boxes whose minimum lies in [its min, its max] on that axis; test the two other axes.
#pragma once

#include "broadphase/pairs.hpp"
#include "broadphase/sap_grid.hpp"

#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace batchcol::broadphase {

/// One object copy in one grid cell: x = sweep axis, u, v = grid axes. 28 bytes.
struct CellRecord {
  float x0, x1, u0, u1, v0, v1;
  std::uint32_t id;
};

/// A record whose object left the cell: it keeps its x0 (the cell stays sorted) and can never overlap anything
/// (x1 = -inf stops its own scan at once; u0 > u1 fails every overlap test as the other box).
inline void make_tombstone(CellRecord& r) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  r.x1 = -kInf, r.u0 = kInf, r.u1 = -kInf, r.v0 = kInf, r.v1 = -kInf;
}

/// Cells up to this many records are insertion-sorted and need no scratch.
constexpr std::size_t kInsertionSortMax = 48;

/// Scratch of sort_cell(), one per worker slot. The caller grows it with reserve() to the largest cell before a
/// parallel sort (so what is allocated depends on the cells only, not on which thread sorted which cell); sort_cell()
/// never grows it then, and a warm frame allocates nothing.
struct SortScratch {
  std::vector<std::uint64_t> words, tmp;
  std::vector<CellRecord> entries;
  /// Makes room for cells of up to k records (none needed up to kInsertionSortMax).
  void reserve(std::size_t k) {
    if (k <= kInsertionSortMax) return;
    if (words.size() < k) words.resize(k), tmp.resize(k);
    if (entries.size() < k) entries.resize(k);
  }
  std::size_t bytes() const {
    return words.capacity() * sizeof(std::uint64_t) + tmp.capacity() * sizeof(std::uint64_t) +
           entries.capacity() * sizeof(CellRecord);
  }
};

/// Sorts e[0, k) by x0: insertion sort for small cells and for nearly sorted ones (update(): it gives up after about
/// 4 moves per record); for mid-size cells a counting sort into slabs of x0 followed by insertion sort (rebuild():
/// records arrive in input order); an LSD radix sort on the float keys for huge cells and when the slabs fail
/// (degenerate scenes).
void sort_cell(CellRecord* e, std::size_t k, bool nearly_sorted, SortScratch& scratch);

/// Where a cell's pairs go: the cell's grid coordinates, the filter and the output words (a << 32 | b).
struct CellSweep {
  const SapGrid& grid;
  int cu, cv;
  const FilterSoa& filter;
  std::vector<std::uint64_t>& out;

  /// Reports (p, q) when their boxes overlap on the grid axes (the sweep-axis overlap is known) and the lower corner
  /// of their overlap lies in this cell: a pair shared by several cells is reported by exactly one of them (cell_of
  /// is monotone, so that corner's cell is in both boxes' cell ranges).
  void test(const CellRecord& p, const CellRecord& q) const {
    if ((q.u0 <= p.u1) & (p.u0 <= q.u1) & (q.v0 <= p.v1) & (p.v0 <= q.v1)) report(p, q);
  }

  /// The second half of test(), for boxes known to overlap on the grid axes.
  void report(const CellRecord& p, const CellRecord& q) const {
    if (grid.cell_u(p.u0 < q.u0 ? q.u0 : p.u0) != cu || grid.cell_v(p.v0 < q.v0 ? q.v0 : p.v0) != cv) return;
    std::uint32_t a = p.id, b = q.id;
    if (a > b) std::swap(a, b);
    if (pair_passes(filter, a, b)) out.push_back(static_cast<std::uint64_t>(a) << 32 | b);
  }

  /// All pairs within e[0, k), sorted by x0: x0[i] <= x0[j] <= x1[j], so the x overlap reduces to x0[j] <= x1[i].
  /// The grid-axis test is one 4-wide comparison per candidate (sap_cell.cpp).
  void within(const CellRecord* e, std::size_t k) const;

  /// All pairs (m in a, n in b) of two sorted lists: the record with the smaller x0 scans the other list (ties: a's
  /// record first, and b's later scan starts after it), so each pair overlapping on x is met exactly once.
  void between(const CellRecord* a, std::size_t na, const CellRecord* b, std::size_t nb) const {
    std::size_t i = 0, j = 0;
    while (i < na && j < nb) {
      if (a[i].x0 <= b[j].x0) {
        const float hx = a[i].x1;
        for (std::size_t k = j; k < nb && b[k].x0 <= hx; ++k) test(a[i], b[k]);
        ++i;
      } else {
        const float hx = b[j].x1;
        for (std::size_t k = i; k < na && a[k].x0 <= hx; ++k) test(b[j], a[k]);
        ++j;
      }
    }
  }
};

}  // namespace batchcol::broadphase
