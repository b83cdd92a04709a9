// Parallel least-significant-digit radix sort of 64-bit words on chosen 8-bit digits (TBB).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace batchcol::broadphase {

/// Stable sort of data[0, n) by the 8-bit digits starting at the given bit shifts, least significant first (e.g.
/// {32, 40, 48, 56} sorts by the high 32 bits and keeps the order of equal keys). `scratch` has room for n words.
/// A pass whose digit is the same for every word is skipped. The result is in `data`. The work is split into a
/// fixed number of chunks that does not depend on the thread count, and a stable sort has one answer anyway.
void radix_sort(std::uint64_t* data, std::uint64_t* scratch, std::size_t n, const std::vector<int>& shifts);
/// The same with caller-owned histograms (resized as needed), so that repeated sorts allocate nothing.
void radix_sort(std::uint64_t* data, std::uint64_t* scratch, std::size_t n, const std::vector<int>& shifts,
                std::vector<std::array<std::uint32_t, 256>>& histograms);

/// The shifts that sort by bits [bit_begin, bit_end), 8 at a time.
std::vector<int> digit_shifts(int bit_begin, int bit_end);

}  // namespace batchcol::broadphase
