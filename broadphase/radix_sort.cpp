// Parallel LSD radix sort. References: P. Terdiman, "Radix sort revisited" (2000) for float keys and skipping
// passes whose digit is constant; the parallel scheme is the classic per-chunk histogram, exclusive scan over
// (digit, chunk), and stable scatter: chunk c writes digit d to the slots after all smaller digits and after the
// same digit of chunks < c, so the result equals a sequential stable sort.
#include "broadphase/radix_sort.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <utility>

namespace batchcol::broadphase {
namespace {

constexpr int kRadix = 256;
// Chunks of at least this many words: below it the per-chunk histogram (256 counters) dominates the work.
constexpr std::size_t kMinChunk = 16384;
// At most this many chunks: enough to balance 2..64 threads, independent of the actual thread count.
constexpr std::size_t kMaxChunks = 64;

using Histogram = std::array<std::uint32_t, kRadix>;

}  // namespace

std::vector<int> digit_shifts(int bit_begin, int bit_end) {
  std::vector<int> s;
  for (int b = bit_begin; b < bit_end; b += 8) s.push_back(b);
  return s;
}

void radix_sort(std::uint64_t* data, std::uint64_t* scratch, std::size_t n, const std::vector<int>& shifts) {
  std::vector<Histogram> hist;
  radix_sort(data, scratch, n, shifts, hist);
}

void radix_sort(std::uint64_t* data, std::uint64_t* scratch, std::size_t n, const std::vector<int>& shifts,
                std::vector<Histogram>& hist) {
  if (n < 2 || shifts.empty()) return;
  if (n <= 64) {  // tiny inputs: a stable comparison sort on the same digits is cheaper than 256-bucket passes
    std::uint64_t mask = 0;
    for (int s : shifts) mask |= std::uint64_t{0xff} << s;
    std::stable_sort(data, data + n, [mask](std::uint64_t a, std::uint64_t b) { return (a & mask) < (b & mask); });
    return;
  }
  const std::size_t chunks = std::clamp<std::size_t>(n / kMinChunk, 1, kMaxChunks);
  const std::size_t chunk_size = (n + chunks - 1) / chunks;
  if (hist.size() < chunks) hist.resize(chunks);
  std::uint64_t* src = data;
  std::uint64_t* dst = scratch;
  for (int shift : shifts) {
    tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
      Histogram& h = hist[c];
      h.fill(0);
      const std::size_t end = std::min(n, (c + 1) * chunk_size);
      for (std::size_t i = c * chunk_size; i < end; ++i) ++h[(src[i] >> shift) & 0xff];
    });
    // Exclusive scan in (digit, chunk) order; skip the pass when one digit holds every word.
    std::uint32_t running = 0;
    bool trivial = false;
    for (int d = 0; d < kRadix; ++d) {
      std::uint32_t total = 0;
      for (std::size_t c = 0; c < chunks; ++c) total += hist[c][d];
      if (total == n) { trivial = true; break; }
      for (std::size_t c = 0; c < chunks; ++c) {
        const std::uint32_t count = hist[c][d];
        hist[c][d] = running;
        running += count;
      }
    }
    if (trivial) continue;
    tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
      Histogram& offset = hist[c];
      const std::size_t end = std::min(n, (c + 1) * chunk_size);
      for (std::size_t i = c * chunk_size; i < end; ++i) dst[offset[(src[i] >> shift) & 0xff]++] = src[i];
    });
    std::swap(src, dst);
  }
  if (src != data) std::memcpy(data, src, n * sizeof(std::uint64_t));
}

}  // namespace batchcol::broadphase
