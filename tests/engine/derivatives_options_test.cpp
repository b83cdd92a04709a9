// Derivative options, levels and statuses at the API boundary; determinism and the rigid-motion identity.
#include "batchcol/batchcol.hpp"
#include "support/derivative_reference.hpp"
#include "support/same_results.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <utility>

namespace batchcol::testing {
namespace {

struct Fixture {
  ShapeTable shapes;
  PairBatch batch;
  Fixture() {
    const auto s = shapes.add(Shape::sphere(0.2));
    const auto e = shapes.add(Shape::ellipsoid(0.1, 0.2, 0.3));
    batch.add(s, Pose::identity(), e, Pose::from_translation({1, 0, 0}));
  }
};

void expect_input_error(const ShapeTable& shapes, const PairBatch& batch, const QueryOptions& q,
                        const DerivativeOptions& o, const std::string& field) {
  PairResults r;
  DerivativeResults d;
  try {
    differentiate(shapes, batch, q, o, r, d);
    ADD_FAILURE() << "no InputError for " << field;
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(field), std::string::npos) << error.what();
  }
}

TEST(DerivativesOptions, BadOptionsAreInputErrorsNamingTheOption) {
  Fixture f;
  QueryOptions q;
  DerivativeOptions o;
  o.method = DerivativeMethod::smoothed0;
  o.samples = 0;
  expect_input_error(f.shapes, f.batch, q, o, "samples");
  o.samples = -3;
  expect_input_error(f.shapes, f.batch, q, o, "samples");
  o.samples = kMaxDerivativeSamples + 1;  // above the documented limit
  expect_input_error(f.shapes, f.batch, q, o, "samples");
  o.samples = 8;
  for (double bad : {0.0, -1e-3, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    o.noise = bad;
    expect_input_error(f.shapes, f.batch, q, o, "noise");
  }
  o.noise = 1e-2;
  for (QueryLevel level : {QueryLevel::boolean, QueryLevel::distance}) {
    q.level = level;
    expect_input_error(f.shapes, f.batch, q, o, "level");
  }
  q.level = QueryLevel::witness;
  PairResults r;
  collide(f.shapes, f.batch, q, r);
  DerivativeResults d;
  EXPECT_THROW(differentiate_results(f.shapes, f.batch, r, o, 0, d), InputError);  // smoothed0 needs queries
  o.method = DerivativeMethod::analytic;
  q.level = QueryLevel::distance;
  collide(f.shapes, f.batch, q, r);
  EXPECT_THROW(differentiate_results(f.shapes, f.batch, r, o, 0, d), InputError);  // no witness arrays
}

TEST(DerivativesOptions, PairsWithoutWitnessAreFlaggedNotThrown) {
  ShapeTable shapes;
  const auto s = shapes.add(Shape::ellipsoid(0.5, 0.5, 0.5));  // a sphere by GJK (no closed form, no EPA below
                                                                // the penetration level)
  const auto h = shapes.add(Shape::halfspace({0, 0, 1}, 0));
  PairBatch batch;
  batch.add(s, Pose::identity(), s, Pose::from_translation({0.5, 0, 0}));  // overlapping, witness level
  batch.add(s, Pose::identity(), 7, Pose::identity());                      // invalid shape index
  batch.add(s, Pose::from_translation({0, 0, 2}), h, Pose::identity());     // halfspace
  batch.add(s, Pose::identity(), s, Pose::from_translation({0.5, 0, 0}));  // overlapping, penetration below
  for (DerivativeMethod m : {DerivativeMethod::analytic, DerivativeMethod::smoothed0, DerivativeMethod::smoothed1}) {
    DerivativeOptions o;
    o.method = m;
    o.samples = 1024;  // smoothed0's gradient below has a standard error of sqrt(2 / M) ~ 0.044
    PairResults r;
    DerivativeResults d;
    differentiate(shapes, batch, QueryOptions{}, o, r, d);
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_EQ(d.status[i], DerivativeStatus::no_witness) << to_string(m) << " pair " << i;
      EXPECT_TRUE(std::isnan(d.distance_gradient_b[i](0)));
    }
    QueryOptions penetration;
    penetration.level = QueryLevel::penetration;
    differentiate(shapes, batch, penetration, o, r, d);
    EXPECT_EQ(d.status[3], DerivativeStatus::smooth) << to_string(m);
    // EPA's normal on this GJK-handled sphere is ~1e-4 rad off (its tolerance on a curved Minkowski difference),
    // so the gradient's x component is 1 - O(1e-8).
    EXPECT_NEAR(d.distance_gradient_b[3](0), 1.0, m == DerivativeMethod::smoothed0 ? 0.2 : 1e-7);
  }
}

// Moving both shapes by one twist is a rigid motion of the scene: J_a + J_b is the rigid motion of the point
// ([I, -[x]x]), of the normal ([0, -[n]x]), and the distance gradients cancel. Both sides are computed
// independently by the analytic and first-order formulas, so this checks them on every shape type.
TEST(DerivativesOptions, RigidMotionIdentityHoldsForEveryShapeType) {
  Rng rng(7);
  ShapeTable shapes;
  const PairBatch batch = random_separated_pairs(rng, shapes, bounded_shape_types(), 2000);
  for (DerivativeMethod m : {DerivativeMethod::analytic, DerivativeMethod::smoothed1}) {
    DerivativeOptions o;
    o.method = m;
    PairResults r;
    DerivativeResults d;
    differentiate(shapes, batch, QueryOptions{}, o, r, d);
    int checked = 0;
    for (std::size_t i = 0; i < batch.size(); ++i) {
      if (d.status[i] != DerivativeStatus::smooth && d.status[i] != DerivativeStatus::zero_curvature) continue;
      ++checked;
      const auto skew = [](const Eigen::Vector3d& x) {
        Eigen::Matrix3d s;
        s << 0, -x.z(), x.y(), x.z(), 0, -x.x(), -x.y(), x.x(), 0;
        return s;
      };
      Mat36 rigid_a, rigid_b, rigid_n;
      rigid_a << Eigen::Matrix3d::Identity(), -skew(r.witness_a[i]);
      rigid_b << Eigen::Matrix3d::Identity(), -skew(r.witness_b[i]);
      rigid_n << Eigen::Matrix3d::Zero(), -skew(r.normal[i]);
      const double scale = 1.0 + batch.translation_a[i].norm() + batch.translation_b[i].norm();
      EXPECT_LE((d.distance_gradient_a[i] + d.distance_gradient_b[i]).cwiseAbs().maxCoeff(), 1e-12 * scale);
      EXPECT_LE((d.witness_a_wrt_a[i] + d.witness_a_wrt_b[i] - rigid_a).cwiseAbs().maxCoeff(), 1e-9 * scale) << i;
      EXPECT_LE((d.witness_b_wrt_a[i] + d.witness_b_wrt_b[i] - rigid_b).cwiseAbs().maxCoeff(), 1e-9 * scale) << i;
      EXPECT_LE((d.normal_wrt_a[i] + d.normal_wrt_b[i] - rigid_n).cwiseAbs().maxCoeff(), 1e-9 * scale) << i;
    }
    EXPECT_GE(checked, 1500) << to_string(m);
  }
}

TEST(DerivativesOptions, BitwiseIdenticalForAnyThreadCount) {
  Rng rng(11);
  ShapeTable shapes;
  const PairBatch batch = random_separated_pairs(rng, shapes, bounded_shape_types(), 600);
  for (DerivativeMethod m : {DerivativeMethod::analytic, DerivativeMethod::smoothed0, DerivativeMethod::smoothed1}) {
    DerivativeOptions o;
    o.method = m;
    o.samples = 7;  // odd: the last sample keeps the baseline
    o.seed = 42;
    DerivativeResults d1, d2;
    PairResults r;
    QueryOptions q;
    q.threads = 1;
    differentiate(shapes, batch, q, o, r, d1);
    q.threads = 2;
    differentiate(shapes, batch, q, o, r, d2);
    EXPECT_EQ(d1.status, d2.status);
    EXPECT_TRUE(same_bits(d1.distance_gradient_b.data, d2.distance_gradient_b.data)) << to_string(m);
    EXPECT_TRUE(same_bits(d1.witness_a_wrt_b.data, d2.witness_a_wrt_b.data)) << to_string(m);
    EXPECT_TRUE(same_bits(d1.normal_wrt_a.data, d2.normal_wrt_a.data)) << to_string(m);
    EXPECT_TRUE(same_bits(d1.smoothed_distance, d2.smoothed_distance)) << to_string(m);
    // Another seed gives other samples (smoothed methods only).
    o.seed = 43;
    differentiate(shapes, batch, q, o, r, d2);
    EXPECT_EQ(same_bits(d1.witness_a_wrt_b.data, d2.witness_a_wrt_b.data), m == DerivativeMethod::analytic);
  }
}

// smoothed0 maps its estimator to the world 8 pairs at a time, one pair per SIMD lane, in code compiled for each
// instruction set (engine/src/derivative_finish_lanes.inl), flushed early where a pair without witness (here a
// halfspace pair every 11 pairs, at every lane position) breaks a run of consecutive pairs: every set must give
// the same bits, and each lane's a-twist blocks must be its own rigid motion minus its own b-twist block, exactly as
// the mapping computes them ([I, -[x]x] - J_b with the pair's smoothed witness point x; [0, -[n]x] - J_b for the
// normal), which a lane mixed up with another pair's would break.
TEST(DerivativesOptions, Smoothed0SameBitsOnEveryInstructionSetAndEachLaneItsOwnPair) {
  Rng rng(13);
  ShapeTable shapes;
  const PairBatch separated = random_separated_pairs(rng, shapes, bounded_shape_types(), 300);
  const auto h = shapes.add(Shape::halfspace({0, 0, 1}, 0));
  PairBatch batch;
  for (std::size_t i = 0; i < separated.size(); ++i) {
    if (i % 11 == 5) batch.add(separated.shape_a[i], Pose::from_translation({0, 0, 3}), h, Pose::identity());
    batch.add(separated.shape_a[i], separated.pose_a(i), separated.shape_b[i], separated.pose_b(i));
  }
  const auto skew = [](const Eigen::Vector3d& x) {
    Eigen::Matrix3d m;
    m << 0, -x.z(), x.y(), x.z(), 0, -x.x(), -x.y(), x.x(), 0;
    return m;
  };
  for (int samples : {4, 7}) {  // 4: several pairs per sample register; 7: pair by pair
    DerivativeOptions o;
    o.method = DerivativeMethod::smoothed0;
    o.samples = samples;
    o.seed = 5;
    DerivativeResults reference;
    PairResults r;
    QueryOptions q;
    q.isa = InstructionSet::scalar;
    differentiate(shapes, batch, q, o, r, reference);
    int checked = 0;
    for (std::size_t i = 0; i < batch.size(); ++i) {
      if (reference.status[i] != DerivativeStatus::smooth) continue;
      ++checked;
      Mat36 rigid_a, rigid_b, rigid_n;
      rigid_a << Eigen::Matrix3d::Identity(), -skew(reference.smoothed_witness_a[i]);
      rigid_b << Eigen::Matrix3d::Identity(), -skew(reference.smoothed_witness_b[i]);
      rigid_n << Eigen::Matrix3d::Zero(), -skew(reference.smoothed_normal[i]);
      const Mat36 a_a = rigid_a - reference.witness_a_wrt_b[i], b_a = rigid_b - reference.witness_b_wrt_b[i],
                  n_a = rigid_n - reference.normal_wrt_b[i];
      EXPECT_EQ(std::memcmp(a_a.data(), reference.witness_a_wrt_a[i].data(), sizeof(Mat36)), 0) << i;
      EXPECT_EQ(std::memcmp(b_a.data(), reference.witness_b_wrt_a[i].data(), sizeof(Mat36)), 0) << i;
      EXPECT_EQ(std::memcmp(n_a.data(), reference.normal_wrt_a[i].data(), sizeof(Mat36)), 0) << i;
      const Row6 minus_b = -reference.distance_gradient_b[i];
      EXPECT_EQ(std::memcmp(minus_b.data(), reference.distance_gradient_a[i].data(), sizeof(Row6)), 0) << i;
    }
    EXPECT_GE(checked, 250) << samples;
    for (std::size_t i = 5; i < batch.size(); i += 12) EXPECT_EQ(reference.status[i], DerivativeStatus::no_witness);
    int compared = 0;
    for (InstructionSet isa : vector_isas_here()) {
      ++compared;
      q.isa = isa;
      DerivativeResults d;
      differentiate(shapes, batch, q, o, r, d);
      expect_same_derivatives(reference, d, to_string(isa));
      EXPECT_TRUE(same_bits(d.smoothed_distance, reference.smoothed_distance)) << to_string(isa);
      for (const auto& [x, y] : {std::pair{&d.smoothed_witness_a, &reference.smoothed_witness_a},
                                 std::pair{&d.smoothed_witness_b, &reference.smoothed_witness_b},
                                 std::pair{&d.smoothed_normal, &reference.smoothed_normal}})
        EXPECT_TRUE(same_bits(x->x, y->x) && same_bits(x->y, y->y) && same_bits(x->z, y->z)) << to_string(isa);
    }
    std::printf("smoothed0 M = %d: %d pairs checked, %d instruction sets compared with scalar\n", samples, checked,
                compared);
  }
}

// DerivativeOptions::jacobians = false: the gradient of every pair is bitwise the full analytic derivative's (every
// shape type, separated and overlapping pairs at the penetration level, pairs without witness), the Jacobian arrays
// are empty, the status is smooth exactly where the full derivative gave a gradient, and a later full call on the
// same DerivativeResults fills the Jacobians again.
TEST(DerivativesOptions, GradientsOnlyAreTheFullDerivativesGradients) {
  Rng rng(5);
  ShapeTable shapes;
  PairBatch batch = random_separated_pairs(rng, shapes, bounded_shape_types(), 1500);
  const auto s = shapes.add(Shape::ellipsoid(0.5, 0.5, 0.5));
  batch.add(s, Pose::identity(), s, Pose::from_translation({0.5, 0, 0}));  // overlapping
  batch.add(s, Pose::identity(), 1u << 30, Pose::identity());              // invalid shape index
  const auto h = shapes.add(Shape::halfspace({0, 0, 1}, 0));
  batch.add(s, Pose::from_translation({0, 0, 2}), h, Pose::identity());  // halfspace
  for (QueryLevel level : {QueryLevel::witness, QueryLevel::penetration}) {
    QueryOptions q;
    q.level = level;
    DerivativeOptions full, gradients;
    gradients.jacobians = false;
    PairResults r;
    DerivativeResults d_full, d;
    differentiate(shapes, batch, q, full, r, d_full);
    differentiate(shapes, batch, q, gradients, r, d);
    ASSERT_EQ(d.size(), batch.size());
    EXPECT_TRUE(d.witness_a_wrt_a.data.empty() && d.witness_b_wrt_b.data.empty() && d.normal_wrt_b.data.empty());
    EXPECT_TRUE(d.smoothed_distance.empty());
    std::size_t computed = 0;
    for (std::size_t i = 0; i < batch.size(); ++i) {
      const bool given = d_full.status[i] != DerivativeStatus::no_witness;
      EXPECT_EQ(d.status[i], given ? DerivativeStatus::smooth : DerivativeStatus::no_witness) << i;
      computed += given;
      for (int k = 0; k < 6; ++k) {
        const double ga = d.distance_gradient_a[i](k), gb = d.distance_gradient_b[i](k);
        const double fa = d_full.distance_gradient_a[i](k), fb = d_full.distance_gradient_b[i](k);
        if (!given) {
          EXPECT_TRUE(std::isnan(ga) && std::isnan(gb)) << i;
          continue;
        }
        EXPECT_EQ(std::memcmp(&ga, &fa, sizeof ga), 0) << "pair " << i << " a" << k << ": " << ga << " vs " << fa;
        EXPECT_EQ(std::memcmp(&gb, &fb, sizeof gb), 0) << "pair " << i << " b" << k << ": " << gb << " vs " << fb;
      }
    }
    EXPECT_GE(computed, 1400u) << to_string(level);
    differentiate(shapes, batch, q, full, r, d);  // the same object, Jacobians again
    EXPECT_EQ(d.witness_a_wrt_a.data.size(), 18 * batch.size());
    EXPECT_EQ(d.status, d_full.status);
  }
  // Only analytic has a gradients-only path.
  DerivativeOptions o;
  o.jacobians = false;
  for (DerivativeMethod m : {DerivativeMethod::smoothed0, DerivativeMethod::smoothed1}) {
    o.method = m;
    expect_input_error(shapes, batch, QueryOptions{}, o, "jacobians");
  }
}

// The eight derivative output arrays start on a 64-byte line (CacheLineAllocator): a block of eight pairs of one row
// is then one whole-line store. Checked after differentiate() (which sizes them), resize(), a copy and a move, for
// pair counts that are and are not multiples of 8; malloc's 16-byte alignment would leave most of them 16, 32 or 48
// bytes into a line.
TEST(DerivativesOptions, OutputArraysStartOnCacheLines) {
  const auto on_line = [](const double* p) { return reinterpret_cast<std::uintptr_t>(p) % 64 == 0; };
  const auto expect_aligned = [&](const DerivativeResults& d, const std::string& label) {
    EXPECT_TRUE(on_line(d.distance_gradient_a.data.data()) && on_line(d.distance_gradient_b.data.data())) << label;
    for (const Mat36Array* m : {&d.witness_a_wrt_a, &d.witness_a_wrt_b, &d.witness_b_wrt_a, &d.witness_b_wrt_b,
                                &d.normal_wrt_a, &d.normal_wrt_b})
      EXPECT_TRUE(on_line(m->data.data())) << label;
  };
  Rng rng(8);
  ShapeTable shapes;
  const PairBatch all = random_separated_pairs(rng, shapes, bounded_shape_types(), 24);
  for (std::size_t n : {1u, 3u, 8u, 13u, 24u}) {
    PairBatch batch;
    for (std::size_t i = 0; i < n; ++i) batch.add(all.shape_a[i], all.pose_a(i), all.shape_b[i], all.pose_b(i));
    PairResults r;
    DerivativeResults d;
    differentiate(shapes, batch, QueryOptions{}, DerivativeOptions{}, r, d);
    expect_aligned(d, std::to_string(n) + " pairs, differentiate()");
    DerivativeResults copy = d;
    expect_aligned(copy, std::to_string(n) + " pairs, copy");
    EXPECT_TRUE(same_bits(copy.witness_b_wrt_a.data, d.witness_b_wrt_a.data));
    const DerivativeResults moved = std::move(copy);
    expect_aligned(moved, std::to_string(n) + " pairs, move");
    d.resize(n + 5, false);
    expect_aligned(d, std::to_string(n + 5) + " pairs, resize()");
  }
}

}  // namespace
}  // namespace batchcol::testing
