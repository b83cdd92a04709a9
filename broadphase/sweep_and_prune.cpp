// Parallel sweep-and-prune.
// References: P. Terdiman, "Sweep-and-prune" (2007, www.codercorner.com/SAP.pdf) and the "box pruning" series
// (codercorner.com, 2002-2017) for the inner loop (sap_cell.hpp); "multi box pruning" for splitting the world into
// regions swept separately; P. Terdiman, "Radix sort revisited" (2000) for sorting float keys as integers.
//
// Pipeline (each stage is split into a fixed number of chunks or cell groups, never into "one per thread", so every
// stage computes the same thing for any thread count):
//   1. grid: chosen by rebuild() (see sap_grid.hpp), kept by update() unless the object count changed or the scene
//      drifted (entries or fullest cell grew past kDrift* of the rebuild's);
//   2. rebuild() buckets in INPUT order: a counting pass and a scatter pass read the box arrays linearly and write
//      one record per cell a box spans; update() instead refreshes the previous frame's records in place (sap_update
//      below) and buckets only the overflow (objects that left their cells);
//   3. per cell, in parallel over fixed groups of cells: sort the records by min on the sweep axis (nearly sorted in
//      update()), then box pruning within the cell, plus overflow x cell and overflow x overflow; a pair is kept only
//      in the cell holding the lower corner of its overlap on the grid axes (so exactly once); each group appends to
//      its own buffer;
//   4. emit: the group buffers concatenated and radix-sorted as (a << 32 | b): unique keys, one sorted answer.
#include "broadphase/sweep_and_prune.hpp"

#include "broadphase/radix_sort.hpp"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <utility>

namespace batchcol::broadphase {
namespace {

// Bucketing chunks: at least this many objects each (below, per-chunk cell counters cost more than they save; 4096
// lets a 10k scene use both cores) and at most kMaxBucketChunks (the counters are chunks x cells words, kept between
// frames: 4 chunks x n/16 cells x 4 bytes = 1 byte per object at most).
constexpr std::size_t kBucketChunkMin = 4096;
constexpr std::size_t kMaxBucketChunks = 4;
// Groups of cells sorted and swept as parallel tasks, balanced by entry count; enough for load balance on a few cores.
constexpr std::size_t kSweepGroups = 64;
// update() re-buckets when the entries exceed kDriftEntries x (or the fullest cell kDriftMaxCell x) those of the call
// that chose the current grid, plus some slack for small scenes, or when the overflow holds more than
// 1 / kOverflowFraction of the objects (it is bucketed every frame and its tombstones are swept for nothing).
constexpr double kDriftEntries = 1.25;
constexpr double kDriftMaxCell = 2.0;
constexpr std::size_t kOverflowFraction = 8;
// Big boxes straddling many cells: when the copies exceed this many per object, coarsen the grid (x 1/2 per axis).
constexpr std::size_t kMaxCopiesPerObject = 4;

struct Chunks {
  std::size_t count, size;
  Chunks(std::size_t n, std::size_t min_size, std::size_t max_count)
      : count(std::clamp<std::size_t>(n / min_size, 1, max_count)), size((n + count - 1) / count) {}
  std::size_t begin(std::size_t c, std::size_t n) const { return std::min(n, c * size); }
  std::size_t end(std::size_t c, std::size_t n) const { return std::min(n, (c + 1) * size); }
};

int bit_width(std::size_t x) {
  int w = 0;
  while (x > 0) ++w, x >>= 1;
  return w;
}

template <class V> std::size_t bytes(const V& v) { return v.capacity() * sizeof(typename V::value_type); }

}  // namespace

void SweepAndPrune::rebuild(const AabbSoa& boxes, const FilterSoa& filter, std::vector<CandidatePair>& pairs) {
  run(boxes, filter, pairs, false);
}

void SweepAndPrune::update(const AabbSoa& boxes, const FilterSoa& filter, std::vector<CandidatePair>& pairs) {
  run(boxes, filter, pairs, true);
}

void SweepAndPrune::clear() { *this = SweepAndPrune(); }

std::size_t SweepAndPrune::pair_buffer_bytes() const {
  std::size_t b = held_bytes(words_) + held_bytes(scratch_);
  for (const auto& g : group_pairs_) b += bytes(g);
  return b;
}

std::size_t SweepAndPrune::memory_bytes() const {
  std::size_t b = pair_buffer_bytes() + bytes(counts_) + bytes(cell_start_) + held_bytes(entries_) +
                  bytes(overflow_ids_) + bytes(overflow_start_) + bytes(overflow_entries_);
  for (const auto& g : group_movers_) b += bytes(g);
  for (const SortScratch& s : sort_scratch_) b += s.bytes();
  b += bytes(sort_scratch_);
  return b + bytes(first_cell_) + bytes(group_start_) + bytes(chunk_entries_) + bytes(shifts_) +
         bytes(radix_histograms_) + bytes(group_pairs_) + bytes(group_movers_);
}

void SweepAndPrune::run(const AabbSoa& boxes, const FilterSoa& filter, std::vector<CandidatePair>& pairs,
                        bool incremental) {
  using Clock = std::chrono::steady_clock;
  const auto ms = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  const auto t0 = Clock::now();
  validate_aabbs(boxes);
  const std::size_t n = boxes.size();
  validate_filter(filter, n);
  incremental = incremental && have_order_ && object_count_ == n;
  const SapStats previous = stats_;
  stats_ = SapStats{};
  bool rebucket = true;
  if (incremental) {
    refresh(boxes);  // fills overflow_ids_
    rebucket = overflow_ids_.size() * kOverflowFraction > n + 1024;
    stats_.max_cell = previous.max_cell;
  }
  if (!incremental) grid_ = choose_grid(boxes);
  std::size_t entries = cell_start_.empty() ? 0 : cell_start_.back();
  if (rebucket) {
    entries = count_entries(boxes);
    const auto grew = [](std::size_t now, std::size_t then, double factor, double slack) {
      return static_cast<double>(now) > factor * static_cast<double>(then) + slack;
    };
    if (incremental && (grew(entries, rebuild_entries_, kDriftEntries, 1024) ||
                        grew(stats_.max_cell, rebuild_max_cell_, kDriftMaxCell, 64))) {
      incremental = false;
      grid_ = choose_grid(boxes);
      entries = count_entries(boxes);
    }
    while (entries > kMaxCopiesPerObject * n + 1024 && grid_.cell_count() > 1) {
      grid_ = coarser(grid_);
      entries = count_entries(boxes);
    }
    if (!incremental) rebuild_entries_ = entries, rebuild_max_cell_ = stats_.max_cell;
    bucket(boxes);
    choose_groups();
    overflow_ids_.clear();
  }
  bucket_overflow(boxes);
  object_count_ = n;
  have_order_ = true;
  stats_.axis = grid_.axis;
  stats_.cells_u = grid_.cells_u;
  stats_.cells_v = grid_.cells_v;
  stats_.entries = entries;
  stats_.incremental = incremental;
  stats_.rebucketed = rebucket;
  stats_.overflow = overflow_ids_.size();
  const auto t1 = Clock::now();
  sort_and_sweep(filter, !rebucket);
  const auto t2 = Clock::now();
  emit(pairs);
  stats_.pairs = pairs.size();
  stats_.bucket_ms = ms(t0, t1), stats_.sweep_ms = ms(t1, t2), stats_.emit_ms = ms(t2, Clock::now());
}

std::size_t SweepAndPrune::count_entries(const AabbSoa& boxes) {
  const std::size_t n = boxes.size(), cells = grid_.cell_count();
  const Chunks ch(n, kBucketChunkMin, kMaxBucketChunks);
  counts_.assign(ch.count * cells, 0);
  chunk_entries_.assign(ch.count, 0);
  const SapGrid g = grid_;
  tbb::parallel_for(std::size_t{0}, ch.count, [&](std::size_t c) {
    std::uint32_t* count = counts_.data() + c * cells;
    std::size_t total = 0;
    const std::size_t end = ch.end(c, n);
    int u0[kSpanBlock], u1[kSpanBlock], v0[kSpanBlock], v1[kSpanBlock];
    for (std::size_t b = ch.begin(c, n); b < end; b += kSpanBlock) {
      const std::size_t k = std::min(kSpanBlock, end - b);
      cell_spans(g, boxes, b, k, u0, u1, v0, v1);
      for (std::size_t j = 0; j < k; ++j) {
        g.for_each_cell(u0[j], u1[j], v0[j], v1[j], [&](std::size_t cell) { ++count[cell], ++total; });
      }
    }
    chunk_entries_[c] = total;
  });
  std::size_t entries = 0;
  for (std::size_t e : chunk_entries_) entries += e;
  std::size_t max_cell = 0;
  for (std::size_t cell = 0; cell < cells; ++cell) {
    std::size_t total = 0;
    for (std::size_t c = 0; c < ch.count; ++c) total += counts_[c * cells + cell];
    max_cell = std::max(max_cell, total);
  }
  stats_.max_cell = max_cell;
  return entries;
}

void SweepAndPrune::bucket(const AabbSoa& boxes) {
  const std::size_t n = boxes.size(), cells = grid_.cell_count();
  const Chunks ch(n, kBucketChunkMin, kMaxBucketChunks);
  // Exclusive scan in (cell, chunk) order: chunk c's entries of a cell follow those of chunks < c.
  cell_start_.resize(cells + 1);
  std::uint32_t running = 0;
  for (std::size_t cell = 0; cell < cells; ++cell) {
    cell_start_[cell] = running;
    for (std::size_t c = 0; c < ch.count; ++c) {
      const std::uint32_t count = counts_[c * cells + cell];
      counts_[c * cells + cell] = running;
      running += count;
    }
  }
  cell_start_[cells] = running;
  resize_tight(entries_, running);  // default-initialised (BigBufferAllocator): every record is written below
  Entry* out = entries_.data();
  const float *lx = boxes.min(grid_.axis), *hx = boxes.max(grid_.axis);
  const float *lu = boxes.min(grid_.u), *hu = boxes.max(grid_.u), *lv = boxes.min(grid_.v), *hv = boxes.max(grid_.v);
  const SapGrid g = grid_;
  tbb::parallel_for(std::size_t{0}, ch.count, [&](std::size_t c) {
    std::uint32_t* offset = counts_.data() + c * cells;
    const std::size_t end = ch.end(c, n);
    int u0[kSpanBlock], u1[kSpanBlock], v0[kSpanBlock], v1[kSpanBlock];
    for (std::size_t b = ch.begin(c, n); b < end; b += kSpanBlock) {
      const std::size_t k = std::min(kSpanBlock, end - b);
      cell_spans(g, boxes, b, k, u0, u1, v0, v1);
      for (std::size_t j = 0; j < k; ++j) {
        const std::size_t i = b + j;
        const Entry e{lx[i], hx[i], lu[i], hu[i], lv[i], hv[i], static_cast<std::uint32_t>(i)};
        g.for_each_cell(u0[j], u1[j], v0[j], v1[j], [&](std::size_t cell) { out[offset[cell]++] = e; });
      }
    }
  });
}

void SweepAndPrune::choose_groups() {
  // Group g = the cells whose entries start in [g E / groups, (g + 1) E / groups): contiguous, balanced, fixed.
  const std::size_t cells = grid_.cell_count();
  const std::size_t groups = std::min(kSweepGroups, cells);
  const std::uint64_t entries = cell_start_[cells];
  first_cell_.resize(groups + 1);
  for (std::size_t g = 0; g <= groups; ++g) {
    const std::uint64_t target = entries * g / groups;
    first_cell_[g] = g == groups ? cells
                                 : static_cast<std::size_t>(
                                       std::lower_bound(cell_start_.begin(), cell_start_.end() - 1, target) -
                                       cell_start_.begin());
  }
  first_cell_[0] = 0;
  group_pairs_.resize(groups);
  group_movers_.resize(groups);
}

void SweepAndPrune::sort_and_sweep(const FilterSoa& filter, bool nearly_sorted) {
  const std::size_t groups = first_cell_.size() - 1;
  const SapGrid grid = grid_;
  Entry* all = entries_.data();
  Entry* over = overflow_entries_.data();
  // Scratch for the largest cell in every worker slot, grown here (serially): what is allocated depends on the cells,
  // never on which thread sorts which cell, so a warm frame allocates nothing.
  std::size_t largest = 0;
  for (std::size_t cell = 0; cell + 1 < cell_start_.size(); ++cell)
    largest = std::max<std::size_t>({largest, cell_start_[cell + 1] - cell_start_[cell],
                                     overflow_start_[cell + 1] - overflow_start_[cell]});
  const auto slots = static_cast<std::size_t>(tbb::this_task_arena::max_concurrency());
  if (sort_scratch_.size() < slots) sort_scratch_.resize(slots);
  for (SortScratch& s : sort_scratch_) s.reserve(largest);
  tbb::parallel_for(std::size_t{0}, groups, [&](std::size_t g) {
    std::vector<std::uint64_t>& out = group_pairs_[g];
    out.clear();
    SortScratch& scratch = sort_scratch_[static_cast<std::size_t>(tbb::this_task_arena::current_thread_index())];
    for (std::size_t cell = first_cell_[g]; cell < first_cell_[g + 1]; ++cell) {
      const std::size_t s = cell_start_[cell], k = cell_start_[cell + 1] - s;
      Entry* e = all + s;
      sort_cell(e, k, nearly_sorted, scratch);
      const CellSweep sweep{grid, static_cast<int>(cell % grid.cells_u), static_cast<int>(cell / grid.cells_u),
                            filter, out};
      sweep.within(e, k);
      const std::size_t os = overflow_start_[cell], ok = overflow_start_[cell + 1] - os;
      if (ok == 0) continue;
      sort_cell(over + os, ok, false, scratch);
      sweep.within(over + os, ok);
      sweep.between(e, k, over + os, ok);
    }
  });
}

void SweepAndPrune::emit(std::vector<CandidatePair>& pairs) {
  const std::size_t groups = group_pairs_.size();
  std::vector<std::size_t>& start = group_start_;
  start.assign(groups + 1, 0);
  for (std::size_t g = 0; g < groups; ++g) start[g + 1] = start[g] + group_pairs_[g].size();
  const std::size_t total = start[groups];
  if (words_.size() < total) resize_tight(words_, total);
  if (scratch_.size() < total) resize_tight(scratch_, total);
  tbb::parallel_for(std::size_t{0}, groups, [&](std::size_t g) {
    std::copy(group_pairs_[g].begin(), group_pairs_[g].end(), words_.begin() + static_cast<std::ptrdiff_t>(start[g]));
  });
  // Object ids are < n: only the low bit_width(n - 1) bits of a and of b can differ.
  const int w = bit_width(object_count_ == 0 ? 0 : object_count_ - 1);
  shifts_.clear();
  for (int s = 0; s < w; s += 8) shifts_.push_back(s);        // digit_shifts(0, w) without a temporary vector
  for (int s = 32; s < 32 + w; s += 8) shifts_.push_back(s);  // digit_shifts(32, 32 + w)
  radix_sort(words_.data(), scratch_.data(), total, shifts_, radix_histograms_);
  pairs.resize(total);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, total, 16384), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k < r.end(); ++k)
      pairs[k] = {static_cast<std::uint32_t>(words_[k] >> 32), static_cast<std::uint32_t>(words_[k])};
  });
}

}  // namespace batchcol::broadphase
