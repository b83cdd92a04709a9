// Parallel sweep-and-prune.
// References: P. Terdiman, "Sweep-and-prune" (2007, www.codercorner.com/SAP.pdf) and the "box pruning" series
// (codercorner.com, 2002-2017) for the inner loop: sort boxes by min on one axis, then for each box scan the boxes
// whose min lies in [min, max] on that axis and test the two other axes; "multi box pruning" for splitting the world
// into regions swept separately; P. Terdiman, "Radix sort revisited" (2000) for sorting float keys as integers.
//
// Pipeline (each stage is split into a fixed number of chunks, never into "one per thread", so every stage computes
// the same thing for any thread count):
//   1. keys: (sortable min on the sweep axis << 32 | object id), radix-sorted (rebuild) or the previous frame's order
//      re-keyed and insertion-sorted (update); equal keys are ordered by id in both cases, so both orders are equal;
//   2. bucketing: a stable counting sort of that order into the grid cells each box spans (see sap_grid.hpp), which
//      leaves every cell's entries sorted by min on the sweep axis;
//   3. sweep: box pruning inside each cell, groups of cells in parallel, each group appending to its own buffer;
//      a pair is kept only in the cell holding the lower corner of its overlap on the grid axes (so exactly once);
//   4. emit: the group buffers concatenated and radix-sorted as (a << 32 | b): unique keys, one sorted answer.
#include "broadphase/sweep_and_prune.hpp"

#include "broadphase/float_key.hpp"
#include "broadphase/radix_sort.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <utility>

namespace batchcol::broadphase {
namespace {

// Bucketing chunks: at least this many objects each (below, per-chunk cell counters cost more than they save) and at
// most kMaxBucketChunks (the counters are chunks x cells words).
constexpr std::size_t kBucketChunkMin = 16384;
constexpr std::size_t kMaxBucketChunks = 16;
// Groups of cells swept as parallel tasks, balanced by entry count; enough for load balance on a few cores.
constexpr std::size_t kSweepGroups = 64;
// Incremental re-sort: chunks insertion-sorted in parallel, then their boundaries merged sequentially.
constexpr std::size_t kSortChunk = 32768;
// Beyond a few moves per object, insertion sort costs more than the 4 radix passes (each reads and scatters every
// word): give up and radix-sort. "Moves" are inversions repaired, counted exactly. Objects moving by a tenth of their
// size in a dense scene already cross several neighbours' keys, hence a budget above 1.
constexpr std::size_t kMovesPerObject = 4;
// Objects visited in sorted order are scattered in memory: prefetch this many iterations ahead to overlap the misses.
constexpr std::size_t kPrefetchDistance = 16;
// Big boxes straddling many cells: when the copies exceed this many per object, coarsen the grid (x 1/2 per axis).
constexpr std::size_t kMaxCopiesPerObject = 4;

std::uint64_t pack_range(int cu0, int cu1, int cv0, int cv1) {
  return static_cast<std::uint64_t>(cu0) | static_cast<std::uint64_t>(cu1) << 16 |
         static_cast<std::uint64_t>(cv0) << 32 | static_cast<std::uint64_t>(cv1) << 48;
}

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

}  // namespace

void SweepAndPrune::rebuild(const AabbSoa& boxes, const FilterSoa& filter, std::vector<CandidatePair>& pairs) {
  run(boxes, filter, pairs, false);
}

void SweepAndPrune::update(const AabbSoa& boxes, const FilterSoa& filter, std::vector<CandidatePair>& pairs) {
  run(boxes, filter, pairs, true);
}

void SweepAndPrune::clear() { *this = SweepAndPrune(); }

std::size_t SweepAndPrune::memory_bytes() const {
  std::size_t bytes = order_.capacity() * 4 + words_.capacity() * 8 + scratch_.capacity() * 8 +
                      counts_.capacity() * 4 + cell_start_.capacity() * 4 + id_.capacity() * 4;
  for (const auto* v : {&x0_, &x1_, &u0_, &u1_, &v0_, &v1_}) bytes += v->capacity() * 4;
  for (const auto& g : group_pairs_) bytes += g.capacity() * 8;
  return bytes;
}

void SweepAndPrune::run(const AabbSoa& boxes, const FilterSoa& filter, std::vector<CandidatePair>& pairs,
                        bool incremental) {
  validate_aabbs(boxes);
  const std::size_t n = boxes.size();
  validate_filter(filter, n);
  incremental = incremental && have_order_ && order_.size() == n;
  if (!incremental) grid_ = choose_grid(boxes);
  stats_ = SapStats{};
  words_.resize(n);
  scratch_.resize(n);
  order_.resize(n);
  const float* key = boxes.min(grid_.axis);
  stats_.incremental = incremental && sort_incremental(key);
  if (!stats_.incremental) sort_full(key);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16384), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k < r.end(); ++k) order_[k] = static_cast<std::uint32_t>(words_[k]);
  });
  have_order_ = true;
  std::size_t entries = count_entries(boxes);
  while (entries > kMaxCopiesPerObject * n + 1024 && grid_.cell_count() > 1) {
    grid_ = coarser(grid_);
    entries = count_entries(boxes);
  }
  stats_.axis = grid_.axis;
  stats_.cells_u = grid_.cells_u;
  stats_.cells_v = grid_.cells_v;
  stats_.entries = entries;
  bucket(boxes);
  sweep(filter);
  emit(pairs);
  stats_.pairs = pairs.size();
}

void SweepAndPrune::sort_full(const float* key) {
  const std::size_t n = order_.size();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16384), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i < r.end(); ++i)
      words_[i] = static_cast<std::uint64_t>(sortable_key(key[i])) << 32 | i;
  });
  radix_sort(words_.data(), scratch_.data(), n, digit_shifts(32, 64));
}

bool SweepAndPrune::sort_incremental(const float* key) {
  const std::size_t n = order_.size();
  const std::size_t chunks = (n + kSortChunk - 1) / kSortChunk;
  std::vector<std::size_t> moves(chunks, 0);
  std::vector<char> ok(chunks, 1);
  std::uint64_t* w = words_.data();
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
    const std::size_t s = c * kSortChunk, e = std::min(n, s + kSortChunk);
    const std::size_t budget = (e - s) * kMovesPerObject;
    for (std::size_t k = s; k < e; ++k) {
      const std::uint32_t id = order_[k];
      w[k] = static_cast<std::uint64_t>(sortable_key(key[id])) << 32 | id;
    }
    std::size_t m = 0;
    for (std::size_t j = s + 1; j < e; ++j) {
      const std::uint64_t x = w[j];
      if (x >= w[j - 1]) continue;
      std::size_t i = j;
      do {
        w[i] = w[i - 1];
        --i;
      } while (i > s && w[i - 1] > x);
      w[i] = x;
      m += j - i;
      if (m > budget) { ok[c] = 0; return; }
    }
    moves[c] = m;
  });
  std::size_t total = 0;
  for (std::size_t c = 0; c < chunks; ++c) {
    if (!ok[c]) return false;
    total += moves[c];
  }
  // Merge the chunk boundaries: with [0, s) sorted and chunk c sorted, insert chunk c's elements backwards until one
  // is already >= its predecessor; the rest of the chunk is then >= everything before it.
  const std::size_t budget = n * kMovesPerObject;
  for (std::size_t c = 1; c < chunks; ++c) {
    const std::size_t s = c * kSortChunk, e = std::min(n, s + kSortChunk);
    for (std::size_t j = s; j < e; ++j) {
      const std::uint64_t x = w[j];
      if (x >= w[j - 1]) break;
      std::size_t i = j;
      do {
        w[i] = w[i - 1];
        --i;
      } while (i > 0 && w[i - 1] > x);
      w[i] = x;
      total += j - i;
      if (total > budget) return false;
    }
  }
  stats_.sort_moves = total;
  return true;
}

std::size_t SweepAndPrune::count_entries(const AabbSoa& boxes) {
  const std::size_t n = order_.size(), cells = grid_.cell_count();
  const Chunks ch(n, kBucketChunkMin, kMaxBucketChunks);
  counts_.assign(ch.count * cells, 0);
  std::vector<std::size_t> chunk_entries(ch.count, 0);
  const float *lu = boxes.min(grid_.u), *hu = boxes.max(grid_.u), *lv = boxes.min(grid_.v), *hv = boxes.max(grid_.v);
  const SapGrid g = grid_;
  tbb::parallel_for(std::size_t{0}, ch.count, [&](std::size_t c) {
    std::uint32_t* count = counts_.data() + c * cells;
    std::size_t total = 0;
    const std::size_t end = ch.end(c, n);
    for (std::size_t k = ch.begin(c, n); k < end; ++k) {
      if (k + kPrefetchDistance < end) {
        const std::uint32_t ahead = order_[k + kPrefetchDistance];
        __builtin_prefetch(lu + ahead), __builtin_prefetch(hu + ahead);
        __builtin_prefetch(lv + ahead), __builtin_prefetch(hv + ahead);
      }
      const std::uint32_t id = order_[k];
      const int cu0 = g.cell_u(lu[id]), cu1 = g.cell_u(hu[id]), cv0 = g.cell_v(lv[id]), cv1 = g.cell_v(hv[id]);
      scratch_[k] = pack_range(cu0, cu1, cv0, cv1);
      for (int cv = cv0; cv <= cv1; ++cv)
        for (int cu = cu0; cu <= cu1; ++cu) ++count[static_cast<std::size_t>(cv) * g.cells_u + cu];
      total += static_cast<std::size_t>(cu1 - cu0 + 1) * static_cast<std::size_t>(cv1 - cv0 + 1);
    }
    chunk_entries[c] = total;
  });
  std::size_t entries = 0;
  for (std::size_t e : chunk_entries) entries += e;
  return entries;
}

void SweepAndPrune::bucket(const AabbSoa& boxes) {
  const std::size_t n = order_.size(), cells = grid_.cell_count();
  const Chunks ch(n, kBucketChunkMin, kMaxBucketChunks);
  // Exclusive scan in (cell, chunk) order: chunk c's entries of a cell follow those of chunks < c, which keeps each
  // cell sorted by key (a stable counting sort).
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
  const std::size_t entries = running;
  for (auto* v : {&x0_, &x1_, &u0_, &u1_, &v0_, &v1_}) v->resize(entries);
  id_.resize(entries);
  const float *lx = boxes.min(grid_.axis), *hx = boxes.max(grid_.axis);
  const float *lu = boxes.min(grid_.u), *hu = boxes.max(grid_.u), *lv = boxes.min(grid_.v), *hv = boxes.max(grid_.v);
  const int cells_u = grid_.cells_u;
  tbb::parallel_for(std::size_t{0}, ch.count, [&](std::size_t c) {
    std::uint32_t* offset = counts_.data() + c * cells;
    const std::size_t end = ch.end(c, n);
    for (std::size_t k = ch.begin(c, n); k < end; ++k) {
      if (k + kPrefetchDistance < end) {
        const std::uint32_t ahead = order_[k + kPrefetchDistance];
        __builtin_prefetch(lx + ahead), __builtin_prefetch(hx + ahead), __builtin_prefetch(lu + ahead);
        __builtin_prefetch(hu + ahead), __builtin_prefetch(lv + ahead), __builtin_prefetch(hv + ahead);
      }
      const std::uint32_t id = order_[k];
      const std::uint64_t r = scratch_[k];
      const int cu0 = r & 0xffff, cu1 = (r >> 16) & 0xffff, cv0 = (r >> 32) & 0xffff, cv1 = (r >> 48) & 0xffff;
      const float a = lx[id], b = hx[id], d = lu[id], e = hu[id], f = lv[id], h = hv[id];
      for (int cv = cv0; cv <= cv1; ++cv)
        for (int cu = cu0; cu <= cu1; ++cu) {
          const std::uint32_t p = offset[static_cast<std::size_t>(cv) * cells_u + cu]++;
          x0_[p] = a, x1_[p] = b, u0_[p] = d, u1_[p] = e, v0_[p] = f, v1_[p] = h, id_[p] = id;
        }
    }
  });
}

void SweepAndPrune::sweep(const FilterSoa& filter) {
  const std::size_t cells = grid_.cell_count();
  const std::size_t groups = std::min(kSweepGroups, cells);
  group_pairs_.resize(groups);
  const std::uint64_t entries = cell_start_[cells];
  // Group g = the cells whose entries start in [g E / groups, (g + 1) E / groups): contiguous, balanced, fixed.
  std::vector<std::size_t> first_cell(groups + 1);
  for (std::size_t g = 0; g <= groups; ++g) {
    const std::uint64_t target = entries * g / groups;
    first_cell[g] = g == groups ? cells
                                : static_cast<std::size_t>(
                                      std::lower_bound(cell_start_.begin(), cell_start_.end() - 1, target) -
                                      cell_start_.begin());
  }
  first_cell[0] = 0;
  const SapGrid grid = grid_;
  const float *x0 = x0_.data(), *x1 = x1_.data(), *u0 = u0_.data(), *u1 = u1_.data(), *v0 = v0_.data(),
              *v1 = v1_.data();
  const std::uint32_t* id = id_.data();
  tbb::parallel_for(std::size_t{0}, groups, [&](std::size_t g) {
    std::vector<std::uint64_t>& out = group_pairs_[g];
    out.clear();
    for (std::size_t cell = first_cell[g]; cell < first_cell[g + 1]; ++cell) {
      const int cu = static_cast<int>(cell % grid.cells_u), cv = static_cast<int>(cell / grid.cells_u);
      const std::size_t s = cell_start_[cell], e = cell_start_[cell + 1];
      for (std::size_t i = s; i < e; ++i) {
        const float hx = x1[i], lu = u0[i], hu = u1[i], lv = v0[i], hv = v1[i];
        // Entries are sorted by x0, so x0[i] <= x0[j] <= x1[j]: the x overlap reduces to x0[j] <= x1[i].
        for (std::size_t j = i + 1; j < e && x0[j] <= hx; ++j) {
          if (!((u0[j] <= hu) & (lu <= u1[j]) & (v0[j] <= hv) & (lv <= v1[j]))) continue;
          // Report the pair only in the cell of the lower corner of the overlap (in both boxes' cell ranges since
          // cell_of is monotone), so pairs straddling several shared cells appear once.
          if (grid.cell_u(std::max(lu, u0[j])) != cu || grid.cell_v(std::max(lv, v0[j])) != cv) continue;
          std::uint32_t a = id[i], b = id[j];
          if (a > b) std::swap(a, b);
          if (pair_passes(filter, a, b)) out.push_back(static_cast<std::uint64_t>(a) << 32 | b);
        }
      }
    }
  });
}

void SweepAndPrune::emit(std::vector<CandidatePair>& pairs) {
  const std::size_t groups = group_pairs_.size();
  std::vector<std::size_t> start(groups + 1, 0);
  for (std::size_t g = 0; g < groups; ++g) start[g + 1] = start[g] + group_pairs_[g].size();
  const std::size_t total = start[groups];
  if (words_.size() < total) words_.resize(total);  // words_ and scratch_ are free again after bucketing
  if (scratch_.size() < total) scratch_.resize(total);
  tbb::parallel_for(std::size_t{0}, groups, [&](std::size_t g) {
    std::copy(group_pairs_[g].begin(), group_pairs_[g].end(), words_.begin() + static_cast<std::ptrdiff_t>(start[g]));
  });
  // Object ids are < n: only the low bit_width(n - 1) bits of a and of b can differ.
  const int w = bit_width(order_.empty() ? 0 : order_.size() - 1);
  std::vector<int> shifts = digit_shifts(0, w);
  for (int s : digit_shifts(32, 32 + w)) shifts.push_back(s);
  radix_sort(words_.data(), scratch_.data(), total, shifts);
  pairs.resize(total);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, total, 16384), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k < r.end(); ++k)
      pairs[k] = {static_cast<std::uint32_t>(words_[k] >> 32), static_cast<std::uint32_t>(words_[k])};
  });
}

}  // namespace batchcol::broadphase
