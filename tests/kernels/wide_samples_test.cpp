// The smoothed0 sample builder (kernels::simd::build_samples): its noise is engine/src/counter_rng.hpp's
// gaussian_vector<6> bit for bit on every instruction set, antithetic copies are exact negations with the
// transposed rotation, the poses are E R0 and t0 + s_t z with E the rotation exponential of s_w z_w, and the first
// directions follow the plan.
#include "batchcol/batch.hpp"  // to_string(InstructionSet)
#include "counter_rng.hpp"  // engine/src
#include "kernels/simd/wide_gjk.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstring>
#include <vector>

namespace batchcol {
namespace {

bool same(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

struct Arrays {
  std::vector<double> data;
  kernels::simd::SampleArrays view;
  explicit Arrays(std::size_t n) : data(21 * n, -7.0) {
    for (int e = 0; e < 9; ++e) view.R[e] = data.data() + e * n;
    for (int e = 0; e < 3; ++e) view.t[e] = data.data() + (9 + e) * n, view.direction[e] = data.data() + (12 + e) * n;
    for (int e = 0; e < 6; ++e) view.z[e] = data.data() + (15 + e) * n;
  }
};

kernels::simd::SamplePlan plan(std::uint64_t seed, std::uint64_t pair, double rotation, bool predict) {
  kernels::simd::SamplePlan p;
  p.key = detail::splitmix64(detail::splitmix64(seed) ^ pair);
  const Eigen::Matrix3d R0 = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (int e = 0; e < 9; ++e) p.R0[e] = R0(e / 3, e % 3);
  for (int e = 0; e < 3; ++e) p.t0[e] = 0.3 * (e + 1), p.n0[e] = e == 2 ? 1.0 : 0.0, p.first[e] = -0.5 * e;
  for (int e = 0; e < 18; ++e) p.P[e] = 0.01 * (e - 9);
  p.translation = 0.02;
  p.rotation = rotation;
  p.predict = predict;
  return p;
}

TEST(WideSamples, NoiseIsTheCounterGeneratorsAndPosesFollowThePlan) {
  // 13 antithetic pairs (a partial register on every width), the last without its copy (an odd M); a rotation
  // noise whose angles cross the series' pi/4 bound on some samples.
  const std::size_t count = 13, odds = 12;
  for (double rotation : {0.05, 0.6}) {
    for (bool predict : {false, true}) {
      const kernels::simd::SamplePlan p = plan(42, 9, rotation, predict);
      std::vector<double> reference;
      for (InstructionSet isa : {InstructionSet::scalar, InstructionSet::avx2, InstructionSet::avx512}) {
        if (!kernels::simd::cpu_has(isa)) continue;
        SCOPED_TRACE(std::string(to_string(isa)) + (predict ? " predicted" : " plain"));
        Arrays even(count), odd(count);
        kernels::simd::build_samples(isa, p, 5, count, odds, even.view, odd.view);
        for (std::size_t k = 0; k < count; ++k) {
          double z[6];
          detail::gaussian_vector<6>(42, 9, 5 + k, 0, z);
          for (int e = 0; e < 6; ++e) ASSERT_TRUE(same(even.view.z[e][k], z[e])) << k << " " << e;
          const Eigen::Vector3d w = rotation * Eigen::Vector3d(z[3], z[4], z[5]);
          const Eigen::Matrix3d E = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
          Eigen::Matrix3d R0, R, Rt;
          for (int e = 0; e < 9; ++e) {
            R0(e / 3, e % 3) = p.R0[e];
            R(e / 3, e % 3) = even.view.R[e][k];
            Rt(e / 3, e % 3) = odd.view.R[e][k];
          }
          EXPECT_LT((R - E * R0).norm(), 1e-14);
          for (int e = 0; e < 3; ++e) {
            EXPECT_TRUE(same(even.view.t[e][k], p.t0[e] + p.translation * z[e]));
            double d = p.first[e];
            if (predict) {
              double dz = 0;
              for (int f = 0; f < 6; ++f) dz += p.P[6 * e + f] * z[f];
              d = -(p.n0[e] + dz);
            }
            EXPECT_NEAR(even.view.direction[e][k], d, 1e-15);
          }
          if (k >= odds) {  // no copy: odd's entry untouched
            EXPECT_EQ(odd.view.z[0][k], -7.0);
            continue;
          }
          EXPECT_LT((Rt - E.transpose() * R0).norm(), 1e-14);
          for (int e = 0; e < 6; ++e) EXPECT_TRUE(same(odd.view.z[e][k], -z[e]));
          for (int e = 0; e < 3; ++e) EXPECT_TRUE(same(odd.view.t[e][k], p.t0[e] - p.translation * z[e]));
        }
        // Every instruction set writes the same bits.
        std::vector<double> all = even.data;
        all.insert(all.end(), odd.data.begin(), odd.data.end());
        if (reference.empty()) reference = all;
        else EXPECT_EQ(std::memcmp(all.data(), reference.data(), all.size() * sizeof(double)), 0);
      }
    }
  }
}

}  // namespace
}  // namespace batchcol
