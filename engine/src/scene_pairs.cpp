// Candidate pairs of a scene beyond the sweep-and-prune: halfspaces (infinite boxes, never put in the sweep) against
// every object, and the PairBatch handed to the narrow phase.
#include "scene_state.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace batchcol {
namespace {

// Objects per halfspace-test chunk: a fixed split (independent of the thread count) keeps the output order fixed.
constexpr std::size_t kHalfspaceChunk = 16384;
// Relative slack of the box-halfspace test, computed in double on float boxes: the rounding of the dot products is
// a few 1e-16 of the magnitudes involved; 1e-12 keeps the test conservative (the narrow phase decides).
constexpr double kHalfspaceSlack = 1e-12;

WorldHalfspace world_halfspace(const Shape& s, const Pose& pose) {
  WorldHalfspace h;
  h.normal = pose.rotation * s.size;
  h.offset = s.offset + h.normal.dot(pose.translation) + s.inflation;
  return h;
}

}  // namespace

void Scene::State::find_halfspace_pairs() {
  halfspace_pairs.clear();
  const std::size_t n = finite.size(), hs = halfspaces.size();
  if (hs == 0) return;
  world_halfspaces.clear();
  for (const HalfspaceObject& h : halfspaces) world_halfspaces.push_back(world_halfspace((*shapes)[h.shape], h.pose));
  const std::vector<WorldHalfspace>& world = world_halfspaces;
  const std::size_t chunks = (n + kHalfspaceChunk - 1) / kHalfspaceChunk;
  if (halfspace_chunks.size() < chunks) halfspace_chunks.resize(chunks);
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
    std::vector<ScenePair>& out = halfspace_chunks[c];
    out.clear();
    const std::size_t end = std::min(n, (c + 1) * kHalfspaceChunk);
    for (std::size_t k = 0; k < hs; ++k) {
      const WorldHalfspace& h = world[k];
      const CollisionFilter& hf = halfspaces[k].filter;
      for (std::size_t i = c * kHalfspaceChunk; i < end; ++i) {
        // Lowest value of normal . x over the box: the corner picked by the signs of the normal.
        double low = 0.0, scale = std::fabs(h.offset);
        for (int a = 0; a < 3; ++a) {
          const double lo = boxes.min(a)[i], hi = boxes.max(a)[i];
          low += h.normal[a] * (h.normal[a] >= 0.0 ? lo : hi);
          scale += std::fabs(h.normal[a]) * std::fmax(std::fabs(lo), std::fabs(hi));
        }
        if (low > h.offset + kHalfspaceSlack * scale) continue;
        if (!filters_pass(finite.get_filter(i), hf)) continue;
        out.push_back({static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(k) | kHalfspaceBit});
      }
    }
  });
  for (std::size_t c = 0; c < chunks; ++c)
    halfspace_pairs.insert(halfspace_pairs.end(), halfspace_chunks[c].begin(), halfspace_chunks[c].end());
  // Two halfspaces intersect unless they are opposite and apart: every pair is a candidate.
  for (std::size_t a = 0; a < hs; ++a)
    for (std::size_t b = a + 1; b < hs; ++b)
      if (filters_pass(halfspaces[a].filter, halfspaces[b].filter))
        halfspace_pairs.push_back({static_cast<std::uint32_t>(a) | kHalfspaceBit,
                                   static_cast<std::uint32_t>(b) | kHalfspaceBit});
}

void Scene::State::fill_batch(SceneResults& results) {
  const std::size_t ns = sap_pairs.size(), total = ns + halfspace_pairs.size();
  batch.shape_a.resize(total), batch.shape_b.resize(total);
  batch.translation_a.resize(total), batch.translation_b.resize(total);
  batch.rotation_a.resize(total), batch.rotation_b.resize(total);
  batch.warm_start.x.clear(), batch.warm_start.y.clear(), batch.warm_start.z.clear();
  results.object_a.resize(total), results.object_b.resize(total);
  const FiniteObjects& o = finite;
  // Writes object `id` (finite index or halfspace index | kHalfspaceBit) as side a or b of pair k.
  const auto put = [&](std::size_t k, std::uint32_t id, std::vector<std::uint32_t>& shape, Vec3Array& t,
                       QuatArray& q, std::vector<ObjectHandle>& handle) {
    if (id & kHalfspaceBit) {
      const HalfspaceObject& h = halfspaces[id & ~kHalfspaceBit];
      shape[k] = h.shape;
      t.set(k, h.pose.translation);
      q.set(k, h.pose.rotation);
      handle[k] = handle_of(h.slot);
      return;
    }
    const PoseRecord& p = pose_records[id];
    shape[k] = o.shape[id];
    t.x[k] = p.tx, t.y[k] = p.ty, t.z[k] = p.tz;
    q.w[k] = p.qw, q.x[k] = p.qx, q.y[k] = p.qy, q.z[k] = p.qz;
    handle[k] = handle_of(o.slot[id]);
  };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, total, 8192), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k < r.end(); ++k) {
      const ScenePair p = k < ns ? ScenePair{sap_pairs[k].a, sap_pairs[k].b} : halfspace_pairs[k - ns];
      put(k, p.a, batch.shape_a, batch.translation_a, batch.rotation_a, results.object_a);
      put(k, p.b, batch.shape_b, batch.translation_b, batch.rotation_b, results.object_b);
    }
  });
}

}  // namespace batchcol
