// Candidate pairs and per-object collision filters shared by the sweep-and-prune and the brute-force reference.
#pragma once

#include <cstdint>
#include <vector>

namespace batchcol::broadphase {

/// Two object indices with a < b. Every producer in this folder emits pairs sorted lexicographically by (a, b), so
/// outputs compare with == whatever the algorithm, the sweep axis or the thread count.
struct CandidatePair {
  std::uint32_t a = 0, b = 0;
  friend bool operator==(const CandidatePair& x, const CandidatePair& y) { return x.a == y.a && x.b == y.b; }
  friend bool operator!=(const CandidatePair& x, const CandidatePair& y) { return !(x == y); }
  friend bool operator<(const CandidatePair& x, const CandidatePair& y) {
    return x.a < y.a || (x.a == y.a && x.b < y.b);
  }
};

/// Optional per-object filter, Bullet-style. Empty vectors mean "no filter": every pair passes and no body
/// exclusion applies. When present, each vector has one entry per object.
///  - a pair passes iff (group[a] & mask[b]) != 0 and (group[b] & mask[a]) != 0;
///  - a pair of two objects with the same body id >= 0 is excluded (parts of one rigid body); -1 = no body.
struct FilterSoa {
  std::vector<std::uint32_t> group, mask;
  std::vector<std::int32_t> body;

  bool has_groups() const { return !group.empty(); }
  bool has_bodies() const { return !body.empty(); }
  void clear() { group.clear(); mask.clear(); body.clear(); }
};

/// Throws InputError unless the filter is empty or sized for `objects` (groups and masks come together).
void validate_filter(const FilterSoa& filter, std::size_t objects);

/// The filter rule above; `filter` must be validated.
inline bool pair_passes(const FilterSoa& filter, std::uint32_t a, std::uint32_t b) {
  if (filter.has_groups() &&
      ((filter.group[a] & filter.mask[b]) == 0 || (filter.group[b] & filter.mask[a]) == 0))
    return false;
  if (filter.has_bodies() && filter.body[a] >= 0 && filter.body[a] == filter.body[b]) return false;
  return true;
}

}  // namespace batchcol::broadphase
