// Pair placement of the testkit (tools/testkit/bench_pairs.hpp): every pair lands in its regime at the reference
// distance it records (checked by an independent collide() call), reproducibly from the seed; bad specs throw.
#include "testkit/bench_pairs.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace batchcol::testkit {
namespace {

TEST(BenchPairs, PlacesEveryPairAtItsRecordedReferenceInsideTheRegime) {
  for (const char* spec : {"box-cylinder", "convex8-ellipsoid", "cone-capsule"}) {
    for (Regime regime : {Regime::distant, Regime::close, Regime::overlap}) {
      const BenchCase bench_case = parse_bench_cases(spec)[0];
      const BenchPairs p = make_bench_pairs(bench_case, regime, 48, 3, 2);
      ASSERT_EQ(p.pairs.size(), 48u);
      ASSERT_EQ(p.reference.size(), 48u);
      PairResults r;
      collide(p.shapes, p.pairs, reference_options(1), r);
      const DistanceRange range = regime_range(regime);
      for (std::size_t i = 0; i < p.pairs.size(); ++i) {
        EXPECT_EQ(p.shapes[p.pairs.shape_a[i]].type, bench_case.a.type);
        EXPECT_EQ(p.shapes[p.pairs.shape_b[i]].type, bench_case.b.type);
        // Placement stops within 0.1% of a target drawn inside the range.
        EXPECT_GE(p.reference[i], range.lo - 1e-3 * std::abs(range.lo)) << spec << " pair " << i;
        EXPECT_LE(p.reference[i], range.hi + 1e-3 * std::abs(range.hi)) << spec << " pair " << i;
        ASSERT_EQ(r.status[i], Status::converged) << spec << " pair " << i;
        // The same reference query on one thread gives the recorded value (results are thread-count independent).
        EXPECT_EQ(r.distance[i], p.reference[i]) << spec << " pair " << i;
      }
    }
  }
}

TEST(BenchPairs, SameSeedSamePairs) {
  const BenchCase c = parse_bench_cases("sphere-convex8")[0];
  const BenchPairs a = make_bench_pairs(c, Regime::close, 32, 17, 2), b = make_bench_pairs(c, Regime::close, 32, 17, 1);
  ASSERT_EQ(a.pairs.size(), b.pairs.size());
  EXPECT_EQ(a.reference, b.reference);
  EXPECT_EQ(a.pairs.translation_b.x, b.pairs.translation_b.x);
  EXPECT_EQ(a.pairs.rotation_a.w, b.pairs.rotation_a.w);
  const BenchPairs other = make_bench_pairs(c, Regime::close, 32, 18, 2);
  EXPECT_NE(a.reference, other.reference);
}

TEST(BenchPairs, ParsesCasesAndRejectsBadOnes) {
  const auto all = parse_bench_cases("all");
  EXPECT_EQ(all.size(), 7u * 8u / 2u + 2u);  // unordered pairs of the seven kinds, plus the two large hulls
  EXPECT_EQ(all.back().name(), "convex940-convex940");
  EXPECT_EQ(parse_bench_cases("convex-box")[0].a.hull_vertices, 8);
  EXPECT_EQ(parse_regime("overlap"), Regime::overlap);
  EXPECT_STREQ(to_string(Regime::distant), "distant");
  EXPECT_THROW(parse_bench_cases("sphere"), InputError);
  EXPECT_THROW(parse_bench_cases("sphere-box-cone"), InputError);
  EXPECT_THROW(parse_bench_cases("sphere-torus"), InputError);
  EXPECT_THROW(parse_regime("near"), InputError);
}

}  // namespace
}  // namespace batchcol::testkit
