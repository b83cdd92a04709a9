// Scene API: the candidate pairs and narrow-phase results of Scene::collide() equal an all-pairs narrow phase on
// small scenes (every shape type, filters, halfspaces, add/remove/update sequences), the world boxes contain the
// shapes, results do not depend on the thread count, and warm frames reuse the scene's buffers.
#include "support/generators.hpp"

#include "batchcol/scene.hpp"
#include "scene_hooks.hpp"  // engine/src: last_aabbs, buffer_reallocations

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <utility>
#include <vector>

namespace batchcol {
namespace {

using testing::Rng;
using testing::uniform;
using Key = std::pair<ObjectHandle, ObjectHandle>;

Key key_of(ObjectHandle a, ObjectHandle b) { return a < b ? Key{a, b} : Key{b, a}; }

struct Object {
  ObjectHandle handle;
  std::uint32_t shape;
  Pose pose;
  CollisionFilter filter;
};

std::vector<Object> objects_of(const Scene& scene, const std::vector<ObjectHandle>& handles) {
  std::vector<Object> out;
  for (ObjectHandle h : handles)
    if (scene.contains(h)) out.push_back({h, scene.shape(h), scene.pose(h), scene.filter(h)});
  return out;
}

bool passes(const CollisionFilter& a, const CollisionFilter& b) {
  return (a.group & b.mask) && (b.group & a.mask) && !(a.body >= 0 && a.body == b.body);
}

struct Reference {
  std::map<Key, std::size_t> index;  // pair -> row of `results` (row computed with a = key.first)
  PairResults results;
};

// The all-pairs narrow phase: every pair of objects that passes the filters, no broad phase.
Reference all_pairs(const ShapeTable& shapes, const std::vector<Object>& objects, const QueryOptions& options) {
  Reference ref;
  PairBatch batch;
  for (std::size_t i = 0; i < objects.size(); ++i)
    for (std::size_t j = i + 1; j < objects.size(); ++j) {
      if (!passes(objects[i].filter, objects[j].filter)) continue;
      const Object *a = &objects[i], *b = &objects[j];
      if (b->handle < a->handle) std::swap(a, b);
      ref.index[{a->handle, b->handle}] = batch.add(a->shape, a->pose, b->shape, b->pose);
    }
  collide(shapes, batch, options, ref.results);
  return ref;
}

std::vector<Key> colliding_keys(const SceneResults& r) {
  std::vector<Key> keys;
  for (std::uint32_t k : r.colliding) keys.push_back(key_of(r.object_a[k], r.object_b[k]));
  std::sort(keys.begin(), keys.end());
  return keys;
}

// Scene results equal the all-pairs reference: same colliding pairs; every reference-colliding pair is a
// candidate; results of candidates oriented like the reference are bitwise equal, the others agree to the tolerance.
void expect_matches_all_pairs(Scene& scene, const std::vector<ObjectHandle>& handles, const QueryOptions& options) {
  SceneResults got;
  scene.collide(options, got);
  const Reference ref = all_pairs(scene.shapes(), objects_of(scene, handles), options);
  std::vector<Key> want;
  for (const auto& [key, row] : ref.index)
    if (ref.results.collide[row]) want.push_back(key);
  const std::vector<Key> have = colliding_keys(got);
  ASSERT_EQ(have.size(), want.size()) << "colliding pairs: scene " << have.size() << ", all pairs " << want.size();
  EXPECT_TRUE(have == want);
  for (std::size_t k = 0; k < got.candidate_count(); ++k) {
    const Key key = key_of(got.object_a[k], got.object_b[k]);
    const auto it = ref.index.find(key);
    ASSERT_NE(it, ref.index.end()) << "candidate pair not allowed by the filters";
    const std::size_t row = it->second;
    EXPECT_EQ(got.pairs.collide[k], ref.results.collide[row]);
    ASSERT_EQ(got.pairs.distance.empty(), ref.results.distance.empty());
    if (got.pairs.distance.empty()) {  // boolean: no distance array in either
      EXPECT_LT(options.level, QueryLevel::distance);
      continue;
    }
    const double d = got.pairs.distance[k], e = ref.results.distance[row];
    if (got.object_a[k] == key.first) {
      EXPECT_TRUE(d == e || (std::isnan(d) && std::isnan(e))) << d << " vs " << e;
    } else if (!std::isnan(e)) {
      // Swapped pair: each distance is certified to options.tolerance, not bitwise equal.
      EXPECT_NEAR(d, e, 2 * options.tolerance);
    }
  }
}

std::shared_ptr<ShapeTable> mixed_shapes(Rng& rng, int per_type, bool with_halfspace = false) {
  auto shapes = std::make_shared<ShapeTable>();
  for (ShapeType type : testing::bounded_shape_types())
    for (int k = 0; k < per_type; ++k) {
      Shape s = testing::random_shape(rng, type, 0.05, 0.3);
      if (k % 2 == 1) s = s.inflated(0.01);
      shapes->add(s);
    }
  if (with_halfspace) {
    shapes->add(Shape::halfspace({0, 0, 1}, 0.0));
    shapes->add(Shape::halfspace(Eigen::Vector3d(1, 0, 1).normalized(), 0.5).inflated(0.02));
  }
  return shapes;
}

Pose random_pose(Rng& rng, double side) {
  return {Eigen::Vector3d(uniform(rng, 0, side), uniform(rng, 0, side), uniform(rng, 0, side)),
          testing::random_rotation(rng)};
}

std::vector<ObjectHandle> fill(Scene& scene, Rng& rng, std::size_t n, double side, std::uint32_t bounded_shapes) {
  std::vector<ObjectHandle> handles;
  for (std::size_t i = 0; i < n; ++i)
    handles.push_back(scene.add(static_cast<std::uint32_t>(rng() % bounded_shapes), random_pose(rng, side)));
  return handles;
}

QueryOptions options_at(QueryLevel level, double margin = 0.0, int threads = 2) {
  QueryOptions o;
  o.level = level;
  o.margin = margin;
  o.threads = threads;
  return o;
}

TEST(Scene, EqualsAllPairsNarrowPhaseOnMixedScenes) {
  Rng rng(11);
  auto shapes = mixed_shapes(rng, 3);
  const auto bounded = static_cast<std::uint32_t>(shapes->size());
  for (QueryLevel level : {QueryLevel::boolean, QueryLevel::witness, QueryLevel::penetration})
    for (double margin : {0.0, 0.05}) {
      SCOPED_TRACE(::testing::Message() << to_string(level) << " margin " << margin);
      Scene scene(shapes);
      const auto handles = fill(scene, rng, 400, 3.0, bounded);
      expect_matches_all_pairs(scene, handles, options_at(level, margin));
    }
}

TEST(Scene, WorldBoxesContainTheShapesAndAreTightForPrimitives) {
  Rng rng(12);
  auto shapes = mixed_shapes(rng, 4);
  Scene scene(shapes);
  std::vector<ObjectHandle> handles = fill(scene, rng, 500, 2.0, static_cast<std::uint32_t>(shapes->size()));
  const double margin = 0.03;
  SceneResults results;
  scene.collide(options_at(QueryLevel::boolean, margin), results);
  std::vector<Aabb> boxes;
  std::vector<ObjectHandle> objects;
  detail::SceneHooks::last_aabbs(scene, boxes, objects);
  ASSERT_EQ(boxes.size(), handles.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const Shape& shape = (*shapes)[scene.shape(objects[i])];
    const Pose pose = scene.pose(objects[i]);
    const Aabb exact = compute_aabb(shape, pose.rotation, pose.translation);  // support-function box
    for (int a = 0; a < 3; ++a) {
      EXPECT_LE(boxes[i].min[a], exact.min[a] - margin) << to_string(shape.type);
      EXPECT_GE(boxes[i].max[a], exact.max[a] + margin) << to_string(shape.type);
      if (shape.type == ShapeType::convex) continue;  // hulls: rotated local box, looser by design
      // Tight: only the outward rounding (~2 float ulps of the coordinates, <= 2 m here) plus support rounding.
      EXPECT_NEAR(boxes[i].min[a], exact.min[a] - margin, 2e-6) << to_string(shape.type);
      EXPECT_NEAR(boxes[i].max[a], exact.max[a] + margin, 2e-6) << to_string(shape.type);
    }
  }
}

TEST(Scene, AddRemoveUpdateSequences) {
  Rng rng(13);
  auto shapes = mixed_shapes(rng, 2);
  const auto bounded = static_cast<std::uint32_t>(shapes->size());
  Scene scene(shapes);
  std::vector<ObjectHandle> live = fill(scene, rng, 150, 2.0, bounded);
  std::vector<ObjectHandle> removed;
  const QueryOptions options = options_at(QueryLevel::distance, 0.02);
  for (int round = 0; round < 12; ++round) {
    SCOPED_TRACE(::testing::Message() << "round " << round);
    const int op = round % 3;
    if (op == 0) {  // remove a third, add some
      for (int k = 0; k < 40 && !live.empty(); ++k) {
        const std::size_t i = rng() % live.size();
        scene.remove(live[i]);
        removed.push_back(live[i]);
        live.erase(live.begin() + static_cast<std::ptrdiff_t>(i));
      }
      for (ObjectHandle h : fill(scene, rng, 30, 2.0, bounded)) live.push_back(h);
    } else {  // move everything a little (incremental broad phase), some far
      for (ObjectHandle h : live) {
        Pose p = scene.pose(h);
        p.translation += Eigen::Vector3d(uniform(rng, -0.05, 0.05), uniform(rng, -0.05, 0.05), uniform(rng, -0.05, 0.05));
        if (rng() % 10 == 0) p = random_pose(rng, 2.0);
        scene.set_pose(h, p);
      }
    }
    EXPECT_EQ(scene.size(), live.size());
    for (ObjectHandle h : removed) EXPECT_FALSE(scene.contains(h));
    for (ObjectHandle h : live) EXPECT_TRUE(scene.contains(h));
    expect_matches_all_pairs(scene, live, options);
  }
  // Stale handles are errors, even once their slot is reused.
  ASSERT_FALSE(removed.empty());
  EXPECT_THROW(scene.remove(removed.front()), InputError);
  EXPECT_THROW(scene.set_pose(removed.front(), Pose::identity()), InputError);
  EXPECT_THROW(scene.pose(removed.front()), InputError);
  EXPECT_THROW(scene.remove(ObjectHandle{}), InputError);
}

TEST(Scene, FiltersGroupsMasksAndBodies) {
  Rng rng(14);
  auto shapes = mixed_shapes(rng, 2);
  const auto bounded = static_cast<std::uint32_t>(shapes->size());
  Scene scene(shapes);
  std::vector<ObjectHandle> handles;
  for (int i = 0; i < 300; ++i) {
    CollisionFilter f;
    f.group = 1u << (rng() % 3);
    f.mask = static_cast<std::uint32_t>(rng() % 8) | 1u;
    f.body = rng() % 3 == 0 ? -1 : static_cast<std::int32_t>(rng() % 40);
    handles.push_back(scene.add(static_cast<std::uint32_t>(rng() % bounded), random_pose(rng, 1.5), f));
  }
  expect_matches_all_pairs(scene, handles, options_at(QueryLevel::boolean, 0.01));
  // Changing filters takes effect on the next frame.
  for (std::size_t i = 0; i < handles.size(); i += 2) scene.set_filter(handles[i], CollisionFilter{});
  expect_matches_all_pairs(scene, handles, options_at(QueryLevel::boolean, 0.01));
  // An object whose mask excludes everything never appears.
  scene.set_filter(handles[1], CollisionFilter{1, 0, -1});
  SceneResults r;
  scene.collide(options_at(QueryLevel::boolean), r);
  for (std::size_t k = 0; k < r.candidate_count(); ++k) {
    EXPECT_NE(r.object_a[k], handles[1]);
    EXPECT_NE(r.object_b[k], handles[1]);
  }
}

TEST(Scene, HalfspacesAgainstAllObjects) {
  Rng rng(15);
  auto shapes = mixed_shapes(rng, 2, true);
  const auto bounded = static_cast<std::uint32_t>(shapes->size() - 2);
  Scene scene(shapes);
  std::vector<ObjectHandle> handles;
  for (int i = 0; i < 250; ++i) {  // objects around the ground plane z = 0
    Pose p = random_pose(rng, 3.0);
    p.translation.z() = uniform(rng, -0.5, 0.8);
    handles.push_back(scene.add(static_cast<std::uint32_t>(rng() % bounded), p));
  }
  const ObjectHandle ground = scene.add(bounded, Pose::identity());
  const ObjectHandle slope = scene.add(bounded + 1, Pose{{0.3, 0, 0}, testing::random_rotation(rng)});
  handles.push_back(ground);
  handles.push_back(slope);
  expect_matches_all_pairs(scene, handles, options_at(QueryLevel::witness, 0.01));
  SceneResults r;
  scene.collide(options_at(QueryLevel::boolean, 0.01), r);
  std::size_t ground_pairs = 0;
  for (std::uint32_t k : r.colliding) ground_pairs += (r.object_a[k] == ground || r.object_b[k] == ground) ? 1 : 0;
  EXPECT_GT(ground_pairs, 50u);  // about half the objects reach below z = 0.3
  // Moving and removing a halfspace.
  scene.set_pose(ground, Pose::from_translation({0, 0, -10}));
  expect_matches_all_pairs(scene, handles, options_at(QueryLevel::boolean));
  scene.remove(slope);
  handles.pop_back();
  expect_matches_all_pairs(scene, handles, options_at(QueryLevel::boolean));
}

TEST(Scene, SameResultsForOneAndTwoThreads) {
  Rng rng(16);
  auto shapes = mixed_shapes(rng, 3, true);
  const auto bounded = static_cast<std::uint32_t>(shapes->size() - 2);
  Scene scene(shapes);
  fill(scene, rng, 3000, 6.0, bounded);
  scene.add(bounded, Pose::from_translation({0, 0, 0.5}));
  SceneResults one, two;
  for (int frame = 0; frame < 2; ++frame) {
    scene.collide(options_at(QueryLevel::witness, 0.01, 1), one);
    scene.collide(options_at(QueryLevel::witness, 0.01, 2), two);
    ASSERT_EQ(one.candidate_count(), two.candidate_count());
    ASSERT_GT(one.colliding_count(), 100u);
    EXPECT_TRUE(one.object_a == two.object_a);
    EXPECT_TRUE(one.object_b == two.object_b);
    EXPECT_TRUE(one.colliding == two.colliding);
    for (std::size_t k = 0; k < one.candidate_count(); ++k) {
      const double a = one.pairs.distance[k], b = two.pairs.distance[k];
      ASSERT_TRUE(a == b || (std::isnan(a) && std::isnan(b))) << k;
      ASSERT_TRUE(one.pairs.normal[k] == two.pairs.normal[k] || std::isnan(a));
    }
  }
}

TEST(Scene, WarmFramesReuseBuffers) {
  Rng rng(17);
  auto shapes = mixed_shapes(rng, 2, true);
  const auto bounded = static_cast<std::uint32_t>(shapes->size() - 2);
  Scene scene(shapes);
  const auto handles = fill(scene, rng, 20000, 12.0, bounded);
  scene.add(bounded, Pose::identity());
  // Two alternating frames: after both were seen once, no buffer needs to grow.
  std::vector<Pose> a, b;
  for (ObjectHandle h : handles) {
    a.push_back(scene.pose(h));
    b.push_back(a.back());
    b.back().translation += Eigen::Vector3d(uniform(rng, -0.02, 0.02), uniform(rng, -0.02, 0.02), 0.01);
  }
  const QueryOptions options = options_at(QueryLevel::witness, 0.01);
  SceneResults r;
  const auto frame = [&](const std::vector<Pose>& poses) {
    for (std::size_t i = 0; i < handles.size(); ++i) scene.set_pose(handles[i], poses[i]);
    scene.collide(options, r);
  };
  frame(a), frame(b), frame(a), frame(b);  // warm-up
  const std::size_t reallocations = detail::SceneHooks::buffer_reallocations(scene);
  const std::size_t bytes = scene.memory_bytes();
  const void* const pointers[] = {r.object_a.data(), r.pairs.distance.data(), r.pairs.normal.x.data(),
                                  r.colliding.data()};
  for (int k = 0; k < 6; ++k) {
    frame(k % 2 ? a : b);
    EXPECT_TRUE(r.incremental);
  }
  EXPECT_GT(r.colliding_count(), 1000u);
  EXPECT_EQ(detail::SceneHooks::buffer_reallocations(scene), reallocations);
  EXPECT_EQ(scene.memory_bytes(), bytes);
  const void* const after[] = {r.object_a.data(), r.pairs.distance.data(), r.pairs.normal.x.data(),
                               r.colliding.data()};
  for (int k = 0; k < 4; ++k) EXPECT_EQ(pointers[k], after[k]) << "results buffer " << k << " was reallocated";
  // The counter does move when a frame needs more room: the check can fail.
  for (std::size_t i = 0; i < handles.size(); ++i) scene.set_pose(handles[i], Pose::from_translation(a[i].translation * 0.5));
  scene.collide(options, r);
  EXPECT_GT(detail::SceneHooks::buffer_reallocations(scene), reallocations);
}

TEST(Scene, RebuildRenumbersObjectsSpatiallyKeepingHandlesPosesAndResults) {
  // The frame that rebuilds the broad phase renumbers the objects internally (spatial order): handles, poses and
  // the pairs must not change, the next frame (no change) must give the same results in the same order, and the
  // world boxes must still belong to their handles.
  Rng rng(19);
  auto shapes = mixed_shapes(rng, 2);
  const auto bounded = static_cast<std::uint32_t>(shapes->size());
  Scene scene(shapes);
  const auto handles = fill(scene, rng, 1200, 6.0, bounded);
  std::vector<Pose> poses;
  for (ObjectHandle h : handles) poses.push_back(scene.pose(h));
  const QueryOptions options = options_at(QueryLevel::witness, 0.01);
  SceneResults first, second;
  scene.collide(options, first);
  scene.collide(options, second);
  ASSERT_GT(first.colliding_count(), 20u);
  EXPECT_FALSE(first.incremental);
  EXPECT_TRUE(second.incremental);
  EXPECT_TRUE(first.object_a == second.object_a);
  EXPECT_TRUE(first.object_b == second.object_b);
  EXPECT_TRUE(first.colliding == second.colliding);
  for (std::size_t k = 0; k < first.candidate_count(); ++k) {
    const double a = first.pairs.distance[k], b = second.pairs.distance[k];
    EXPECT_TRUE(a == b || (std::isnan(a) && std::isnan(b))) << k;
  }
  for (std::size_t i = 0; i < handles.size(); ++i) {
    EXPECT_EQ(scene.pose(handles[i]).translation, poses[i].translation);
    EXPECT_EQ(scene.pose(handles[i]).rotation.coeffs(), poses[i].rotation.coeffs());
  }
  std::vector<Aabb> boxes;
  std::vector<ObjectHandle> owners;
  detail::SceneHooks::last_aabbs(scene, boxes, owners);
  ASSERT_EQ(boxes.size(), handles.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const Aabb exact = compute_aabb((*shapes)[scene.shape(owners[i])], scene.pose(owners[i]).rotation,
                                    scene.pose(owners[i]).translation);
    EXPECT_TRUE((boxes[i].min.array() <= exact.min.array()).all() &&
                (boxes[i].max.array() >= exact.max.array()).all())
        << "box " << i << " does not contain its object";
  }
  expect_matches_all_pairs(scene, handles, options);
}

TEST(Scene, RejectsBadInput) {
  auto shapes = std::make_shared<ShapeTable>();
  shapes->add(Shape::sphere(0.1));
  EXPECT_THROW(Scene(nullptr), InputError);
  Scene scene(shapes);
  EXPECT_THROW(scene.add(1, Pose::identity()), InputError);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(scene.add(0, Pose::from_translation({nan, 0, 0})), InputError);
  EXPECT_THROW(scene.add(0, Pose::from_translation({0, 2e30, 0})), InputError);
  EXPECT_THROW(scene.add(0, Pose{{0, 0, 0}, Eigen::Quaterniond(1.1, 0, 0, 0)}), InputError);
  const ObjectHandle h = scene.add(0, Pose{{0, 0, 0}, Eigen::Quaterniond(1 + 1e-8, 0, 0, 0)});  // normalised
  EXPECT_EQ(scene.pose(h).rotation.w(), 1.0);
  SceneResults r;
  QueryOptions bad;
  bad.margin = -1;
  EXPECT_THROW(scene.collide(bad, r), InputError);
  scene.collide(QueryOptions{}, r);  // one object: no pairs
  EXPECT_EQ(r.candidate_count(), 0u);
  std::vector<Aabb> boxes;
  std::vector<ObjectHandle> objects;
  detail::SceneHooks::last_aabbs(scene, boxes, objects);
  EXPECT_EQ(objects, std::vector<ObjectHandle>{h});
  scene.add(0, Pose::identity());
  EXPECT_THROW(detail::SceneHooks::last_aabbs(scene, boxes, objects), InputError);  // boxes of a different set of objects
}

}  // namespace
}  // namespace batchcol
