// Parallel sweep-and-prune broad phase: all pairs of objects whose float AABBs overlap or touch, filtered.
//
// Output: pairs (a, b) with a < b, sorted lexicographically, each exactly once; identical to brute_force_pairs()
// on the same input and the same for any thread count (tested). Touching counts: intervals [lo1, hi1] and
// [lo2, hi2] overlap iff lo1 <= hi2 and lo2 <= hi1.
//
// Usage: keep one SweepAndPrune per scene; call rebuild() for a fresh scene, update() every frame after. update()
// keeps the sweep axis and the grid of the last rebuild (skipping their choice); it chooses them afresh, like
// rebuild(), when the object count changed or the scene drifted away from the grid (many more cell copies, or a
// much fuller largest cell, than at the last rebuild). Both give the same pairs; every call re-buckets and re-sorts
// each cell (the per-cell sort runs in cache, so re-sorting a previous order would save little).
#pragma once

#include "broadphase/aabb_soa.hpp"
#include "broadphase/pairs.hpp"
#include "broadphase/sap_grid.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace batchcol::broadphase {

struct SapStats {
  int axis = -1;                  // sweep axis of the last rebuild
  int cells_u = 0, cells_v = 0;   // grid over the two other axes
  std::size_t entries = 0;        // object copies in grid cells (>= objects: boxes straddling cells)
  std::size_t max_cell = 0;       // entries in the fullest cell
  bool incremental = false;       // the last call kept the previous grid (false: axis and grid chosen afresh)
  std::size_t pairs = 0;
  double bucket_ms = 0, sweep_ms = 0, emit_ms = 0;  // wall clock of the stages: grid + bucketing, per-cell sort and
                                                    // sweep, merging the pairs
};

class SweepAndPrune {
 public:
  /// Full rebuild: chooses the sweep axis and grid, buckets, sorts and sweeps each cell. Throws InputError (naming the
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
  // One object copy in one grid cell: x = sweep axis, u, v = grid axes; key = sortable_key(x0). 32 bytes, so a
  // candidate tested by the sweep costs one cache line at most.
  struct alignas(32) Entry {
    float x0, x1, u0, u1, v0, v1;
    std::uint32_t id, key;
  };

  void run(const AabbSoa& boxes, const FilterSoa& filter, std::vector<CandidatePair>& pairs, bool incremental);
  std::size_t count_entries(const AabbSoa& boxes);  // sets stats_.max_cell
  void bucket(const AabbSoa& boxes);
  void sort_and_sweep(const FilterSoa& filter);
  void emit(std::vector<CandidatePair>& pairs);

  SapGrid grid_;
  bool have_order_ = false;               // a grid from an earlier call exists
  std::size_t object_count_ = 0;          // objects of the last call
  std::size_t rebuild_entries_ = 0, rebuild_max_cell_ = 0;  // stats when the grid was chosen: drift reference
  SapStats stats_;
  std::vector<std::uint64_t> words_;      // the pairs (a << 32 | b) while sorting them
  std::vector<std::uint64_t> scratch_;    // radix scratch for the pairs
  std::vector<std::uint32_t> counts_;     // per bucketing chunk and cell: entry count, then write offset
  std::vector<std::uint32_t> cell_start_; // entries of cell c are [cell_start_[c], cell_start_[c + 1])
  std::vector<Entry> entries_;            // by cell, then sorted by (x0, id) inside each cell
  std::vector<std::vector<std::uint64_t>> group_pairs_;  // per fixed group of cells: its pairs, written lock-free
  // Scratch kept across calls so that a frame of a warm SAP allocates nothing.
  struct CellScratch {
    std::vector<std::uint64_t> words, tmp;
    std::vector<Entry> entries;
  };
  std::vector<CellScratch> group_scratch_;      // per group: radix sort of its large cells
  std::vector<std::size_t> first_cell_;         // per group: its first cell
  std::vector<std::size_t> group_start_;        // per group: offset of its pairs in words_
  std::vector<std::size_t> chunk_entries_;      // per bucketing chunk: cell copies
  std::vector<int> shifts_;                     // radix digits of the pair words
  std::vector<std::array<std::uint32_t, 256>> radix_histograms_;
};

}  // namespace batchcol::broadphase
