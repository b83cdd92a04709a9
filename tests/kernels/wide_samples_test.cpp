// The smoothed0 sample builder (kernels::simd::build_samples): its noise is engine/src/counter_rng.hpp's
// sample_noise() bit for bit on every instruction set, antithetic copies are exact negations with the
// transposed rotation, the poses are E R0 and t0 + s_t z with E the rotation exponential of s_w z_w, and the first
// directions follow the plan. The smoothed1 noise (draw_support_noise) is support_noise_pair() bit for bit, and the
// smoothed0 reduction (accumulate_samples) is the scalar antithetic-pair sums bit for bit, on every instruction set.
#include "batchcol/batch.hpp"  // to_string(InstructionSet)
#include "counter_rng.hpp"  // engine/src
#include "kernels/simd/wide_gjk.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
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
        const kernels::simd::SamplePlan* plans[] = {&p};
        kernels::simd::build_samples(isa, plans, 1, count, 5, count, odds, even.view, odd.view);
        for (std::size_t k = 0; k < count; ++k) {
          double z[6];
          detail::sample_noise(p.key, 5 + k, z);
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

TEST(WideSamples, SeveralPairsPerRegisterGiveEachPairsOwnSamples) {
  // Small M packs several pairs' samples into one register: 5 plans of 1, 2 (M = 4, the 16-byte stores) or 3
  // antithetic pairs, laid out as the engine's block (plan q's firsts at q stride, its copies right after them), so
  // that registers mix 2 to 8 pairs and the last one is partial on AVX2 and AVX-512. Every entry must be the bits
  // of the plan built alone, whatever its lane neighbours are (their own keys, rotations, predictions), and
  // nothing else is written.
  const std::size_t pairs = 5;
  std::vector<kernels::simd::SamplePlan> p;
  for (std::size_t q = 0; q < pairs; ++q) {
    p.push_back(plan(42, 100 + q, q % 2 == 0 ? 0.05 : 0.6, q % 3 != 1));
    for (int e = 0; e < 3; ++e) p.back().t0[e] += 0.1 * double(q), p.back().first[e] += double(q);
    p.back().translation *= double(q + 1);
  }
  const kernels::simd::SamplePlan* ptr[pairs];
  for (std::size_t q = 0; q < pairs; ++q) ptr[q] = &p[q];
  for (std::size_t count : {1, 2, 3}) {
    const std::size_t stride = 2 * count, n = pairs * stride + 1;  // one spare entry: nothing past the block
    for (InstructionSet isa : {InstructionSet::scalar, InstructionSet::avx2, InstructionSet::avx512}) {
      if (!kernels::simd::cpu_has(isa)) continue;
      SCOPED_TRACE(std::string(to_string(isa)) + " count " + std::to_string(count));
      Arrays block(n);
      kernels::simd::SampleArrays odd = block.view;
      for (double*& a : odd.R) a += count;
      for (double*& a : odd.t) a += count;
      for (double*& a : odd.direction) a += count;
      for (double*& a : odd.z) a += count;
      kernels::simd::build_samples(isa, ptr, pairs, stride, 3, count, count, block.view, odd);
      for (int a = 0; a < 21; ++a) EXPECT_EQ(block.data[a * n + n - 1], -7.0) << a;
      for (std::size_t q = 0; q < pairs; ++q) {
        Arrays e1(count), o1(count);
        kernels::simd::build_samples(isa, ptr + q, 1, count, 3, count, count, e1.view, o1.view);
        for (int a = 0; a < 21; ++a)
          for (std::size_t k = 0; k < count; ++k) {
            const std::size_t at = a * n + q * stride + k, alone = a * count + k;
            ASSERT_TRUE(same(block.data[at], e1.data[alone])) << q << " " << a << " " << k;
            ASSERT_TRUE(same(block.data[at + count], o1.data[alone])) << q << " " << a << " " << k;
          }
      }
    }
  }
}

TEST(WideSamples, SupportNoiseIsTheCounterGenerators) {
  // draw_support_noise(): 1 .. 9 pairs (AVX2's 4 and AVX-512's 8 lanes full, partial and padded) of 1 .. 5 draws;
  // pair p's block gets exactly support_noise_pair(key_p, j) for j < 3 draws, the sentinel after the last block stays.
  for (std::size_t pairs = 1; pairs <= 9; ++pairs) {
    for (std::size_t draws = 1; draws <= 5; ++draws) {
      std::vector<std::uint64_t> keys(pairs);
      for (std::size_t p = 0; p < pairs; ++p) keys[p] = detail::splitmix64(detail::splitmix64(43) ^ (1000 * p + draws));
      for (InstructionSet isa : {InstructionSet::scalar, InstructionSet::avx2, InstructionSet::avx512}) {
        if (!kernels::simd::cpu_has(isa)) continue;
        SCOPED_TRACE(to_string(isa));
        std::vector<double> z(6 * draws * pairs + 1, -7.0);
        kernels::simd::draw_support_noise(isa, keys.data(), pairs, draws, z.data());
        for (std::size_t p = 0; p < pairs; ++p)
          for (std::size_t j = 0; j < 3 * draws; ++j) {
            double g0, g1;
            detail::support_noise_pair(keys[p], j, g0, g1);
            ASSERT_TRUE(same(z[6 * draws * p + 2 * j], g0)) << pairs << " " << draws << " " << p << " " << j;
            ASSERT_TRUE(same(z[6 * draws * p + 2 * j + 1], g1)) << pairs << " " << draws << " " << p << " " << j;
          }
        EXPECT_EQ(z.back(), -7.0);
      }
    }
  }
}

TEST(WideSamples, SupportNoiseIsStandardNormal) {
  // support_noise_pair()'s 32-bit uniforms: the moments of 2^20 normals (both outputs of 2^19 transforms over
  // 2^13 keys) against N(0, 1)'s, each within 6 of its standard errors (mean 1/sqrt(n), variance sqrt(2/n),
  // fourth moment sqrt(96/n)), the two outputs' correlation too, and P(|z| > 3) within 6 standard errors of 0.0027.
  const int keys = 1 << 13, per_key = 64;
  double m1 = 0, m2 = 0, m4 = 0, cross = 0, tail = 0;
  for (int p = 0; p < keys; ++p) {
    const std::uint64_t key = detail::splitmix64(detail::splitmix64(5) ^ std::uint64_t(p));
    for (int j = 0; j < per_key; ++j) {
      double g[2];
      detail::support_noise_pair(key, std::uint64_t(j), g[0], g[1]);
      cross += g[0] * g[1];
      for (double v : g) m1 += v, m2 += v * v, m4 += v * v * v * v, tail += std::abs(v) > 3.0;
    }
  }
  const double n = 2.0 * keys * per_key;
  EXPECT_NEAR(m1 / n, 0.0, 6.0 / std::sqrt(n));
  EXPECT_NEAR(m2 / n, 1.0, 6.0 * std::sqrt(2.0 / n));
  EXPECT_NEAR(m4 / n, 3.0, 6.0 * std::sqrt(96.0 / n));
  EXPECT_NEAR(cross / (n / 2), 0.0, 6.0 / std::sqrt(n / 2));
  const double p3 = 0.0026997960632601866;
  EXPECT_NEAR(tail / n, p3, 6.0 * std::sqrt(p3 * (1 - p3) / n));
}

TEST(WideSamples, SupportNoiseFloatPiecesFollowLibm) {
  // support_noise_pair()'s float -2 log(u) and sin/cos of a 2^-32 turn against libm in double, over the radius
  // uniform's extremes (h = 0: u = 2^-31, the largest radius; h = 2^31 - 1: u = 1) and 2^20 mixed inputs. Bounds:
  // a few float roundings (2^-24 = 6e-8 each) of the result, the series' remainders being below 3e-8.
  std::uint64_t state = 11;
  double worst_log = 0, worst_trig = 0;
  for (int i = 0; i < (1 << 20) + 2; ++i) {
    state = detail::splitmix64(state);
    const std::uint32_t h = i == 0 ? 0u : i == 1 ? 0x7FFFFFFFu : std::uint32_t(state >> 33), a = std::uint32_t(state);
    const float u = (static_cast<float>(static_cast<std::int32_t>(h)) + 1.0f) * 0x1.0p-31f;  // the uniform exactly
    const double want = -2.0 * std::log(double(u)), got = detail::minus_two_log_unit_f(h);
    ASSERT_GE(got, 0.0) << h;
    worst_log = std::max(worst_log, std::abs(got - want) / std::max(want, 1e-30));
    float s, c;
    detail::sincos_turn_f(a, s, c);
    const double angle = 6.283185307179586 * double(a) * 0x1.0p-32;
    worst_trig = std::max({worst_trig, std::abs(s - std::sin(angle)), std::abs(c - std::cos(angle))});
  }
  EXPECT_LT(worst_log, 5e-7);
  EXPECT_LT(worst_trig, 5e-7);
  std::printf("worst relative -2 log error %.3g, worst sin/cos error %.3g\n", worst_log, worst_trig);
}

TEST(WideSamples, AccumulationIsTheAntitheticPairSums) {
  // 23 samples (an odd count: 12 firsts, 11 copies), values of all magnitudes, one non-converged sample and one
  // with an infinite entry (each leaves its pair's other sample alone); the sums are taken in two calls (a pair
  // split over blocks) and in one.
  const std::size_t count = 23, evens = 12;
  std::vector<double> values(12 * count, 0.0), zdata(6 * count);
  std::vector<Status> status(count, Status::converged);
  std::uint64_t state = 5;
  const auto next = [&] {
    state = detail::splitmix64(state);
    return std::ldexp(double(state >> 11) * 0x1.0p-53 - 0.5, int(state % 40) - 20);
  };
  for (std::size_t k = 0; k < count; ++k) {
    for (int e = 0; e < 10; ++e) values[12 * k + e] = next();
    for (int f = 0; f < 6; ++f) zdata[f * count + k] = next();
  }
  status[4] = Status::max_iterations;
  values[12 * 7 + 5] = INFINITY;
  const double* z[6];
  for (int f = 0; f < 6; ++f) z[f] = zdata.data() + f * count;
  double g0[10];
  for (double& g : g0) g = next();
  // The reference, antithetic pair by pair: the values' sums in sample order; a pair with both samples valid adds
  // (v_first - v_copy) z_first, a valid sample alone (v - g0) z (the copy's z is -z_first in the engine; here
  // unrelated numbers, so the copy's own z is seen to be used only when its first is invalid).
  double mean[10] = {}, G[6][10] = {};
  int valid = 0, differ = 0;
  const auto ok = [&](std::size_t k) {
    bool finite = status[k] == Status::converged;
    for (int e = 0; e < 10; ++e) finite = finite && std::isfinite(values[12 * k + e]);
    return finite;
  };
  for (std::size_t e = 0; e < evens; ++e) {
    const std::size_t ko = evens + e;
    const bool ve = ok(e), vo = 2 * e + 1 < count && ok(ko);
    for (std::size_t k : {e, ko})
      if (k == e ? ve : vo)
        for (int r = 0; r < 10; ++r) mean[r] += values[12 * k + r];
    valid += int(ve) + int(vo);
    for (int r = 0; r < 10; ++r)
      for (int f = 0; f < 6; ++f) {
        if (ve && vo) {
          G[f][r] += (values[12 * e + r] - values[12 * ko + r]) * z[f][e];
          // The former per-sample sum with the copy's z = -z_first rounds differently in most entries.
          const double old = (values[12 * e + r] - g0[r]) * z[f][e] + (values[12 * ko + r] - g0[r]) * -z[f][e];
          differ += old != (values[12 * e + r] - values[12 * ko + r]) * z[f][e];
        } else if (ve) {
          G[f][r] += (values[12 * e + r] - g0[r]) * z[f][e];
        } else if (vo) {
          G[f][r] += (values[12 * ko + r] - g0[r]) * z[f][ko];
        }
      }
  }
  EXPECT_GT(differ, 0);
  EXPECT_EQ(valid, 21);
  for (InstructionSet isa : {InstructionSet::scalar, InstructionSet::avx2, InstructionSet::avx512}) {
    if (!kernels::simd::cpu_has(isa)) continue;
    SCOPED_TRACE(to_string(isa));
    kernels::simd::SampleSums whole, split;
    for (int e = 0; e < 10; ++e) whole.g0[e] = split.g0[e] = g0[e];
    kernels::simd::accumulate_samples(isa, values.data(), status.data(), z, count, evens, whole);
    // The first 10 samples (5 pairs) of a block holding only them, then the rest as the next block would.
    {
      const std::size_t part = 10, part_evens = 5;
      std::vector<double> v(12 * part), zd(6 * part);
      std::vector<Status> st(part);
      for (std::size_t n = 0; n < part; ++n) {
        const std::size_t k = n % 2 == 0 ? n / 2 : evens + n / 2, kk = n % 2 == 0 ? n / 2 : part_evens + n / 2;
        std::copy_n(values.data() + 12 * k, 12, v.data() + 12 * kk);
        for (int f = 0; f < 6; ++f) zd[f * part + kk] = z[f][k];
        st[kk] = status[k];
      }
      const double* zp[6];
      for (int f = 0; f < 6; ++f) zp[f] = zd.data() + f * part;
      kernels::simd::accumulate_samples(isa, v.data(), st.data(), zp, part, part_evens, split);
      const std::size_t rest = count - part, rest_evens = (rest + 1) / 2;
      std::vector<double> v2(12 * rest), zd2(6 * rest);
      std::vector<Status> st2(rest);
      for (std::size_t n = 0; n < rest; ++n) {
        const std::size_t m = part + n, k = m % 2 == 0 ? m / 2 : evens + m / 2;
        const std::size_t kk = n % 2 == 0 ? n / 2 : rest_evens + n / 2;
        std::copy_n(values.data() + 12 * k, 12, v2.data() + 12 * kk);
        for (int f = 0; f < 6; ++f) zd2[f * rest + kk] = z[f][k];
        st2[kk] = status[k];
      }
      for (int f = 0; f < 6; ++f) zp[f] = zd2.data() + f * rest;
      kernels::simd::accumulate_samples(isa, v2.data(), st2.data(), zp, rest, rest_evens, split);
    }
    for (const kernels::simd::SampleSums* s : {&whole, &split}) {
      EXPECT_EQ(s->valid, valid);
      for (int e = 0; e < 10; ++e) {
        EXPECT_TRUE(same(s->mean[e], mean[e])) << e;
        for (int f = 0; f < 6; ++f) EXPECT_TRUE(same(s->G[f][e], G[f][e])) << e << " " << f;
      }
    }
  }
}

}  // namespace
}  // namespace batchcol
