// RaySceneIndex against brute force: every ray against every object through the shape form (cast_rays), on mixed
// scenes (every shape type, inflated shapes, a halfspace). Closest, any and all queries; refit after moves, rebuild
// after additions and removals; bitwise the same answers for 1 and 2 threads; invalid rays and calls.
#include "support/generators.hpp"
#include "support/same_results.hpp"

#include "batchcol/rays.hpp"
#include "batchcol/scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <thread>
#include <vector>

namespace batchcol {
namespace {

using testing::Rng;
using testing::uniform;

std::shared_ptr<ShapeTable> mixed_table(Rng& rng) {
  auto table = std::make_shared<ShapeTable>();
  for (ShapeType type : testing::bounded_shape_types()) {
    table->add(testing::random_shape(rng, type, 0.1, 0.6));
    table->add(testing::random_shape(rng, type, 0.1, 0.6).inflated(0.05));
  }
  return table;
}

struct World {
  std::shared_ptr<ShapeTable> table;
  Scene scene;
  std::vector<ObjectHandle> handles;
  explicit World(std::shared_ptr<ShapeTable> t) : table(t), scene(t) {}
};

World make_world(Rng& rng, int objects, bool with_ground) {
  World w(mixed_table(rng));
  const std::uint32_t bounded = static_cast<std::uint32_t>(w.table->size());
  for (int i = 0; i < objects; ++i) {
    const Eigen::Vector3d t(uniform(rng, -5, 5), uniform(rng, -5, 5), uniform(rng, -5, 5));
    w.handles.push_back(w.scene.add(static_cast<std::uint32_t>(i % bounded), {t, testing::random_rotation(rng)}));
  }
  if (with_ground) {
    const std::uint32_t ground = w.table->add(Shape::halfspace(Eigen::Vector3d::UnitZ(), 0.0));
    w.handles.push_back(w.scene.add(ground, Pose::from_translation(Eigen::Vector3d(0, 0, -6))));
  }
  return w;
}

RayBatch random_rays(Rng& rng, int n) {
  RayBatch rays;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d o(uniform(rng, -8, 8), uniform(rng, -8, 8), uniform(rng, -8, 8));
    const Eigen::Vector3d target(uniform(rng, -5, 5), uniform(rng, -5, 5), uniform(rng, -5, 5));
    const double t_max = i % 3 == 0 ? uniform(rng, 0.5, 1.5) : std::numeric_limits<double>::infinity();
    rays.add(o, (target - o).normalized() * (i % 5 == 0 ? 2.5 : 1.0), t_max);
  }
  return rays;
}

struct BruteHit {
  double t;
  ObjectHandle object;
};

// Every ray against every object of the scene, through cast_rays() (the shape form), hits sorted by (t, slot).
std::vector<std::vector<BruteHit>> brute_force(const World& w, const RayBatch& rays) {
  std::vector<ObjectHandle> live;
  for (ObjectHandle h : w.handles)
    if (w.scene.contains(h)) live.push_back(h);
  ShapeRayBatch batch;
  for (std::size_t i = 0; i < rays.size(); ++i)
    for (ObjectHandle h : live)
      batch.add(w.scene.shape(h), w.scene.pose(h), rays.origin[i], rays.direction[i], rays.t_max[i]);
  RayResults r;
  cast_rays(*w.table, batch, RayOptions{}, r);
  std::vector<std::vector<BruteHit>> hits(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    for (std::size_t k = 0; k < live.size(); ++k) {
      const std::size_t row = i * live.size() + k;
      EXPECT_NE(r.status[row], RayStatus::invalid_input);
      if (r.hit[row]) hits[i].push_back({r.t[row], live[k]});
    }
    std::sort(hits[i].begin(), hits[i].end(), [](const BruteHit& a, const BruteHit& b) {
      return a.t < b.t || (a.t == b.t && a.object.slot < b.object.slot);
    });
  }
  return hits;
}

// The scene form transforms rays with its own copy of the rotation; the shape form normalises the quaternion again:
// the two may differ by a few ulps.
constexpr double kTransformSlack = 1e-9;

void expect_matches_brute_force(const RaySceneIndex& index, const World& w, const RayBatch& rays) {
  const auto brute = brute_force(w, rays);
  RayResults closest, any, all;
  RayOptions o;
  index.cast(rays, o, closest);
  o.query = RayQuery::any;
  index.cast(rays, o, any);
  o.query = RayQuery::all;
  index.cast(rays, o, all);
  int hits = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    SCOPED_TRACE(::testing::Message() << "ray " << i);
    const auto& b = brute[i];
    ASSERT_EQ(closest.status[i], RayStatus::ok);
    ASSERT_EQ(closest.hit[i], b.empty() ? 0 : 1);
    ASSERT_EQ(any.hit[i], closest.hit[i]);
    ASSERT_EQ(all.hit_begin[i + 1] - all.hit_begin[i], b.size());
    if (b.empty()) continue;
    ++hits;
    EXPECT_NEAR(closest.t[i], b[0].t, kTransformSlack);
    // The same object, unless a second one is hit within the slack (a tie up to rounding).
    if (b.size() < 2 || b[1].t - b[0].t > kTransformSlack) { EXPECT_EQ(closest.object[i], b[0].object); }
    EXPECT_NEAR(closest.normal[i].norm(), 1.0, 1e-12);
    // Any: one of the objects brute force hits, at its t.
    const auto it = std::find_if(b.begin(), b.end(), [&](const BruteHit& h) { return h.object == any.object[i]; });
    ASSERT_NE(it, b.end());
    EXPECT_NEAR(any.t[i], it->t, kTransformSlack);
    // All: the same objects with the same t (compared as sets: ties may be ordered differently).
    for (std::uint64_t row = all.hit_begin[i]; row < all.hit_begin[i + 1]; ++row) {
      const auto m = std::find_if(b.begin(), b.end(), [&](const BruteHit& h) { return h.object == all.all_object[row]; });
      ASSERT_NE(m, b.end());
      EXPECT_NEAR(all.all_t[row], m->t, kTransformSlack);
      if (row > all.hit_begin[i]) { EXPECT_LE(all.all_t[row - 1], all.all_t[row]); }
    }
    EXPECT_EQ(all.t[i], all.all_t[all.hit_begin[i]]);
  }
  EXPECT_GT(hits, static_cast<int>(rays.size()) / 8);  // the scene is dense enough for the test to mean something
}

TEST(RayScene, MatchesBruteForceForEveryQuery) {
  Rng rng(11);
  World w = make_world(rng, 300, true);
  RaySceneIndex index;
  index.update(w.scene);
  EXPECT_TRUE(index.last_update_rebuilt());
  EXPECT_EQ(index.object_count(), 301u);
  expect_matches_brute_force(index, w, random_rays(rng, 1500));
}

TEST(RayScene, RaysGrazingTheExtremePointsOfTurnedHullsMatchBruteForce) {
  // The ray index clips a hull's world box (its turned local box) to the box of its bounding ball about the local
  // origin. Hulls here are off-centre (the origin is not their centre) and turned at random; rays pass 1e-7 inside
  // each hull's extreme vertex along every world axis, parallel to another axis, where a box clipped too far would
  // drop the hull. Every answer must be brute force's.
  Rng rng(31);
  auto table = std::make_shared<ShapeTable>();
  for (int s = 0; s < 4; ++s) {
    std::vector<Eigen::Vector3d> points;
    const Eigen::Vector3d offset(uniform(rng, -0.4, 0.4), uniform(rng, -0.4, 0.4), uniform(rng, -0.4, 0.4));
    for (int k = 0; k < 40; ++k) points.push_back(offset + 0.5 * testing::random_unit_vector(rng));
    table->add(Shape::convex(points));
  }
  World w(table);
  for (int i = 0; i < 60; ++i) {
    const Eigen::Vector3d t(uniform(rng, -4, 4), uniform(rng, -4, 4), uniform(rng, -4, 4));
    w.handles.push_back(w.scene.add(static_cast<std::uint32_t>(i % 4), {t, testing::random_rotation(rng)}));
  }
  RaySceneIndex index;
  index.update(w.scene);
  RayBatch rays;
  for (ObjectHandle h : w.handles) {
    const Pose p = w.scene.pose(h);
    const std::vector<Eigen::Vector3d>& local = (*w.table)[w.scene.shape(h)].hull->vertices;
    for (int a = 0; a < 3; ++a) {
      for (double sign : {-1.0, 1.0}) {
        Eigen::Vector3d best = p.rotation * local[0] + p.translation;
        for (const Eigen::Vector3d& v : local) {
          const Eigen::Vector3d x = p.rotation * v + p.translation;
          if (sign * x[a] > sign * best[a]) best = x;
        }
        const int b = (a + 1) % 3;
        Eigen::Vector3d o = best, d = Eigen::Vector3d::Zero();
        o[a] -= sign * 1e-7;
        o[b] -= 20.0;
        d[b] = 1.0;
        rays.add(o, d, INFINITY);
      }
    }
  }
  expect_matches_brute_force(index, w, rays);
  RayResults r;
  index.cast(rays, RayOptions{}, r);
  const long hits = std::count(r.hit.begin(), r.hit.end(), 1);
  EXPECT_GT(hits, long(rays.size()) / 4);  // rays that reach their hull (and usually others) are common, not rare
}

TEST(RayScene, SmallScenes) {
  Rng rng(12);
  for (int n : {1, 2, 3, 17}) {
    World w = make_world(rng, n, false);
    RaySceneIndex index;
    index.update(w.scene);
    RayBatch rays;
    // Rays aimed at the objects so that most of them hit.
    for (int i = 0; i < 200; ++i) {
      const Pose p = w.scene.pose(w.handles[i % n]);
      const Eigen::Vector3d o(uniform(rng, -8, 8), uniform(rng, -8, 8), uniform(rng, -8, 8));
      rays.add(o, p.translation - o + 0.05 * testing::random_unit_vector(rng), INFINITY);
    }
    expect_matches_brute_force(index, w, rays);
  }
}

TEST(RayScene, RefitAfterMovesAndRebuildAfterAddRemove) {
  Rng rng(13);
  World w = make_world(rng, 200, false);
  RaySceneIndex index;
  index.update(w.scene);
  for (ObjectHandle h : w.handles) {
    Pose p = w.scene.pose(h);
    p.translation += Eigen::Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    w.scene.set_pose(h, {p.translation, testing::random_rotation(rng)});
  }
  index.update(w.scene);
  EXPECT_FALSE(index.last_update_rebuilt());
  EXPECT_EQ(index.timings().build_ms, 0.0);
  expect_matches_brute_force(index, w, random_rays(rng, 800));
  w.scene.remove(w.handles[5]);
  w.handles.push_back(w.scene.add(0, Pose::from_translation(Eigen::Vector3d(1, 2, 3))));
  index.update(w.scene);
  EXPECT_TRUE(index.last_update_rebuilt());
  expect_matches_brute_force(index, w, random_rays(rng, 800));
  // A forced rebuild over unchanged objects gives the same answers as the refit tree would.
  index.update(w.scene, 0, true);
  EXPECT_TRUE(index.last_update_rebuilt());
}

template <class T> bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

TEST(RayScene, BitwiseIdenticalForAnyThreadCount) {
  Rng rng(14);
  World w = make_world(rng, 2000, true);
  const RayBatch rays = random_rays(rng, 5000);
  for (RayQuery q : {RayQuery::closest, RayQuery::any, RayQuery::all}) {
    RayResults r1, r2;
    RaySceneIndex i1, i2;
    i1.update(w.scene, 1);
    i2.update(w.scene, 2);
    RayOptions o;
    o.query = q;
    o.threads = 1;
    i1.cast(rays, o, r1);
    o.threads = 2;
    i2.cast(rays, o, r2);
    EXPECT_TRUE(same_bits(r1.hit, r2.hit) && same_bits(r1.t, r2.t) && same_bits(r1.normal.x, r2.normal.x) &&
                same_bits(r1.normal.z, r2.normal.z) && same_bits(r1.hit_begin, r2.hit_begin) &&
                same_bits(r1.all_t, r2.all_t))
        << to_string(q);
    for (std::size_t i = 0; i < rays.size(); ++i) ASSERT_EQ(r1.object[i], r2.object[i]);
  }
}

TEST(RayScene, InvalidRaysGetAStatusAndBadCallsThrow) {
  Rng rng(15);
  World w = make_world(rng, 20, false);
  RaySceneIndex index;
  RayBatch rays;
  rays.add({0, 0, 20}, {0, 0, -1}, INFINITY);  // valid, infinite t_max
  rays.add({0, 0, 20}, {0, 0, 0}, 1.0);        // zero direction
  rays.add({NAN, 0, 0}, {0, 0, 1}, 1.0);       // non-finite origin
  rays.add({0, 0, 0}, {INFINITY, 0, 0}, 1.0);  // non-finite direction
  rays.add({0, 0, 0}, {1, 0, 0}, -1.0);        // negative t_max
  rays.add({0, 0, 0}, {1, 0, 0}, NAN);         // NaN t_max
  RayResults r;
  EXPECT_THROW(index.cast(rays, {}, r), InputError);  // before update()
  index.update(w.scene);
  index.cast(rays, {}, r);
  EXPECT_EQ(r.status[0], RayStatus::ok);
  for (std::size_t i = 1; i < rays.size(); ++i) {
    EXPECT_EQ(r.status[i], RayStatus::invalid_input) << i;
    EXPECT_EQ(r.hit[i], 0);
    EXPECT_TRUE(std::isnan(r.t[i]));
    EXPECT_EQ(r.object[i], ObjectHandle{});
  }
  rays.t_max.pop_back();
  EXPECT_THROW(index.cast(rays, {}, r), InputError);
  rays.t_max.push_back(1.0);
  RayOptions bad;
  bad.tolerance = 0.0;
  EXPECT_THROW(index.cast(rays, bad, r), InputError);
  bad = {};
  bad.threads = -1;
  EXPECT_THROW(index.cast(rays, bad, r), InputError);
  EXPECT_THROW(parse_ray_query("nearest"), InputError);
  EXPECT_EQ(parse_ray_query("all"), RayQuery::all);
}

}  // namespace
}  // namespace batchcol

namespace batchcol {
namespace {

TEST(RayScene, EmptySceneAndHalfspacesOnly) {
  auto table = std::make_shared<ShapeTable>();
  const std::uint32_t ground = table->add(Shape::halfspace(Eigen::Vector3d::UnitZ(), 0.0));
  Scene scene(table);
  RaySceneIndex index;
  index.update(scene);
  RayBatch rays;
  rays.add({0, 0, 5}, {0, 0, -1}, INFINITY);
  RayResults r;
  index.cast(rays, {}, r);
  EXPECT_EQ(r.status[0], RayStatus::ok);
  EXPECT_EQ(r.hit[0], 0);
  const ObjectHandle h = scene.add(ground, Pose::from_translation(Eigen::Vector3d(0, 0, 1)));
  index.update(scene);
  EXPECT_TRUE(index.last_update_rebuilt());
  for (RayQuery q : {RayQuery::closest, RayQuery::any, RayQuery::all}) {
    RayOptions o;
    o.query = q;
    index.cast(rays, o, r);
    ASSERT_EQ(r.hit[0], 1) << to_string(q);
    EXPECT_EQ(r.t[0], 4.0);
    EXPECT_EQ(r.object[0], h);
    EXPECT_EQ(r.normal[0], Eigen::Vector3d(0, 0, 1));
  }
  EXPECT_EQ(r.hit_begin, (std::vector<std::uint64_t>{0, 1}));
}

// Large batches on large trees are cast in a coherent order with the rays and results copied (ray_scene_cast.cpp,
// RayOrder: batches of >= 4096 rays when the wide nodes and the objects' records reach 1 MiB; 60k objects here give
// 19928 nodes, 5.1 MB).
// Their results must be those of input order bit for bit: batches of 1000 rays are below the threshold and are cast
// in input order. Invalid rays are mixed in (they sort last and must keep their status).
TEST(RayScene, CastOrderOfLargeBatchesGivesTheSameBits) {
  Rng rng(16);
  World w = make_world(rng, 60000, true);
  RayBatch rays = random_rays(rng, 9000);
  for (std::size_t i = 0; i < rays.size(); i += 97) rays.direction.set(i, Eigen::Vector3d::Zero());
  for (std::size_t i = 5; i < rays.size(); i += 89) rays.origin.x[i] = std::nan("");
  for (RayQuery q : {RayQuery::closest, RayQuery::any}) {
    for (int threads : {1, 2}) {
      RaySceneIndex index;
      index.update(w.scene, threads);
      RayOptions o;
      o.query = q;
      o.threads = threads;
      SCOPED_TRACE(::testing::Message() << to_string(q) << ", " << threads << " threads");
      RayResults whole;
      index.cast(rays, o, whole);
      ASSERT_TRUE(testing::cast_in_parts_matches(index, rays, o, whole));
      const int hits = std::count(whole.hit.begin(), whole.hit.end(), std::uint8_t{1});
      EXPECT_GT(hits, 1000);
      EXPECT_EQ(whole.status[0], RayStatus::invalid_input);
      EXPECT_EQ(whole.status[5], RayStatus::invalid_input);
    }
  }
}

// The ordered cast's memory is the index's, kept from one cast to the next (ray_cast_arena.hpp): what an earlier,
// larger or different batch left there must not show in a later cast, and casts running at the same time on one index
// (one holds the memory, the other takes its own) give the bits of casts one after the other.
TEST(RayScene, ReusedCastMemoryGivesTheSameBits) {
  Rng rng(17);
  World w = make_world(rng, 60000, true);
  const RayBatch big = random_rays(rng, 12000), small = random_rays(rng, 5000);
  const auto same = [](const RayResults& a, const RayResults& b) {
    return same_bits(a.status, b.status) && same_bits(a.hit, b.hit) && same_bits(a.t, b.t) &&
           same_bits(a.normal.x, b.normal.x) && same_bits(a.normal.y, b.normal.y) &&
           same_bits(a.normal.z, b.normal.z) && same_bits(a.object, b.object);
  };
  for (RayQuery q : {RayQuery::closest, RayQuery::any}) {
    SCOPED_TRACE(to_string(q));
    RayOptions o;
    o.query = q;
    o.threads = 2;
    const auto fresh = [&](const RayBatch& rays) {
      RaySceneIndex index;
      index.update(w.scene, 2);
      RayResults r;
      index.cast(rays, o, r);
      return r;
    };
    const RayResults big_fresh = fresh(big), small_fresh = fresh(small);
    int hits = 0;
    for (std::uint8_t h : small_fresh.hit) hits += h;
    EXPECT_GT(hits, 500);
    RaySceneIndex index;
    index.update(w.scene, 2);
    RayResults r;
    index.cast(big, o, r);
    EXPECT_TRUE(same(r, big_fresh));
    index.cast(small, o, r);  // a smaller batch in the larger batch's memory
    EXPECT_TRUE(same(r, small_fresh));
    index.cast(big, o, r);
    EXPECT_TRUE(same(r, big_fresh));
    RayResults a, b;
    std::thread other([&] { index.cast(small, o, b); });
    index.cast(big, o, a);
    other.join();
    EXPECT_TRUE(same(a, big_fresh));
    EXPECT_TRUE(same(b, small_fresh));
  }
}

// RayOptions::isa picks the scene traversal's and the shape form's lane kernels' instruction set: every set this CPU
// runs gives the same bits as the scalar one (closest and any on a tree large enough for the Morton-ordered cast, all
// in input order; the shape form in double and float, where the lanes are 1, 4 or 8 rays wide).
TEST(RayScene, EveryInstructionSetGivesTheSameBits) {
  Rng rng(18);
  World w = make_world(rng, 30000, true);
  const RayBatch rays = random_rays(rng, 6000);
  RaySceneIndex index;
  index.update(w.scene, 2);
  ShapeRayBatch shape_rays;
  for (std::size_t i = 0; i < 3000; ++i) {
    const std::uint32_t shape = static_cast<std::uint32_t>(i % w.table->size());
    const Eigen::Vector3d t(uniform(rng, -2, 2), uniform(rng, -2, 2), uniform(rng, -2, 2));
    const Eigen::Vector3d o = t + Eigen::Vector3d(uniform(rng, -3, 3), uniform(rng, -3, 3), 3.0);
    const Eigen::Vector3d target = t + Eigen::Vector3d(uniform(rng, -0.4, 0.4), uniform(rng, -0.4, 0.4), 0.0);
    shape_rays.add(shape, {t, testing::random_rotation(rng)}, o, target - o, rays.t_max[i]);
  }
  const InstructionSet sets[] = {InstructionSet::scalar, InstructionSet::avx2, InstructionSet::avx512};
  const bool has[] = {true, __builtin_cpu_supports("avx2") != 0,
                      __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                          __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw")};
  const auto same = [](const RayResults& a, const RayResults& b) {
    return same_bits(a.status, b.status) && same_bits(a.hit, b.hit) && same_bits(a.t, b.t) &&
           same_bits(a.normal.x, b.normal.x) && same_bits(a.normal.y, b.normal.y) &&
           same_bits(a.normal.z, b.normal.z) && same_bits(a.object, b.object) && same_bits(a.hit_begin, b.hit_begin) &&
           same_bits(a.all_t, b.all_t) && same_bits(a.all_object, b.all_object);
  };
  for (RayQuery q : {RayQuery::closest, RayQuery::any, RayQuery::all}) {
    RayResults reference;
    for (int k = 0; k < 3; ++k) {
      if (!has[k]) continue;
      RayOptions o;
      o.query = q;
      o.threads = 2;
      o.isa = sets[k];
      RayResults r;
      index.cast(rays, o, r);
      if (k == 0) {
        reference = r;
      } else {
        EXPECT_TRUE(same(r, reference)) << to_string(q) << " " << to_string(sets[k]);
      }
    }
    EXPECT_GT(std::count(reference.hit.begin(), reference.hit.end(), 1), 1000) << to_string(q);
  }
  for (Precision p : {Precision::float64, Precision::float32}) {
    RayResults reference;
    for (int k = 0; k < 3; ++k) {
      if (!has[k]) continue;
      RayOptions o;
      o.precision = p;
      o.isa = sets[k];
      RayResults r;
      cast_rays(*w.table, shape_rays, o, r);
      if (k == 0) {
        reference = r;
      } else {
        EXPECT_TRUE(same(r, reference)) << to_string(p) << " " << to_string(sets[k]);
      }
    }
    EXPECT_GT(std::count(reference.hit.begin(), reference.hit.end(), 1), 100) << to_string(p);
  }
}

// The wide traversal rejects leaves with a float ball test before the exact double one (ray_wide_traverse.hpp); its
// margins cover the rounding of origins and centres to float, which at 10^6 m is 1/16 m, far more than the gap left
// here (the test fails when the margins are left out). Spheres of radius 0.5 m around centres up to 10^6 m from the
// origin, rays from 10 m away aimed to pass each centre at 0.5 (1 - 1e-9) m (hits) or 0.5 (1 + 1e-9) m (misses):
// every answer must be brute force's.
TEST(RayScene, LeafBallFilterKeepsGrazingRaysFarFromTheOrigin) {
  Rng rng(17);
  for (double scale : {1.0, 1e3, 1e6}) {
    auto table = std::make_shared<ShapeTable>();
    const std::uint32_t sphere = table->add(Shape::sphere(0.5));
    World w(table);
    std::vector<Eigen::Vector3d> centres;
    for (int i = 0; i < 300; ++i) {
      centres.emplace_back(uniform(rng, -1, 1) * scale, uniform(rng, -1, 1) * scale, uniform(rng, -1, 1) * scale);
      w.handles.push_back(w.scene.add(sphere, Pose::from_translation(centres.back())));
    }
    RayBatch rays;
    for (int i = 0; i < 600; ++i) {
      const Eigen::Vector3d c = centres[std::size_t(i) % centres.size()];
      const Eigen::Vector3d d =
          Eigen::Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1)).normalized();
      const Eigen::Vector3d side = d.unitOrthogonal();
      const double pass = 0.5 * (i % 2 == 0 ? 1.0 - 1e-9 : 1.0 + 1e-9);
      rays.add(c + pass * side - 10.0 * d, d, INFINITY);
    }
    RaySceneIndex index;
    index.update(w.scene);
    const auto brute = brute_force(w, rays);
    RayResults r;
    index.cast(rays, {}, r);
    int hits = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      SCOPED_TRACE(::testing::Message() << "scale " << scale << ", ray " << i);
      ASSERT_EQ(r.hit[i], brute[i].empty() ? 0 : 1);
      if (!r.hit[i]) continue;
      ++hits;
      if (brute[i].size() < 2 || brute[i][1].t - brute[i][0].t > kTransformSlack) {
        EXPECT_EQ(r.object[i], brute[i][0].object);
      }
    }
    EXPECT_GE(hits, 300);  // every grazing ray hits its sphere
  }
}

}  // namespace
}  // namespace batchcol
