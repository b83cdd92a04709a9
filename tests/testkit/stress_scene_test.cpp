// The stress scene and its brute-force check (tools/testkit/stress_scene.hpp, stress_verify.hpp), in-process: the
// scene's candidates equal brute force for every distribution, before and after moving, and the check does fail
// when a candidate is missing or extra.
#include "testkit/stress_scene.hpp"
#include "testkit/stress_verify.hpp"

#include "scene_hooks.hpp"

#include <gtest/gtest.h>

namespace batchcol::testkit {
namespace {

QueryOptions broad_only() {
  QueryOptions o;
  o.level = QueryLevel::boolean;
  o.threads = 2;
  return o;
}

TEST(StressScene, CandidatesEqualBruteForceForEveryDistribution) {
  for (const char* name : {"uniform", "clustered", "layered"}) {
    StressSceneSpec spec;
    spec.objects = 3000;
    spec.distribution = parse_distribution(name);
    spec.seed = 4;
    StressScene s = make_stress_scene(spec);
    ASSERT_EQ(s.handles.size(), 3000u);
    ASSERT_EQ(s.scene->size(), 3000u);
    SceneResults r;
    for (int step = 0; step < 3; ++step) {
      s.scene->collide(broad_only(), r);
      const Verification v = verify_candidates(*s.scene, r, 7);
      EXPECT_TRUE(v.equal) << name << " step " << step << ": missing " << v.missing << ", extra " << v.extra;
      EXPECT_EQ(v.scope, "whole scene");
      EXPECT_EQ(v.objects, 3000u);
      EXPECT_GT(v.pairs, 300u) << name;  // the density is about 0.4 overlaps per object: the check is not empty
      step_stress_scene(s);
    }
  }
}

TEST(StressScene, VerificationDetectsAMissingAndAnExtraCandidate) {
  StressSceneSpec spec;
  spec.objects = 2000;
  StressScene s = make_stress_scene(spec);
  SceneResults r;
  s.scene->collide(broad_only(), r);
  ASSERT_GT(r.candidate_count(), 2u);
  SceneResults dropped = r;  // one candidate removed
  dropped.object_a.pop_back();
  dropped.object_b.pop_back();
  const Verification missing = verify_candidates(*s.scene, dropped, 7);
  EXPECT_FALSE(missing.equal);
  EXPECT_EQ(missing.missing, 1u);
  EXPECT_EQ(missing.extra, 0u);
  // An extra candidate: two objects whose boxes are far apart (the first and the farthest in x are not paired).
  SceneResults extra = r;
  std::vector<Aabb> boxes;
  std::vector<ObjectHandle> objects;
  detail::SceneHooks::last_aabbs(*s.scene, boxes, objects);
  std::size_t far = 0;
  for (std::size_t i = 1; i < boxes.size(); ++i)
    if ((boxes[i].min - boxes[0].min).norm() > (boxes[far].min - boxes[0].min).norm()) far = i;
  extra.object_a.push_back(objects[0]);
  extra.object_b.push_back(objects[far]);
  const Verification more = verify_candidates(*s.scene, extra, 7);
  EXPECT_FALSE(more.equal);
  EXPECT_EQ(more.extra, 1u);
  EXPECT_EQ(more.missing, 0u);
}

TEST(StressScene, SameSeedSameSceneAndBadDistributionThrows) {
  StressSceneSpec spec;
  spec.objects = 500;
  spec.distribution = Distribution::clustered;
  const StressScene a = make_stress_scene(spec), b = make_stress_scene(spec);
  ASSERT_EQ(a.poses.size(), b.poses.size());
  for (std::size_t i = 0; i < a.poses.size(); ++i) {
    ASSERT_EQ(a.poses[i].translation, b.poses[i].translation);
    ASSERT_EQ(a.poses[i].rotation.coeffs(), b.poses[i].rotation.coeffs());
  }
  EXPECT_THROW(parse_distribution("gaussian"), InputError);
}

}  // namespace
}  // namespace batchcol::testkit
