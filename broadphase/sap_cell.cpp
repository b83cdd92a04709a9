// Sorting one grid cell's records by their minimum on the sweep axis (see sap_cell.hpp).
// Reference for the radix path: P. Terdiman, "Radix sort revisited" (2000): float keys sorted as integers
// (float_key.hpp), passes whose digit is constant skipped.
#include "broadphase/sap_cell.hpp"

#include "broadphase/float_key.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstring>
#include <limits>
#include <utility>

namespace batchcol::broadphase {
namespace {

// Cells up to kInsertionSortMax records are insertion-sorted from any order; up to kSlabSortMax, counting-sorted into
// slabs of x0 and then insertion-sorted; larger ones (degenerate scenes: the grid could not split them) radix-sorted.
// A nearly sorted cell (update()) tries insertion sort first. (kInsertionSortMax: sap_cell.hpp.)
constexpr std::size_t kSlabSortMax = 4096;
// Slabs per record: two records per slab on average, so the insertion sort after the counting sort moves about one
// record per slab. The histogram (kSlabSortMax / 2 + 1 counters) lives on the stack.
constexpr std::size_t kRecordsPerSlab = 2;
// A nearly sorted cell (update()) is insertion-sorted while the records moved stay below this many per record plus
// a constant; past that budget the order was not "nearly sorted" and the next method finishes the job. A cell only
// predicted to be nearly sorted by its few descents gets one move per record: sorted runs of a renumbered scene
// meeting in a cell of a new grid have few descents but need many moves, which the slab sort does cheaper.
constexpr std::size_t kMovesPerRecord = 4;
constexpr std::size_t kPredictedMovesPerRecord = 1;
constexpr std::size_t kMovesSlack = 64;
// A cell with at most 1/kDescentFraction of its neighbours out of order is treated as nearly sorted.
constexpr std::size_t kDescentFraction = 8;

// Insertion sort by x0 with a budget of element moves; returns false (records permuted, none lost) when exceeded.
bool insertion_sort(CellRecord* e, std::size_t k, std::size_t budget) {
  std::size_t moves = 0;
  for (std::size_t j = 1; j < k; ++j) {
    if (!(e[j].x0 < e[j - 1].x0)) continue;
    const CellRecord x = e[j];
    std::size_t i = j;
    do {
      e[i] = e[i - 1];
      --i;
    } while (i > 0 && x.x0 < e[i - 1].x0);
    e[i] = x;
    moves += j - i;
    if (moves > budget) return false;
  }
  return true;
}

void radix_sort_cell(CellRecord* e, std::size_t k, SortScratch& s) {
  s.reserve(k);  // a no-op after the caller's reserve()
  std::vector<std::uint64_t>& w = s.words;
  std::vector<std::uint64_t>& tmp = s.tmp;
  std::vector<CellRecord>& buf = s.entries;
  std::array<std::array<std::uint32_t, 256>, 4> hist{};
  for (std::size_t i = 0; i < k; ++i) {
    const std::uint32_t key = sortable_key(e[i].x0);
    w[i] = static_cast<std::uint64_t>(key) << 32 | i;
    ++hist[0][key & 0xff], ++hist[1][(key >> 8) & 0xff], ++hist[2][(key >> 16) & 0xff], ++hist[3][key >> 24];
  }
  std::uint64_t* src = w.data();
  std::uint64_t* dst = tmp.data();
  for (int d = 0; d < 4; ++d) {
    std::uint32_t running = 0;
    bool trivial = false;
    for (int b = 0; b < 256; ++b) {
      const std::uint32_t count = hist[d][b];
      if (count == k) { trivial = true; break; }
      hist[d][b] = running;
      running += count;
    }
    if (trivial) continue;
    const int shift = 32 + 8 * d;
    for (std::size_t i = 0; i < k; ++i) dst[hist[d][(src[i] >> shift) & 0xff]++] = src[i];
    std::swap(src, dst);
  }
  for (std::size_t i = 0; i < k; ++i) buf[i] = e[static_cast<std::uint32_t>(src[i])];
  std::memcpy(static_cast<void*>(e), buf.data(), k * sizeof(CellRecord));
}

// Counting sort of e[0, k) into slabs of equal width between the smallest and largest x0, then insertion sort inside
// the slabs. The slab index floor((x0 - lo) * scale) is monotone in x0 (rounded subtraction and product, clamp,
// truncation), so records of a lower slab never belong after a higher one. Returns false, records permuted and none
// lost, when the x0 range overflows float or the slabs were too uneven for the move budget.
bool slab_sort(CellRecord* e, std::size_t k, SortScratch& s) {
  float lo = e[0].x0, hi = e[0].x0;
  for (std::size_t i = 1; i < k; ++i) {
    lo = e[i].x0 < lo ? e[i].x0 : lo;
    hi = e[i].x0 > hi ? e[i].x0 : hi;
  }
  if (!(hi > lo)) return true;  // all keys equal: any order is sorted
  const std::size_t slabs = k / kRecordsPerSlab;
  const float scale = static_cast<float>(slabs) / (hi - lo);
  if (!(scale > 0.0f) || !(scale < std::numeric_limits<float>::infinity())) return false;  // range overflowed
  const float last = static_cast<float>(slabs - 1);
  const auto slab = [&](float x) {
    const float t = (x - lo) * scale;
    return static_cast<std::uint32_t>(t < last ? t : last);
  };
  std::uint32_t start[kSlabSortMax / kRecordsPerSlab + 1];
  std::fill(start, start + slabs + 1, 0u);
  for (std::size_t i = 0; i < k; ++i) ++start[slab(e[i].x0) + 1];
  for (std::size_t b = 0; b < slabs; ++b) start[b + 1] += start[b];
  s.reserve(k);  // a no-op after the caller's reserve()
  CellRecord* buf = s.entries.data();
  for (std::size_t i = 0; i < k; ++i) buf[start[slab(e[i].x0)]++] = e[i];
  std::memcpy(static_cast<void*>(e), buf, k * sizeof(CellRecord));
  return insertion_sort(e, k, kMovesPerRecord * k + kMovesSlack);
}

}  // namespace

void sort_cell(CellRecord* e, std::size_t k, bool nearly_sorted, SortScratch& scratch) {
  if (k < 2) return;
  if (k <= kInsertionSortMax) {
    insertion_sort(e, k, static_cast<std::size_t>(-1));
    return;
  }
  // Nearly sorted: the previous frame's order (update()), or objects numbered in spatial order (Scene does that).
  // Few descents predict few insertion moves; the move budget bounds the cost when the prediction fails.
  std::size_t descents = 0;
  for (std::size_t i = 1; i < k; ++i) descents += e[i].x0 < e[i - 1].x0 ? 1 : 0;
  if (descents == 0) return;
  if (nearly_sorted && insertion_sort(e, k, kMovesPerRecord * k + kMovesSlack)) return;
  if (!nearly_sorted && descents * kDescentFraction <= k &&
      insertion_sort(e, k, kPredictedMovesPerRecord * k + kMovesSlack))
    return;
  if (k <= kSlabSortMax && slab_sort(e, k, scratch)) return;
  radix_sort_cell(e, k, scratch);
}

void CellSweep::within(const CellRecord* e, std::size_t k) const {
#if defined(__SSE2__)
  static_assert(offsetof(CellRecord, u1) == offsetof(CellRecord, u0) + 4 &&
                    offsetof(CellRecord, v0) == offsetof(CellRecord, u0) + 8 &&
                    offsetof(CellRecord, v1) == offsetof(CellRecord, u0) + 12,
                "within() loads u0, u1, v0, v1 as one 4-float vector");
  // The four grid-axis conditions q.u0 <= p.u1, -q.u1 <= -p.u0, q.v0 <= p.v1, -q.v1 <= -p.v0 as one comparison of
  // q's (u0, -u1, v0, -v1) with p's (u1, -u0, v1, -v0): the fields u0, u1, v0, v1 are adjacent in a record. Sign
  // flips are exact and keep the order (-0 and +0 compare equal); a tombstone (u0 = +inf, u1 = -inf) fails lane 0
  // or 1 as q, and as p its x1 = -inf ends the scan before any test. Replaces four scalar compares and a mispredicted
  // branch per candidate.
  const __m128 flip = _mm_castsi128_ps(_mm_setr_epi32(0, INT32_MIN, 0, INT32_MIN));
  for (std::size_t i = 0; i + 1 < k; ++i) {
    const float hx = e[i].x1;
    if (!(e[i + 1].x0 <= hx)) continue;
    const __m128 pu = _mm_loadu_ps(&e[i].u0);  // (u0, u1, v0, v1)
    const __m128 bound = _mm_xor_ps(_mm_shuffle_ps(pu, pu, _MM_SHUFFLE(2, 3, 0, 1)), flip);
    for (std::size_t j = i + 1; j < k && e[j].x0 <= hx; ++j) {
      const __m128 q = _mm_xor_ps(_mm_loadu_ps(&e[j].u0), flip);
      if (_mm_movemask_ps(_mm_cmple_ps(q, bound)) == 0xF) report(e[i], e[j]);
    }
  }
#else
  for (std::size_t i = 0; i < k; ++i) {
    const float hx = e[i].x1;
    for (std::size_t j = i + 1; j < k && e[j].x0 <= hx; ++j) test(e[i], e[j]);
  }
#endif
}

}  // namespace batchcol::broadphase
