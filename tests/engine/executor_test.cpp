// The batch executor: results in input order, bitwise identical for any thread count, per-pair statuses for bad
// pairs, exceptions only for a malformed call, warm start.
#include "instruction_set.hpp"  // engine/src: capped_instruction_set
#include "shape_table_access.hpp"  // engine/src: ShapeTableAccess::one_type
#include "kernels/simd/wide_gjk.hpp"
#include "support/generators.hpp"
#include "support/same_results.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <set>
#include <utility>
#include <string>

namespace batchcol {
namespace {

using testing::Rng;

struct Scene {
  ShapeTable shapes;
  PairBatch batch;
};

Scene mixed_scene(std::size_t pairs, std::uint64_t seed) {
  Rng rng(seed);
  Scene s;
  for (ShapeType t : testing::bounded_shape_types())
    for (int k = 0; k < 3; ++k) s.shapes.add(testing::random_shape(rng, t));
  s.shapes.add(Shape::halfspace({0, 0, 1}, -0.5));
  for (std::size_t i = 0; i < pairs; ++i) {
    const auto a = static_cast<std::uint32_t>(rng() % s.shapes.size());
    const auto b = static_cast<std::uint32_t>(rng() % s.shapes.size());
    const Pose pa{testing::random_vector(rng), testing::random_rotation(rng)};
    const Pose pb{pa.translation + testing::random_unit_vector(rng) * testing::uniform(rng, 0, 0.5),
                  testing::random_rotation(rng)};
    s.batch.add(a, pa, b, pb);
  }
  return s;
}

TEST(Executor, BitwiseIdenticalForOneAndTwoThreadsAtEveryLevelAndPrecision) {
  // Tiles are sized from the batch and the thread count (executor.cpp, tile_pairs): 5000 pairs make tiles of 625
  // pairs on 1 thread, 313 on 2 and 209 on 3; 1000 pairs make 128-pair tiles on 2 and 3 threads.
  for (std::size_t pairs : {std::size_t(5000), std::size_t(1000)}) {
    const Scene s = mixed_scene(pairs, 1);
    for (Precision p : {Precision::float64, Precision::float32})
      for (QueryLevel level :
           {QueryLevel::boolean, QueryLevel::distance, QueryLevel::witness, QueryLevel::penetration}) {
        QueryOptions o;
        o.level = level;
        o.precision = p;
        o.threads = 1;
        PairResults one;
        collide(s.shapes, s.batch, o, one);
        for (int threads : {2, 3}) {
          o.threads = threads;
          PairResults more;
          collide(s.shapes, s.batch, o, more);
          testing::expect_same_results(one, more, "1 vs " + std::to_string(threads) + " threads, " +
                                                      std::to_string(pairs) + " pairs, " + to_string(level));
        }
      }
  }
}

// Every instruction set this CPU runs gives bitwise the same results as the scalar build (and so as the
// reference: tests/kernels/wide_gjk_test.cpp), at every level and precision, y component included.
TEST(Executor, BitwiseIdenticalForEveryInstructionSetThisCpuRuns) {
  const Scene s = mixed_scene(4000, 11);
  for (Precision p : {Precision::float64, Precision::float32})
    for (QueryLevel level : {QueryLevel::boolean, QueryLevel::distance, QueryLevel::witness, QueryLevel::penetration}) {
      QueryOptions o;
      o.level = level;
      o.precision = p;
      o.isa = InstructionSet::scalar;
      PairResults want;
      collide(s.shapes, s.batch, o, want);
      for (InstructionSet isa : {InstructionSet::avx2, InstructionSet::avx512}) {
        o.isa = isa;
        PairResults got;
        try {
          collide(s.shapes, s.batch, o, got);
        } catch (const InputError& e) {  // a set this CPU lacks: refused up front, never run
          EXPECT_NE(std::string(e.what()).find("not supported by this CPU"), std::string::npos) << e.what();
          continue;
        }
        testing::expect_same_results(want, got, std::string(to_string(isa)) + ", " + to_string(level));
      }
    }
}

// Float groups of large hulls run on the AVX2 entry when AVX-512 is asked for (kernels/simd/dispatch.cpp: the
// climb is per lane, 16 lanes only crowd the cache); the answer must stay the scalar build's, bit for bit, for
// groups of large hulls only and for groups where small and large hulls mix on either side.
TEST(Executor, LargeHullFloatGroupsGiveTheSameBitsOnEveryInstructionSet) {
  Rng rng(29);
  ShapeTable shapes;
  for (int k = 0; k < 3; ++k) shapes.add(Shape::convex(testing::random_hull_points(rng, 300, 0.05, 0.2)));
  shapes.add(Shape::convex(testing::random_hull_points(rng, 12, 0.05, 0.2)));
  ASSERT_GE(shapes[0].hull->vertices.size(), 32u);  // climbed, not scanned
  PairBatch batch;
  for (int i = 0; i < 3000; ++i) {
    const auto a = static_cast<std::uint32_t>(rng() % shapes.size());
    const auto b = static_cast<std::uint32_t>(rng() % shapes.size());
    const Pose pa{testing::random_vector(rng), testing::random_rotation(rng)};
    const Pose pb{pa.translation + testing::random_unit_vector(rng) * testing::uniform(rng, 0.05, 0.6),
                  testing::random_rotation(rng)};
    batch.add(a, pa, b, pb);
  }
  for (QueryLevel level : {QueryLevel::boolean, QueryLevel::witness}) {
    QueryOptions o;
    o.level = level;
    o.precision = Precision::float32;
    o.isa = InstructionSet::scalar;
    PairResults want;
    collide(shapes, batch, o, want);
    for (InstructionSet isa : {InstructionSet::avx2, InstructionSet::avx512}) {
      o.isa = isa;
      PairResults got;
      try {
        collide(shapes, batch, o, got);
      } catch (const InputError& e) {  // a set this CPU lacks
        EXPECT_NE(std::string(e.what()).find("not supported by this CPU"), std::string::npos) << e.what();
        continue;
      }
      testing::expect_same_results(want, got, std::string(to_string(isa)) + ", " + to_string(level));
    }
  }
}

// BATCHCOL_ISA lowers the automatic choice; a value naming no set is an input error. The environment is read
// once per process (resolve_instruction_set), so the rule is tested on the function that applies it.
TEST(Executor, EnvironmentVariableLowersTheInstructionSet) {
  using detail::capped_instruction_set;
  const InstructionSet best = resolve_instruction_set();
  EXPECT_NE(best, InstructionSet::automatic);
  EXPECT_EQ(capped_instruction_set(best, std::getenv("BATCHCOL_ISA")), best);  // what the first call applied
  EXPECT_EQ(capped_instruction_set(InstructionSet::avx512, nullptr), InstructionSet::avx512);
  EXPECT_EQ(capped_instruction_set(InstructionSet::avx512, ""), InstructionSet::avx512);
  EXPECT_EQ(capped_instruction_set(InstructionSet::avx512, "scalar"), InstructionSet::scalar);
  EXPECT_EQ(capped_instruction_set(InstructionSet::avx512, "avx2"), InstructionSet::avx2);
  EXPECT_EQ(capped_instruction_set(InstructionSet::avx2, "avx512"), InstructionSet::avx2);  // a cap above the best
  EXPECT_EQ(capped_instruction_set(InstructionSet::scalar, "avx2"), InstructionSet::scalar);
  EXPECT_THROW(capped_instruction_set(InstructionSet::avx512, "sse9"), InputError);
  EXPECT_THROW(capped_instruction_set(InstructionSet::avx512, "AVX2"), InputError);
}

TEST(Executor, ResultsComeBackInInputOrder) {
  const Scene s = mixed_scene(3000, 2);
  QueryOptions o;
  o.level = QueryLevel::penetration;
  PairResults all;
  collide(s.shapes, s.batch, o, all);
  for (std::size_t i = 0; i < s.batch.size(); i += 97) {
    const auto r = testing::run_pair(s.shapes[s.batch.shape_a[i]], s.batch.pose_a(i), s.shapes[s.batch.shape_b[i]],
                                     s.batch.pose_b(i), o);
    EXPECT_EQ(r.distance, all.distance[i]) << i;
    EXPECT_EQ(r.witness_a, all.witness_a[i]) << i;
  }
}

TEST(Executor, QueryLevelsComputeOnlyWhatTheyAsk) {
  const Scene s = mixed_scene(2000, 3);
  QueryOptions o;
  PairResults b, d, w, p;
  o.level = QueryLevel::boolean;
  collide(s.shapes, s.batch, o, b);
  o.level = QueryLevel::distance;
  collide(s.shapes, s.batch, o, d);
  o.level = QueryLevel::witness;
  collide(s.shapes, s.batch, o, w);
  o.level = QueryLevel::penetration;
  collide(s.shapes, s.batch, o, p);
  // The arrays a level does not compute stay empty; the others have every pair.
  const std::size_t n = s.batch.size();
  EXPECT_TRUE(b.distance.empty() && b.witness_a.x.empty() && b.witness_b.y.empty() && b.normal.z.empty());
  EXPECT_EQ(b.direction.x.size(), n);
  EXPECT_EQ(d.distance.size(), n);
  EXPECT_TRUE(d.witness_a.x.empty() && d.witness_b.z.empty() && d.normal.y.empty());
  EXPECT_EQ(w.witness_a.z.size(), n);
  EXPECT_EQ(w.normal.x.size(), n);
  int overlapping = 0;
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(b.collide[i], p.collide[i]) << i;
    EXPECT_EQ(d.collide[i], p.collide[i]) << i;
    if (p.distance[i] > 1e-7) {
      EXPECT_NEAR(d.distance[i], p.distance[i], 1e-7) << i;
      EXPECT_NEAR(w.witness_a.x[i], p.witness_a.x[i], 1e-6) << i;
    }
    if (p.collide[i]) ++overlapping;
    EXPECT_FALSE(std::isnan(p.distance[i])) << i;  // penetration computes every pair
  }
  EXPECT_GT(overlapping, 300);
}

TEST(Executor, BadPairsGetInvalidInputAndTheRestIsComputed) {
  Scene s = mixed_scene(10, 4);
  const Pose ok{Eigen::Vector3d(1, 0, 0), Eigen::Quaterniond::Identity()};
  const std::size_t out_of_range = s.batch.add(0, Pose{}, 999, ok);
  const std::size_t nan_pose = s.batch.add(0, Pose{Eigen::Vector3d(std::nan(""), 0, 0), Eigen::Quaterniond::Identity()}, 1, ok);
  const std::size_t bad_quat = s.batch.add(0, Pose{Eigen::Vector3d::Zero(), Eigen::Quaterniond(1, 0.1, 0, 0)}, 1, ok);
  const std::size_t near_unit = s.batch.add(0, Pose{Eigen::Vector3d::Zero(), Eigen::Quaterniond(1 + 5e-7, 0, 0, 0)}, 1, ok);
  PairResults r;
  collide(s.shapes, s.batch, QueryOptions{}, r);
  EXPECT_EQ(r.status[out_of_range], Status::invalid_input);
  EXPECT_EQ(r.status[nan_pose], Status::invalid_input);
  EXPECT_EQ(r.status[bad_quat], Status::invalid_input);
  EXPECT_TRUE(std::isnan(r.distance[bad_quat]));
  EXPECT_EQ(r.status[near_unit], Status::converged);  // normalised: within 1e-6 of unit norm
  for (std::size_t i = 0; i < 10; ++i) EXPECT_NE(r.status[i], Status::invalid_input);
}

TEST(Executor, MalformedCallsThrowInputError) {
  Scene s = mixed_scene(10, 5);
  PairResults r;
  QueryOptions bad;
  bad.tolerance = -1;
  EXPECT_THROW(collide(s.shapes, s.batch, bad, r), InputError);
  bad = QueryOptions{};
  bad.margin = std::nan("");
  EXPECT_THROW(collide(s.shapes, s.batch, bad, r), InputError);
  bad = QueryOptions{};
  bad.max_iterations = 0;
  EXPECT_THROW(collide(s.shapes, s.batch, bad, r), InputError);
  PairBatch ragged = s.batch;
  ragged.translation_b.x.pop_back();
  try {
    collide(s.shapes, ragged, QueryOptions{}, r);
    ADD_FAILURE() << "ragged batch accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("translation_b"), std::string::npos) << e.what();
  }
}

TEST(Executor, WarmStartFromThePreviousFrameSavesIterations) {
  Scene s = mixed_scene(3000, 6);
  QueryOptions o;
  o.level = QueryLevel::witness;
  o.closed_forms = false;
  PairResults first, second;
  collide(s.shapes, s.batch, o, first);
  s.batch.warm_start = first.direction;
  collide(s.shapes, s.batch, o, second);
  long cold = 0, warm = 0;
  for (std::size_t i = 0; i < s.batch.size(); ++i) {
    cold += first.iterations[i];
    warm += second.iterations[i];
    if (first.distance[i] > 0) { EXPECT_NEAR(first.distance[i], second.distance[i], 1e-7) << i; }
  }
  EXPECT_LT(warm, cold * 0.8) << "cold " << cold << " warm " << warm;
}

TEST(Executor, MarginMakesNearPairsCollide) {
  const Shape a = Shape::box(0.1, 0.1, 0.1);
  for (QueryLevel level : {QueryLevel::boolean, QueryLevel::witness})
    for (bool closed : {true, false}) {
      QueryOptions o;
      o.level = level;
      o.closed_forms = closed;
      o.margin = 0.01;
      const auto near = testing::run_pair(a, Pose{}, a, Pose::from_translation({0.205, 0.02, 0}), o);
      const auto far = testing::run_pair(a, Pose{}, a, Pose::from_translation({0.215, 0.02, 0}), o);
      EXPECT_TRUE(near.collide);
      EXPECT_FALSE(far.collide);
    }
}

// The default solver is `automatic`: polyak for boolean queries (gjk for plain_boolean_pays()'s pair types), gjk
// for the other levels except momentum_pays()'s
// pair types (an ellipsoid against an ellipsoid, cylinder, cone or hull), which run polyak there too. Each
// pair's results are its resolved solver's, bit for bit, and not those of the other solvers (iteration counts
// differ on some pair).
TEST(Executor, AutomaticSolverRunsPolyakForBooleanAndEllipsoidPairsAndGjkOtherwise) {
  EXPECT_EQ(QueryOptions{}.solver, Solver::automatic);
  EXPECT_EQ(resolve_solver(Solver::automatic, QueryLevel::boolean), Solver::polyak);
  for (QueryLevel level : {QueryLevel::distance, QueryLevel::witness, QueryLevel::penetration})
    EXPECT_EQ(resolve_solver(Solver::automatic, level), Solver::gjk);
  for (Solver named : {Solver::gjk, Solver::nesterov, Solver::polyak})
    EXPECT_EQ(resolve_solver(named, QueryLevel::boolean), named);
  // Per pair type: boolean polyak but gjk for the six pair types plain_boolean_pays() lists (capsule-box,
  // capsule-cylinder, capsule-cone, box-cylinder, box-cone, cone-cone, either order); the other levels polyak
  // exactly for momentum_pays()'s pairs, in either order; a named solver is never changed.
  const auto plain_boolean = [](ShapeType a, ShapeType b) {
    const std::set<std::pair<ShapeType, ShapeType>> listed = {
        {ShapeType::capsule, ShapeType::box},  {ShapeType::capsule, ShapeType::cylinder},
        {ShapeType::capsule, ShapeType::cone}, {ShapeType::box, ShapeType::cylinder},
        {ShapeType::box, ShapeType::cone},     {ShapeType::cone, ShapeType::cone}};
    return listed.count({a, b}) + listed.count({b, a}) > 0;
  };
  EXPECT_TRUE(plain_boolean_pays(ShapeType::cylinder, ShapeType::box));
  EXPECT_FALSE(plain_boolean_pays(ShapeType::cylinder, ShapeType::cylinder));
  for (ShapeType a : testing::bounded_shape_types())
    for (ShapeType b : testing::bounded_shape_types()) {
      EXPECT_EQ(resolve_solver(Solver::automatic, QueryLevel::boolean, a, b),
                plain_boolean(a, b) ? Solver::gjk : Solver::polyak)
          << to_string(a) << "-" << to_string(b);
      for (Solver named : {Solver::gjk, Solver::nesterov, Solver::polyak})
        EXPECT_EQ(resolve_solver(named, QueryLevel::boolean, a, b), named);
      const bool ellipsoid = a == ShapeType::ellipsoid || b == ShapeType::ellipsoid;
      const ShapeType other = a == ShapeType::ellipsoid ? b : a;
      const bool partner = other == ShapeType::ellipsoid || other == ShapeType::cylinder || other == ShapeType::cone ||
                           other == ShapeType::convex;
      const Solver want = ellipsoid && partner ? Solver::polyak : Solver::gjk;
      for (QueryLevel level : {QueryLevel::distance, QueryLevel::witness, QueryLevel::penetration}) {
        EXPECT_EQ(resolve_solver(Solver::automatic, level, a, b), want) << to_string(a) << "-" << to_string(b);
        for (Solver named : {Solver::gjk, Solver::nesterov, Solver::polyak})
          EXPECT_EQ(resolve_solver(named, level, a, b), named);
      }
    }
  EXPECT_TRUE(momentum_pays(ShapeType::ellipsoid, ShapeType::ellipsoid));
  EXPECT_TRUE(momentum_pays(ShapeType::convex, ShapeType::ellipsoid));
  EXPECT_FALSE(momentum_pays(ShapeType::cylinder, ShapeType::cylinder));
  EXPECT_FALSE(momentum_pays(ShapeType::capsule, ShapeType::ellipsoid));

  const Scene s = mixed_scene(3000, 5);
  const std::size_t n = s.batch.size();
  std::size_t momentum_pairs = 0;
  for (std::size_t i = 0; i < n; ++i)
    momentum_pairs += momentum_pays(s.shapes[s.batch.shape_a[i]].type, s.shapes[s.batch.shape_b[i]].type) ? 1 : 0;
  ASSERT_GT(momentum_pairs, std::size_t(50));  // the scene has pairs on both sides of the rule
  ASSERT_LT(momentum_pairs, n - 50);
  for (QueryLevel level : {QueryLevel::boolean, QueryLevel::distance, QueryLevel::witness, QueryLevel::penetration}) {
    QueryOptions automatic;
    automatic.level = level;
    PairResults got;
    collide(s.shapes, s.batch, automatic, got);
    std::vector<PairResults> named_results;
    for (Solver named : {Solver::gjk, Solver::nesterov, Solver::polyak}) {
      QueryOptions o = automatic;
      o.solver = named;
      named_results.emplace_back();
      collide(s.shapes, s.batch, o, named_results.back());
    }
    // The named solvers' results pair by pair as automatic resolves them.
    PairResults want = named_results[0];
    std::size_t differ[3] = {0, 0, 0}, used[3] = {0, 0, 0};
    for (std::size_t i = 0; i < n; ++i) {
      const Solver r = resolve_solver(Solver::automatic, level, s.shapes[s.batch.shape_a[i]].type,
                                      s.shapes[s.batch.shape_b[i]].type);
      const PairResults& from = named_results[static_cast<std::size_t>(r)];
      ++used[static_cast<std::size_t>(r)];
      want.status[i] = from.status[i];
      want.collide[i] = from.collide[i];
      want.iterations[i] = from.iterations[i];
      if (!want.distance.empty()) want.distance[i] = from.distance[i];
      for (auto m : {&PairResults::witness_a, &PairResults::witness_b, &PairResults::normal, &PairResults::direction})
        if (!(want.*m).empty()) (want.*m).set(i, (from.*m)[i]);
      for (std::size_t k = 0; k < 3; ++k)
        if (k != static_cast<std::size_t>(r) && named_results[k].iterations[i] != got.iterations[i]) ++differ[k];
    }
    testing::expect_same_results(want, got, std::string("automatic at ") + to_string(level));
    // A solver that automatic does not run on every pair differs from it on some pair it does not run on.
    for (std::size_t k = 0; k < 3; ++k)
      if (used[k] < n) {
        EXPECT_GT(differ[k], std::size_t(0)) << k << " at " << to_string(level);
      }
  }
}

// A table of one shape type takes the executor's shortcut (ShapeTableAccess::one_type(): the types are not read per
// pair); the same pairs in a table that also holds another type go through the per-pair grouping. Both must give
// the same bits. Pairs with an invalid index (999, 2^31, 2^32 - 1) go to group 0 (sphere-sphere) in the mixed
// table and to the table's own type pair in the one-type table, whose kernels (box SAT, batch-array GJK,
// per-pair path) must reject them as group 0's do.
TEST(Executor, OneTypeTableGivesTheResultsOfTheGeneralGrouping) {
  Rng rng(77);
  for (const ShapeType type : {ShapeType::sphere, ShapeType::capsule, ShapeType::box, ShapeType::cylinder,
                               ShapeType::convex}) {
    ShapeTable one, mixed;
    for (int k = 0; k < 5; ++k) {
      const Shape shape = testing::random_shape(rng, type);
      one.add(shape);
      mixed.add(shape);
    }
    mixed.add(type == ShapeType::sphere ? Shape::box(0.1, 0.1, 0.1) : Shape::sphere(0.1));  // index 5: never used
    ASSERT_TRUE(detail::ShapeTableAccess::one_type(one)) << to_string(type);
    ASSERT_FALSE(detail::ShapeTableAccess::one_type(mixed)) << to_string(type);
    PairBatch batch;
    const std::uint32_t invalid[] = {999, 0x80000000u, 0xffffffffu};
    for (std::size_t i = 0; i < 3000; ++i) {
      const auto a = static_cast<std::uint32_t>(rng() % 5), b = static_cast<std::uint32_t>(rng() % 5);
      const Pose pa{testing::random_vector(rng), testing::random_rotation(rng)};
      const Pose pb{pa.translation + testing::random_unit_vector(rng) * testing::uniform(rng, 0, 0.5),
                    testing::random_rotation(rng)};
      // Pairs 2500.. (the third tile) hold invalid indices; the first two tiles are all valid.
      const bool bad = i >= 2500 && i % 97 == 0;
      batch.add(bad && i % 2 ? invalid[i % 3] : a, pa, bad && !(i % 2) ? invalid[i % 3] : b, pb);
    }
    for (const QueryLevel level : {QueryLevel::boolean, QueryLevel::witness}) {
      QueryOptions options;
      options.level = level;
      PairResults want, got;
      collide(mixed, batch, options, want);
      collide(one, batch, options, got);
      testing::expect_same_results(want, got, std::string(to_string(type)) + " " + to_string(level));
      std::size_t rejected = 0;
      for (std::size_t i = 0; i < batch.size(); ++i) rejected += got.status[i] == Status::invalid_input ? 1 : 0;
      EXPECT_EQ(rejected, 5u) << to_string(type);  // pairs 2522, 2619, 2716, 2813, 2910
    }
    // Index 5 == size(): the first invalid index of the one-type table.
    PairBatch edge;
    for (std::uint32_t k = 0; k < 4; ++k) edge.add(k, Pose{}, k + 1, Pose{Eigen::Vector3d(1, 0, 0), Eigen::Quaterniond::Identity()});
    edge.add(0, Pose{}, 5, Pose{});
    PairResults r;
    collide(one, edge, QueryOptions{}, r);
    for (std::size_t i = 0; i < 4; ++i) EXPECT_NE(r.status[i], Status::invalid_input) << to_string(type) << " " << i;
    EXPECT_EQ(r.status[4], Status::invalid_input) << to_string(type);
  }
}

TEST(Executor, EmptyBatchIsFine) {
  ShapeTable shapes;
  PairBatch batch;
  PairResults r;
  collide(shapes, batch, QueryOptions{}, r);
  EXPECT_EQ(r.size(), 0u);
}

}  // namespace
}  // namespace batchcol
