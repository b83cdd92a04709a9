// O(n^2) reference broad phase for tests: every pair (a < b) whose boxes overlap or touch on all three axes
// (lo1 <= hi2 and lo2 <= hi1) and passes the filter, sorted lexicographically -- the same contract as
// SweepAndPrune, so the two outputs compare with ==.
#pragma once

#include "broadphase/aabb_soa.hpp"
#include "broadphase/pairs.hpp"

#include <vector>

namespace batchcol::broadphase {

/// Validates like SweepAndPrune (InputError naming the object) and returns the pairs.
std::vector<CandidatePair> brute_force_pairs(const AabbSoa& boxes, const FilterSoa& filter = {});

}  // namespace batchcol::broadphase
