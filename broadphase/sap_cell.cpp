// Sorting one grid cell's records by their minimum on the sweep axis (see sap_cell.hpp).
// Reference for the radix path: P. Terdiman, "Radix sort revisited" (2000): float keys sorted as integers
// (float_key.hpp), passes whose digit is constant skipped.
#include "broadphase/sap_cell.hpp"

#include "broadphase/float_key.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <utility>

namespace batchcol::broadphase {
namespace {

// Cells up to kInsertionSortMax records are insertion-sorted from any order; up to kInPlaceSortMax, std::sort (in
// place: no scratch, which kept per task would cost more memory than the cells); larger ones (degenerate scenes: the
// grid could not split them) radix-sorted with per-task scratch. A nearly sorted cell (update()) tries insertion
// sort first.
constexpr std::size_t kInsertionSortMax = 48;
constexpr std::size_t kInPlaceSortMax = 4096;
// A nearly sorted cell (update()) is insertion-sorted while the records moved stay below this many per record plus
// a constant; past that budget the order was not "nearly sorted" and the radix sort finishes the job.
constexpr std::size_t kMovesPerRecord = 4;
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

void radix_sort_cell(CellRecord* e, std::size_t k, std::vector<std::uint64_t>& w, std::vector<std::uint64_t>& tmp,
                     std::vector<CellRecord>& buf) {
  if (w.size() < k) w.resize(k), tmp.resize(k), buf.resize(k);
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

}  // namespace

void sort_cell(CellRecord* e, std::size_t k, bool nearly_sorted, std::vector<std::uint64_t>& words,
               std::vector<std::uint64_t>& tmp, std::vector<CellRecord>& buf) {
  if (k < 2) return;
  if (k <= kInsertionSortMax) {
    insertion_sort(e, k, static_cast<std::size_t>(-1));
    return;
  }
  // Nearly sorted: the previous frame's order (update()), or objects numbered in spatial order (Scene does that).
  // Few descents predict few insertion moves; the move budget bounds the cost when the prediction fails.
  std::size_t descents = 0;
  for (std::size_t i = 1; i < k; ++i) descents += e[i].x0 < e[i - 1].x0 ? 1 : 0;
  if ((nearly_sorted || descents * kDescentFraction <= k) &&
      insertion_sort(e, k, kMovesPerRecord * k + kMovesSlack))
    return;
  if (k <= kInPlaceSortMax) {
    std::sort(e, e + k, [](const CellRecord& a, const CellRecord& b) { return a.x0 < b.x0; });
    return;
  }
  radix_sort_cell(e, k, words, tmp, buf);
}

}  // namespace batchcol::broadphase
