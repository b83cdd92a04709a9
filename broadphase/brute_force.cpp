// The brute-force reference: a plain double loop, deliberately free of any trick the sweep-and-prune uses (no keys,
// no sort, no grid), so that agreement between the two is evidence.
#include "broadphase/brute_force.hpp"

namespace batchcol::broadphase {

std::vector<CandidatePair> brute_force_pairs(const AabbSoa& b, const FilterSoa& filter) {
  validate_aabbs(b);
  validate_filter(filter, b.size());
  std::vector<CandidatePair> pairs;
  const auto n = static_cast<std::uint32_t>(b.size());
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::uint32_t j = i + 1; j < n; ++j) {
      bool overlap = true;
      for (int a = 0; a < 3 && overlap; ++a) overlap = b.min(a)[i] <= b.max(a)[j] && b.min(a)[j] <= b.max(a)[i];
      if (overlap && pair_passes(filter, i, j)) pairs.push_back({i, j});
    }
  return pairs;
}

}  // namespace batchcol::broadphase
