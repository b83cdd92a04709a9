// Broad phases of the peers on the same boxes as ours: Bullet's btDbvtBroadphase and FCL's
// DynamicAABBTreeCollisionManager and SaPCollisionManager (each when found at configure time). All three are
// single-threaded libraries: they run on the calling thread.
//
// "rebuild" = build the structure from scratch over all boxes and report all overlapping pairs;
// "update"  = move every box to its position in the second frame and report all pairs again.
// Each is timed `runs` times (fresh structure per rebuild run; updates alternate between the two frames) and the
// median is reported.
#pragma once

#include <batchcol/shapes.hpp>

#include <cstddef>
#include <string>
#include <vector>

namespace batchcol::peers {

struct BroadphasePeerTiming {
  std::string name;             // "Bullet btDbvtBroadphase", "FCL DynamicAABBTree", "FCL SaP"
  double rebuild_ms = 0, update_ms = 0;
  std::size_t rebuild_pairs = 0;  // pairs reported by the rebuild (exact AABB overlaps, touching included)
  std::size_t update_pairs = 0;   // pairs reported after the update (Bullet: fattened boxes, a superset)
};

/// `frame` and `moved` hold the same objects (same order) in two positions. `notes` receives missing or skipped peers
/// (FCL SaP is skipped above 200,000 objects).
std::vector<BroadphasePeerTiming> time_broadphase_peers(const std::vector<Aabb>& frame, const std::vector<Aabb>& moved,
                                                        int runs, std::vector<std::string>& notes);

}  // namespace batchcol::peers
