// Parallel sweep-and-prune broad phase: all pairs of objects whose float AABBs overlap or touch, filtered.
//
// Output: pairs (a, b) with a < b, sorted lexicographically, each exactly once; identical to brute_force_pairs()
// on the same input and the same for any thread count (tested). Touching counts: intervals [lo1, hi1] and
// [lo2, hi2] overlap iff lo1 <= hi2 and lo2 <= hi1.
//
// Usage: keep one SweepAndPrune per scene; call rebuild() for a fresh scene, update() every frame after.
//  - rebuild() chooses the sweep axis and the grid, buckets every object into the grid cells its box spans, sorts
//    each cell by the box minimum on the sweep axis and sweeps it.
//  - update() keeps the grid and the sorted cells of the previous frame: each record is refreshed in place with its
//    object's new box, each cell is re-sorted by insertion sort (the keys are nearly sorted), and swept. An object
//    whose new cell range is not inside its previous one leaves its cells (its records become inert tombstones) and
//    joins a small overflow bucketed afresh each frame; when the overflow passes 1/8 of the objects, or the object
//    count changed, or the scene drifted off the grid, update() re-buckets everything (as rebuild()).
// Both give the same pairs as brute force.
#pragma once

#include "broadphase/aabb_soa.hpp"
#include "broadphase/big_buffer.hpp"
#include "broadphase/pairs.hpp"
#include "broadphase/sap_cell.hpp"
#include "broadphase/sap_grid.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace batchcol::broadphase {

struct SapStats {
  int axis = -1;                  // sweep axis of the last rebuild
  int cells_u = 0, cells_v = 0;   // grid over the two other axes
  std::size_t entries = 0;        // object copies in grid cells (>= objects: boxes straddling cells), tombstones incl.
  std::size_t max_cell = 0;       // entries in the fullest cell (at the last re-bucketing)
  bool incremental = false;       // the last call kept the previous grid (false: axis and grid chosen afresh)
  bool rebucketed = true;         // the last call bucketed every object afresh (false: refreshed the sorted cells)
  std::size_t overflow = 0;       // objects in the overflow (left their cells since the last re-bucketing)
  std::size_t pairs = 0;
  double bucket_ms = 0, sweep_ms = 0, emit_ms = 0;  // wall clock of the stages: grid + bucketing (or refresh +
                                                    // overflow), per-cell sort and sweep, merging the pairs
};

class SweepAndPrune {
 public:
  /// Full rebuild: chooses the sweep axis and grid, buckets, sorts and sweeps each cell. Throws InputError (naming the
  /// lowest bad object index) for non-finite boxes, min > max, or a filter of the wrong size.
  void rebuild(const AabbSoa& boxes, const FilterSoa& filter, std::vector<CandidatePair>& pairs);
  /// Incremental update after the objects moved (same objects in the same order); same pairs as rebuild().
  void update(const AabbSoa& boxes, const FilterSoa& filter, std::vector<CandidatePair>& pairs);

  /// Object indices in spatial order (by the grid cell of the box's lower corner, then along the sweep axis); empty
  /// unless the last call re-bucketed every object. A caller that numbers its objects in this order makes every pass
  /// of the following frames (this one's included) read and write memory nearly sequentially.
  void spatial_order(std::vector<std::uint32_t>& order) const;
  /// The caller renumbered its objects: object i is now new_index[i] (a permutation of the last call's objects). Keeps
  /// the cells, so the next update() stays incremental. Throws InputError for a size mismatch.
  void renumber(const std::vector<std::uint32_t>& new_index);

  const SapStats& stats() const { return stats_; }
  /// Bytes held by this object (capacity of its buffers), excluding the input boxes and the output pairs.
  std::size_t memory_bytes() const;
  /// The part of memory_bytes() whose size grows with the candidate pairs rather than the objects.
  std::size_t pair_buffer_bytes() const;
  /// Frees the buffers; the next update() rebuilds.
  void clear();

 private:
  using Entry = CellRecord;

  void run(const AabbSoa& boxes, const FilterSoa& filter, std::vector<CandidatePair>& pairs, bool incremental);
  std::size_t count_entries(const AabbSoa& boxes);  // sets stats_.max_cell
  void bucket(const AabbSoa& boxes);
  void choose_groups();
  void refresh(const AabbSoa& boxes);  // update(): records refreshed in place, movers to the overflow
  void bucket_overflow(const AabbSoa& boxes);
  void sort_and_sweep(const FilterSoa& filter, bool nearly_sorted);
  void emit(std::vector<CandidatePair>& pairs);

  SapGrid grid_;
  bool have_order_ = false;               // a grid and bucketed cells from an earlier call exist
  std::size_t object_count_ = 0;          // objects of the last call
  std::size_t rebuild_entries_ = 0, rebuild_max_cell_ = 0;  // stats when the grid was chosen: drift reference
  SapStats stats_;
  BigVector<std::uint64_t> words_;        // the pairs (a << 32 | b) while sorting them
  BigVector<std::uint64_t> scratch_;      // radix scratch for the pairs
  std::vector<std::uint32_t> counts_;     // per bucketing chunk and cell: entry count, then write offset
  std::vector<std::uint32_t> cell_start_; // entries of cell c are [cell_start_[c], cell_start_[c + 1])
  BigVector<Entry> entries_;              // by cell, then sorted by x0 inside each cell; kept across update()s
  std::vector<std::uint32_t> overflow_ids_;    // objects that left their cells since the last re-bucketing
  std::vector<std::uint32_t> overflow_start_;  // overflow records of cell c: [overflow_start_[c], [c + 1])
  std::vector<Entry> overflow_entries_;        // by cell, sorted by x0
  std::vector<std::vector<std::uint64_t>> group_pairs_;  // per fixed group of cells: its pairs, written lock-free
  std::vector<std::vector<std::uint32_t>> group_movers_; // per group: objects leaving their cells this update
  // Sort scratch per worker slot of the calling arena (this_task_arena::current_thread_index()), each grown to the
  // largest cell before the parallel sort. Per slot rather than per group of cells: 64 groups each holding its
  // largest cell would cost ~30 bytes per object at 10k.
  std::vector<SortScratch> sort_scratch_;
  std::vector<std::size_t> first_cell_;         // per group: its first cell
  std::vector<std::size_t> group_start_;        // per group: offset of its pairs in words_
  std::vector<std::size_t> chunk_entries_;      // per bucketing chunk: cell copies
  std::vector<int> shifts_;                     // radix digits of the pair words
  std::vector<std::array<std::uint32_t, 256>> radix_histograms_;
};

}  // namespace batchcol::broadphase
