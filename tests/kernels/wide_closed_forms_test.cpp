// SIMD closed forms for sphere/capsule pairs (kernels/simd/wide_segments.inl, run by the executor): every lane
// equals the scalar closed form on world segments, partial and scattered blocks included; invalid input and
// touching cores go to the scalar path; every instruction set gives bitwise the same results.
#include "kernels/closed_forms.hpp"
#include "kernels/segment_pairs_world.hpp"
#include "kernels/simd/wide_gjk.hpp"
#include "shape_table_access.hpp"  // engine/src: OwnedShapeView
#include "support/generators.hpp"
#include "support/same_results.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace batchcol {
namespace {

using testing::Rng;

Eigen::Vector3d random_point(Rng& rng, double half_width) {
  return {testing::uniform(rng, -half_width, half_width), testing::uniform(rng, -half_width, half_width),
          testing::uniform(rng, -half_width, half_width)};
}

struct Batch {
  ShapeTable shapes;
  PairBatch pairs;
};

/// Spheres and capsules mixed with boxes (so that the sphere/capsule groups of a tile are scattered), plus the
/// hard lanes: bad quaternions, out-of-range shapes, non-finite translations, crossing capsule axes (touching
/// cores), concentric spheres. 2500 pairs = 2 full tiles and a partial one.
Batch mixed_batch(std::uint64_t seed) {
  Rng rng(seed);
  Batch b;
  std::vector<std::uint32_t> round, other;
  for (int k = 0; k < 4; ++k) round.push_back(b.shapes.add(Shape::sphere(testing::uniform(rng, 0.01, 0.3))));
  for (int k = 0; k < 4; ++k)
    round.push_back(b.shapes.add(Shape::capsule(testing::uniform(rng, 0.01, 0.2), testing::uniform(rng, 0.01, 0.3))));
  round.push_back(b.shapes.add(Shape::capsule(0.1, 0.2).inflated(0.05)));
  other.push_back(b.shapes.add(Shape::box(0.1, 0.2, 0.3)));
  const std::uint32_t sphere = round[0], capsule = round[5];
  for (std::size_t i = 0; i < 2500; ++i) {
    const bool scattered = i % 7 == 3;
    const std::uint32_t a = scattered ? other[0] : round[rng() % round.size()];
    const std::uint32_t c = round[rng() % round.size()];
    Pose pa{random_point(rng, 2.0), testing::random_rotation(rng)};
    Pose pb{pa.translation + testing::random_unit_vector(rng) * testing::uniform(rng, 0, 0.8),
            testing::random_rotation(rng)};
    std::uint32_t sa = a, sb = c;
    switch (i % 97) {
      case 5: pa.rotation.coeffs() *= 1.01; break;                             // not unit
      case 6: pb.rotation.coeffs()[1] = std::nan(""); break;                  // NaN
      case 7: sb = 1000; break;                                               // no such shape
      case 8: pa.translation.y() = INFINITY; break;                           // non-finite
      case 9: sa = sb = capsule, pb.translation = pa.translation; break;      // crossing axes: cores touch
      case 10: sa = sb = sphere, pb.translation = pa.translation; break;     // concentric
      default: break;
    }
    b.pairs.add(sa, pa, sb, pb);
  }
  return b;
}

TEST(WideClosedForms, SphereCapsuleLanesEqualTheScalarClosedForm) {
  const Batch b = mixed_batch(7);
  for (QueryLevel level : {QueryLevel::boolean, QueryLevel::distance, QueryLevel::witness}) {
    QueryOptions o;
    o.level = level;
    o.margin = 0.01;
    PairResults r;
    collide(b.shapes, b.pairs, o, r);
    std::size_t checked = 0, invalid = 0;
    for (std::size_t i = 0; i < b.pairs.size(); ++i) {
      const std::uint32_t ia = b.pairs.shape_a[i], ib = b.pairs.shape_b[i];
      const Eigen::Quaterniond qa = b.pairs.rotation_a[i], qb = b.pairs.rotation_b[i];
      const Eigen::Vector3d ta = b.pairs.translation_a[i], tb = b.pairs.translation_b[i];
      if (ia >= b.shapes.size() || ib >= b.shapes.size() || !is_unit_quaternion(qa) || !is_unit_quaternion(qb) ||
          !ta.allFinite() || !tb.allFinite()) {
        EXPECT_EQ(r.status[i], Status::invalid_input) << "pair " << i;
        EXPECT_TRUE(r.distance.empty() || std::isnan(r.distance[i]));
        ++invalid;
        continue;
      }
      if (!kernels::is_segment_shape(b.shapes[ia].type) || !kernels::is_segment_shape(b.shapes[ib].type)) continue;
      const OwnedShapeView va(b.shapes[ia]), vb(b.shapes[ib]);
      const kernels::WorldSegment A = kernels::world_segment(va.view, qa.normalized(), ta);
      const kernels::WorldSegment B = kernels::world_segment(vb.view, qb.normalized(), tb);
      const kernels::PairOutput<double> ref =
          kernels::segments_with_radii<double>(A.p0, A.p1, B.p0, B.p1, A.radius, B.radius, tb - ta);
      ASSERT_EQ(r.status[i], Status::converged) << "pair " << i;
      EXPECT_EQ(r.collide[i] != 0, ref.distance <= o.margin) << "pair " << i;
      EXPECT_EQ(r.distance.empty(), level < QueryLevel::distance);  // not computed: no array at all
      EXPECT_EQ(r.witness_a.x.empty(), level < QueryLevel::witness);
      EXPECT_TRUE(std::isnan(r.direction.x[i]));  // closed forms have no search direction
      if (level >= QueryLevel::distance) { EXPECT_NEAR(r.distance[i], ref.distance, 1e-14) << "pair " << i; }
      if (level >= QueryLevel::witness) {
        // The normal is (cb - ca) / |cb - ca|: a few ulps of the coordinates in the closest points, divided by
        // the core distance. The witness points add the radius times that; the closest points themselves agree
        // to ~100 ulps of the coordinates (more for nearly parallel segments, whose parameters are ill-conditioned).
        const double core = ref.distance + A.radius + B.radius;
        const double normal_bound = 4e-16 * (1 + ta.norm() + tb.norm()) * 8 / core;
        EXPECT_LT((r.normal[i] - ref.normal).norm(), normal_bound) << "pair " << i;
        EXPECT_LT((r.witness_a[i] - ref.witness_a).norm(), 1e-13 + A.radius * normal_bound) << "pair " << i;
        EXPECT_LT((r.witness_b[i] - ref.witness_b).norm(), 1e-13 + B.radius * normal_bound) << "pair " << i;
      }
      ++checked;
    }
    EXPECT_GT(checked, 1500u);
    EXPECT_GE(invalid, 4 * 25u);
  }
}

/// Box-box pairs with random rotations, one in five against a sphere (scattered groups), inflated boxes (the
/// scalar path answers them), a few invalid lanes, and exact face-to-face contacts every 50th pair.
Batch box_batch(std::uint64_t seed) {
  Rng rng(seed);
  Batch b;
  std::vector<std::uint32_t> boxes;
  for (int k = 0; k < 6; ++k) boxes.push_back(b.shapes.add(testing::random_shape(rng, ShapeType::box)));
  boxes.push_back(b.shapes.add(Shape::box(0.1, 0.2, 0.3).inflated(0.02)));
  const std::uint32_t sphere = b.shapes.add(Shape::sphere(0.1));
  const std::uint32_t plain = b.shapes.add(Shape::box(0.1, 0.2, 0.3));
  for (std::size_t i = 0; i < 3000; ++i) {
    Pose pa{random_point(rng, 1.0), testing::random_rotation(rng)};
    Pose pb{pa.translation + testing::random_unit_vector(rng) * testing::uniform(rng, 0, 0.6),
            testing::random_rotation(rng)};
    std::uint32_t sa = boxes[rng() % boxes.size()], sb = boxes[rng() % boxes.size()];
    if (i % 5 == 2) sb = sphere;
    if (i % 50 == 7) {  // faces x = +0.1 of A and x = -0.1 of B coincide: touching counts as colliding
      sa = sb = plain;
      pa = Pose::from_translation({0.25, -1.5, 0.125});
      pb = Pose::from_translation({0.45, -1.5, 0.125});
    }
    if (i % 97 == 5) pa.rotation.coeffs() *= 1.01;
    if (i % 97 == 6) sb = 1000;
    b.pairs.add(sa, pa, sb, pb);
  }
  return b;
}

TEST(WideClosedForms, BoxBoxLanesAgreeWithTheScalarSatAndGjkAndCountTouching) {
  const Batch b = box_batch(3);
  QueryOptions sat;
  sat.level = QueryLevel::boolean;
  QueryOptions gjk;
  gjk.level = QueryLevel::witness;
  gjk.closed_forms = false;
  gjk.tolerance = 1e-12;
  PairResults fast, reference;
  collide(b.shapes, b.pairs, sat, fast);
  collide(b.shapes, b.pairs, gjk, reference);
  std::size_t compared = 0, colliding = 0, touching = 0, scalar_compared = 0;
  for (std::size_t i = 0; i < b.pairs.size(); ++i) {
    ASSERT_EQ(fast.status[i] == Status::invalid_input, reference.status[i] == Status::invalid_input) << i;
    if (fast.status[i] == Status::invalid_input) continue;
    if (i % 50 == 7) {
      EXPECT_EQ(fast.collide[i], 1) << "touching boxes, pair " << i;
      ++touching;
      continue;
    }
    // Within rounding of touching either answer is right.
    if (!reference.collide[i] && reference.distance[i] < 1e-9) continue;
    EXPECT_EQ(fast.collide[i], reference.collide[i]) << "pair " << i << " distance " << reference.distance[i];
    // The scalar reference of the same test, in A's frame (only plain box-box pairs run it).
    const Shape& a = b.shapes[b.pairs.shape_a[i]];
    const Shape& c = b.shapes[b.pairs.shape_b[i]];
    if (a.type == ShapeType::box && c.type == ShapeType::box && a.inflation == 0 && c.inflation == 0) {
      const Eigen::Matrix3d Ra = b.pairs.rotation_a[i].normalized().toRotationMatrix();
      kernels::Transform<double> b_in_a;
      b_in_a.R = Ra.transpose() * b.pairs.rotation_b[i].normalized().toRotationMatrix();
      b_in_a.t = Ra.transpose() * (b.pairs.translation_b[i] - b.pairs.translation_a[i]);
      EXPECT_EQ(fast.collide[i] != 0, kernels::boxes_intersect<double>(a.size, c.size, b_in_a)) << "pair " << i;
      ++scalar_compared;
    }
    ++compared;
    colliding += fast.collide[i];
  }
  EXPECT_GE(touching, 55u);  // 60 minus those made invalid
  EXPECT_GT(scalar_compared, 1500u);
  EXPECT_GT(colliding, 300u);
  EXPECT_GT(compared - colliding, 300u);
}

TEST(WideClosedForms, ReusedResultsKeepNothingOfTheLevelBefore) {
  // Results are sized, not pre-filled: each kernel writes every computed field of its pairs. A first call at the
  // penetration level fills the arrays with numbers; the next calls at lower levels must leave none behind: the
  // arrays they do not compute are emptied, and the ones they keep are rewritten.
  for (const bool boxes : {false, true}) {
    const Batch b = boxes ? box_batch(17) : mixed_batch(19);
    PairResults r;
    QueryOptions o;
    o.level = QueryLevel::penetration;
    collide(b.shapes, b.pairs, o, r);
    for (QueryLevel level : {QueryLevel::boolean, QueryLevel::distance}) {
      o.level = level;
      collide(b.shapes, b.pairs, o, r);
      std::size_t closed = 0;
      for (std::size_t i = 0; i < b.pairs.size(); ++i) {
        EXPECT_EQ(r.distance.size(), level == QueryLevel::boolean ? 0 : b.pairs.size());
        for (auto m : {&PairResults::witness_a, &PairResults::witness_b, &PairResults::normal})
          EXPECT_TRUE((r.*m).x.empty() && (r.*m).y.empty() && (r.*m).z.empty()) << i;
        if (r.status[i] != Status::invalid_input && level == QueryLevel::distance && !r.collide[i]) {
          EXPECT_FALSE(std::isnan(r.distance[i])) << i;  // separated: computed
        }
        const std::uint32_t ia = b.pairs.shape_a[i], ib = b.pairs.shape_b[i];
        if (r.status[i] == Status::invalid_input) {
          EXPECT_EQ(r.collide[i], 0) << i;
          EXPECT_EQ(r.iterations[i], 0) << i;
          EXPECT_TRUE(std::isnan(r.direction.x[i])) << i;
          continue;
        }
        if (kernel_for(b.shapes[ia], b.shapes[ib], o) == std::string("closed form")) {
          EXPECT_TRUE(std::isnan(r.direction.x[i]) && std::isnan(r.direction.z[i])) << i;
          EXPECT_EQ(r.iterations[i], 0) << i;
          ++closed;
        }
      }
      EXPECT_GT(closed, 400u);  // box-box at the distance level runs GJK: only the sphere-box pairs remain
      // Nothing of the penetration call survives (e.g. an overlapping GJK pair's EPA depth at the distance level):
      // the reused results equal fresh ones bit for bit.
      PairResults fresh;
      collide(b.shapes, b.pairs, o, fresh);
      testing::expect_same_results(fresh, r, std::string("reused at ") + to_string(level));
    }
  }
}

TEST(WideClosedForms, EveryInstructionSetThisCpuRunsGivesTheSameBits) {
  if (!kernels::simd::cpu_has(InstructionSet::avx2))
    GTEST_SKIP() << "this CPU runs only the scalar kernels: no wide set to compare with the scalar one";
  for (const bool boxes : {false, true}) {
    const Batch b = boxes ? box_batch(13) : mixed_batch(11);
    QueryOptions o;
    o.level = boxes ? QueryLevel::boolean : QueryLevel::witness;
    o.isa = InstructionSet::scalar;
    PairResults reference;
    collide(b.shapes, b.pairs, o, reference);
    for (InstructionSet isa : {InstructionSet::avx2, InstructionSet::avx512}) {
      if (!kernels::simd::cpu_has(isa)) continue;
      o.isa = isa;
      PairResults r;
      collide(b.shapes, b.pairs, o, r);
      testing::expect_same_results(reference, r, to_string(isa));
    }
  }
}

}  // namespace
}  // namespace batchcol
