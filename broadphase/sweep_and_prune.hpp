// Parallel sweep-and-prune broad phase: all pairs of objects whose float AABBs overlap or touch, filtered.
//
// Output: pairs (a, b) with a < b, sorted lexicographically, each exactly once; identical to brute_force_pairs()
// on the same input and the same for any thread count (tested). Touching counts: intervals [lo1, hi1] and
// [lo2, hi2] overlap iff lo1 <= hi2 and lo2 <= hi1.
//
// Usage: keep one SweepAndPrune per scene; call rebuild() for a fresh scene, update() every frame after. update()
// re-sorts the previous frame's order (nearly sorted when objects move a little) and keeps the sweep axis and the
// grid of the last rebuild; it falls back to a full rebuild when the object count changed or the order is far from
// sorted. Both give the same pairs.
#pragma once

#include "broadphase/aabb_soa.hpp"
#include "broadphase/pairs.hpp"
#include "broadphase/sap_grid.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace batchcol::broadphase {

struct SapStats {
  int axis = -1;                  // sweep axis of the last rebuild
  int cells_u = 0, cells_v = 0;   // grid over the two other axes
  std::size_t entries = 0;        // object copies in grid cells (>= objects: boxes straddling cells)
  std::size_t sort_moves = 0;     // insertion-sort moves of the last update()
  bool incremental = false;       // the last call re-sorted the previous order (false: full radix sort)
  std::size_t pairs = 0;
};

class SweepAndPrune {
 public:
  /// Full rebuild: chooses the sweep axis and grid, radix-sorts the keys, sweeps. Throws InputError (naming the
  /// lowest bad object index) for non-finite boxes, min > max, or a filter of the wrong size.
  void rebuild(const AabbSoa& boxes, const FilterSoa& filter, std::vector<CandidatePair>& pairs);
  /// Incremental update after the objects moved (same objects, same count); same pairs as rebuild().
  void update(const AabbSoa& boxes, const FilterSoa& filter, std::vector<CandidatePair>& pairs);

  const SapStats& stats() const { return stats_; }
  /// Bytes held by this object (capacity of its buffers), excluding the input boxes and the output pairs.
  std::size_t memory_bytes() const;
  /// Frees the buffers; the next update() rebuilds.
  void clear();

 private:
  void run(const AabbSoa& boxes, const FilterSoa& filter, std::vector<CandidatePair>& pairs, bool incremental);
  void sort_full(const float* keys);
  bool sort_incremental(const float* keys);
  void bucket(const AabbSoa& boxes);
  std::size_t count_entries(const AabbSoa& boxes);
  void sweep(const FilterSoa& filter);
  void emit(std::vector<CandidatePair>& pairs);

  SapGrid grid_;
  bool have_order_ = false;
  SapStats stats_;
  std::vector<std::uint32_t> order_;      // object ids sorted by min on the sweep axis (kept for update())
  std::vector<std::uint64_t> words_;      // (key << 32 | id) while sorting; then the pairs (a << 32 | b)
  std::vector<std::uint64_t> scratch_;    // radix scratch; then each sorted object's cell range (4 x 16 bits)
  std::vector<std::uint32_t> counts_;     // per bucketing chunk and cell: entry count, then write offset
  std::vector<std::uint32_t> cell_start_; // entries of cell c are [cell_start_[c], cell_start_[c + 1])
  // Entries (object copies per cell), sorted by cell then by min on the sweep axis: x = sweep axis, u, v = grid.
  std::vector<float> x0_, x1_, u0_, u1_, v0_, v1_;
  std::vector<std::uint32_t> id_;
  std::vector<std::vector<std::uint64_t>> group_pairs_;  // per fixed group of cells: its pairs, written lock-free
};

}  // namespace batchcol::broadphase
