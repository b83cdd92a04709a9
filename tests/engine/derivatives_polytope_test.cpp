// Analytic derivatives of hull pairs: the contact features read from the vertices the normal exposes
// (exposed_feature()) and the polytope pairs solved in lanes (PolytopeLanes), on configurations whose features are
// known, and bitwise determinism over thread counts on batches of hulls only (whole lane blocks).
#include "batchcol/batchcol.hpp"
#include "support/derivative_reference.hpp"
#include "support/same_results.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

namespace batchcol::testing {
namespace {

std::vector<Eigen::Vector3d> cube_corners() {
  std::vector<Eigen::Vector3d> p;
  for (int k = 0; k < 8; ++k) p.emplace_back(k & 1 ? 1.0 : -1.0, k & 2 ? 1.0 : -1.0, k & 4 ? 1.0 : -1.0);
  return p;
}

struct Case {
  const char* what;
  Pose b;
  DerivativeStatus expected;
};

// Two 2 m cube hulls, a at the origin; b placed so that the closest features are known.
TEST(DerivativesPolytope, HullFeaturesAreTheOnesTheNormalExposes) {
  ShapeTable shapes;
  const auto cube = shapes.add(Shape::convex(cube_corners()));
  const double s3 = std::sqrt(3.0);
  const Eigen::Quaterniond quarter_turn(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d(1, 1, 0).normalized()));
  const Eigen::Quaterniond corner_first =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(-1, 0, 0));
  const Case cases[] = {
      // b's face x = -1 parallel to a's face x = 1: the witness points are not unique.
      {"face-face", Pose::from_translation({3.0, 0.2, 0.1}), DerivativeStatus::nonsmooth},
      // a's edge (1, 1, z) and b's edge (2, 2, z): parallel edges.
      {"parallel edges", Pose::from_translation({3.0, 3.0, 0.3}), DerivativeStatus::nonsmooth},
      // b turned a quarter about (1, 1, 0): its edge between the faces facing a, (2, 2, 0.3) + t (1, -1, 0), crosses
      // over a's edge (1, 1, z).
      {"crossing edges", {{3.0, 3.0, 0.3}, quarter_turn}, DerivativeStatus::smooth},
      // b's corner (-1, -1, -1) turned to -x, at (1.5, 0.2, 0.1) over a's face x = 1.
      {"vertex-face", {{1.5 + s3, 0.2, 0.1}, corner_first}, DerivativeStatus::zero_curvature},
      // corner (1, 1, 1) against corner (2, 2, 2).
      {"vertex-vertex", Pose::from_translation({3.0, 3.0, 3.0}), DerivativeStatus::zero_curvature},
  };
  PairBatch batch;
  for (const Case& c : cases) batch.add(cube, Pose::identity(), cube, c.b);
  QueryOptions q;
  q.level = QueryLevel::witness;
  PairResults r;
  DerivativeResults d;
  differentiate(shapes, batch, q, DerivativeOptions{}, r, d);
  for (std::size_t i = 0; i < batch.size(); ++i) {
    SCOPED_TRACE(cases[i].what);
    ASSERT_EQ(r.status[i], Status::converged);
    EXPECT_EQ(to_string(d.status[i]), std::string(to_string(cases[i].expected)));
    EXPECT_TRUE(d.distance_gradient_b[i].allFinite());
    const bool defined = cases[i].expected != DerivativeStatus::nonsmooth;
    EXPECT_EQ(d.witness_a_wrt_b[i].allFinite(), defined);
  }
  // Crossing edges: b's twist moves a's witness along a's edge (z) by b's edge's motion, the point where they cross;
  // a translation of b along z carries the crossing point with it (d witness_a_z / d v_z = 1), one along b's edge
  // does not move it.
  const Mat36 J = d.witness_a_wrt_b[2];
  EXPECT_NEAR(J(2, 2), 1.0, 1e-12);
  EXPECT_NEAR(J(2, 0) - J(2, 1), 0.0, 1e-12);  // along (1, -1, 0)
  EXPECT_NEAR(J(0, 2), 0.0, 1e-12);           // a's witness stays on its edge (x = y = 1)
  EXPECT_NEAR(J(1, 2), 0.0, 1e-12);
  // Vertex-face: b's vertex is the witness on b and moves rigidly with b; a's witness slides with it on the face.
  const Mat36 Jb = d.witness_b_wrt_b[3], Ja = d.witness_a_wrt_b[3];
  EXPECT_NEAR(Jb(0, 0), 1.0, 1e-12);
  EXPECT_NEAR(Ja(1, 1), 1.0, 1e-12);
  EXPECT_NEAR(Ja(0, 0), 0.0, 1e-12);  // not off the face
}

// Hulls only: every 8-pair block is a whole block of polytope lanes, written straight to the output arrays, and the
// task ranges split the batch differently for each thread count.
TEST(DerivativesPolytope, HullPairsBitwiseIdenticalForAnyThreadCount) {
  Rng rng(19);
  ShapeTable shapes;
  const PairBatch batch = random_separated_pairs(rng, shapes, {ShapeType::convex}, 1201);
  DerivativeResults d[3];
  PairResults r;
  QueryOptions q;
  const int threads[3] = {1, 2, 3};
  for (int k = 0; k < 3; ++k) {
    q.threads = threads[k];
    differentiate(shapes, batch, q, DerivativeOptions{}, r, d[k]);
  }
  int defined = 0;
  for (std::size_t i = 0; i < batch.size(); ++i) defined += d[0].status[i] != DerivativeStatus::no_witness;
  EXPECT_GE(defined, 1150);
  for (int k = 1; k < 3; ++k) {
    expect_same_derivatives(d[0], d[k], "threads " + std::to_string(threads[k]));
  }
}

// PolytopeLanes / SmoothLanes solve a whole block of 8 pairs in one AVX-512 register (two AVX2 registers) and every
// other block two lanes per SSE2 register (derivative_lanes.inl): analytic hull pairs (PolytopeLanes), analytic
// ellipsoid pairs (SmoothLanes with the curvature formula and its square roots) and smoothed1 pairs (SmoothLanes
// with H0) must give the scalar set's bits on every set, in whole blocks (1200 pairs of one type; the wide lanes) and
// in blocks mixed with other shape types (partial lane sets, columns out of order: the SSE2 lanes on every set).
TEST(DerivativesPolytope, WholeBlocksGiveTheSameBitsOnEveryInstructionSet) {
  Rng rng(23);
  ShapeTable shapes;
  const PairBatch hulls = random_separated_pairs(rng, shapes, {ShapeType::convex}, 1200);
  const PairBatch ellipsoids = random_separated_pairs(rng, shapes, {ShapeType::ellipsoid}, 1200);
  const PairBatch mixed = random_separated_pairs(rng, shapes, bounded_shape_types(), 600);
  // smoothed1 at M = 4 (whole AVX2 registers of samples), odd M = 3 and 5 (the masked tails of the AVX2 sample
  // differences and sums) and M = 16 (the small-hull scan's multi-register path); a quarter of the a-sides are
  // inflated (the scan followed by the swept radius).
  DerivativeOptions analytic, smoothed1[4];
  const int samples[4] = {4, 3, 5, 16};
  for (int k = 0; k < 4; ++k) {
    smoothed1[k].method = DerivativeMethod::smoothed1;
    smoothed1[k].samples = samples[k];
    smoothed1[k].seed = 3;
  }
  if (vector_isas_here().empty()) GTEST_SKIP() << "no AVX2 or AVX-512 on this CPU: nothing to compare with scalar";
  int compared = 0;
  for (const PairBatch* batch : {&hulls, &ellipsoids, &mixed})
    for (const DerivativeOptions* o : {&analytic, &smoothed1[0], &smoothed1[1], &smoothed1[2], &smoothed1[3]}) {
      PairResults r;
      QueryOptions q;
      q.isa = InstructionSet::scalar;
      DerivativeResults reference;
      differentiate(shapes, *batch, q, *o, r, reference);
      // Most pairs get finite derivatives through the lanes (hull pairs with a vertex side are zero_curvature).
      int solved = 0;
      for (const DerivativeStatus s : reference.status)
        solved += s == DerivativeStatus::smooth || s == DerivativeStatus::zero_curvature;
      EXPECT_GE(solved, int(batch->size() * 9 / 10));
      for (InstructionSet isa : vector_isas_here()) {
        ++compared;
        q.isa = isa;
        DerivativeResults d;
        differentiate(shapes, *batch, q, *o, r, d);
        const std::string label = std::string(to_string(isa)) +
                                  (o == &analytic ? " analytic" : " smoothed1 M = " + std::to_string(o->samples));
        expect_same_derivatives(reference, d, label);
      }
    }
  std::printf("%d (batch, method, instruction set) runs compared with scalar\n", compared);
}

}  // namespace
}  // namespace batchcol::testing
