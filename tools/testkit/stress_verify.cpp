// Brute-force check of the scene's candidate pairs (see stress_verify.hpp).
#include "testkit/stress_verify.hpp"

#include "testkit/portable_random.hpp"

#include "broadphase/brute_force.hpp"
#include "scene_hooks.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <unordered_map>
#include <utility>
#include <vector>

namespace batchcol::testkit {
namespace {

// Objects expected inside the sub-volume: brute force over them costs ~n^2 / 2 box tests.
constexpr double kSubVolumeObjects = 5000.0;

using Key = std::pair<std::uint32_t, std::uint32_t>;  // object slots, low first

Key key_of(ObjectHandle a, ObjectHandle b) { return a.slot < b.slot ? Key{a.slot, b.slot} : Key{b.slot, a.slot}; }

}  // namespace

Verification verify_candidates(const Scene& scene, const SceneResults& results, std::uint64_t seed) {
  std::vector<Aabb> boxes;
  std::vector<ObjectHandle> objects;
  detail::SceneHooks::last_aabbs(scene, boxes, objects);
  Verification v;
  std::vector<std::uint32_t> subset;  // indices into boxes
  if (boxes.size() <= kWholeSceneLimit) {
    v.scope = "whole scene";
    for (std::uint32_t i = 0; i < boxes.size(); ++i) subset.push_back(i);
  } else {
    v.scope = "sub-volume";
    Eigen::Vector3d lo = boxes[0].min, hi = boxes[0].max;
    for (const Aabb& b : boxes) lo = lo.cwiseMin(b.min), hi = hi.cwiseMax(b.max);
    const double side = std::cbrt((hi - lo).prod() * kSubVolumeObjects / static_cast<double>(boxes.size()));
    PortableRandom rng(seed);
    const Aabb& around = boxes[rng.index(boxes.size())];  // centred on an object: never empty, even in clusters
    const Eigen::Vector3d centre = 0.5 * (around.min + around.max);
    const Eigen::Vector3d vlo = centre.array() - 0.5 * side, vhi = centre.array() + 0.5 * side;
    for (std::uint32_t i = 0; i < boxes.size(); ++i)
      if ((boxes[i].min.array() >= vlo.array()).all() && (boxes[i].max.array() <= vhi.array()).all())
        subset.push_back(i);
  }
  v.objects = subset.size();
  std::vector<Aabb> chosen;
  std::unordered_map<std::uint32_t, std::uint32_t> slot_to_subset;
  for (std::uint32_t k = 0; k < subset.size(); ++k) {
    chosen.push_back(boxes[subset[k]]);
    slot_to_subset[objects[subset[k]].slot] = k;
  }
  broadphase::AabbSoa soa;
  soa.assign(chosen);  // float boxes widened to double and back: exact
  std::vector<Key> want;
  for (const broadphase::CandidatePair& p : broadphase::brute_force_pairs(soa))
    want.push_back(key_of(objects[subset[p.a]], objects[subset[p.b]]));
  std::vector<Key> have;
  for (std::size_t k = 0; k < results.candidate_count(); ++k)
    if (slot_to_subset.count(results.object_a[k].slot) && slot_to_subset.count(results.object_b[k].slot))
      have.push_back(key_of(results.object_a[k], results.object_b[k]));
  std::sort(want.begin(), want.end());
  std::sort(have.begin(), have.end());
  std::vector<Key> diff;
  std::set_difference(want.begin(), want.end(), have.begin(), have.end(), std::back_inserter(diff));
  v.missing = diff.size();
  diff.clear();
  std::set_difference(have.begin(), have.end(), want.begin(), want.end(), std::back_inserter(diff));
  v.extra = diff.size();
  v.pairs = want.size();
  v.equal = v.missing == 0 && v.extra == 0 && have.size() == want.size();
  return v;
}

}  // namespace batchcol::testkit
