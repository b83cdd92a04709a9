// Randomized smoothing: convergence to the analytic derivatives as the noise shrinks, first-order Jacobians on
// polytopes, and the standard error of both estimators against the number of samples.
#include "batchcol/batchcol.hpp"
#include "support/derivative_reference.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

namespace batchcol::testing {
namespace {

DerivativeResults run(const ShapeTable& shapes, const PairBatch& batch, DerivativeMethod method, int samples,
                      double noise, std::uint64_t seed = 0) {
  DerivativeOptions o;
  o.method = method;
  o.samples = samples;
  o.noise = noise;
  o.seed = seed;
  PairResults r;
  DerivativeResults d;
  differentiate(shapes, batch, tight_query(), o, r, d);
  return d;
}

// Mean over pairs of max |J_smoothed - J_analytic| / max |J_analytic| for the witness of b w.r.t. b's twist.
double mean_error(const DerivativeResults& smoothed, const DerivativeResults& analytic) {
  double sum = 0;
  for (std::size_t i = 0; i < analytic.size(); ++i)
    sum += relative_error(smoothed.witness_b_wrt_b[i], analytic.witness_b_wrt_b[i]);
  return sum / analytic.size();
}

// Smooth pairs (ellipsoids): the smoothed derivative is the derivative of the smoothed function, whose bias
// shrinks as O(eps^2) for a C^3 function, down to the estimator's sampling error, which shrinks as 1/sqrt(M).
// Measured (M = 16384, mean over 20 pairs): 1st order 3.8e-2, 1.2e-2, 5.5e-3, 4.8e-3 for eps = 0.2 ... 0.025
// (error ratio 3.1 over the first halving, then the sampling floor); 0th order stays at its sampling floor
// (2.5e-2 at M = 16384, 4x that at M = 1024: the 1/sqrt(M) rate) at every eps.
TEST(DerivativesSmoothing, ConvergesToAnalyticAsNoiseShrinks) {
  Rng rng(5);
  ShapeTable shapes;
  const PairBatch batch = random_separated_pairs(rng, shapes, {ShapeType::ellipsoid}, 20);
  const DerivativeResults analytic = run(shapes, batch, DerivativeMethod::analytic, 1, 1.0);
  const std::vector<double> noises = {0.2, 0.1, 0.05, 0.025};
  std::vector<double> e0, e1;
  std::printf("noise  smoothed0-error  smoothed1-error  (M = 16384, witness_b w.r.t. b, mean over 20 pairs)\n");
  for (double eps : noises) {
    e0.push_back(mean_error(run(shapes, batch, DerivativeMethod::smoothed0, 16384, eps), analytic));
    e1.push_back(mean_error(run(shapes, batch, DerivativeMethod::smoothed1, 16384, eps), analytic));
    std::printf("%5.3f  %15.3e  %15.3e\n", eps, e0.back(), e1.back());
  }
  const double e0_small_m = mean_error(run(shapes, batch, DerivativeMethod::smoothed0, 1024, 0.025), analytic);
  const double e1_small_m = mean_error(run(shapes, batch, DerivativeMethod::smoothed1, 1024, 0.025), analytic);
  std::printf("eps 0.025, M = 1024: smoothed0 %.3e, smoothed1 %.3e\n", e0_small_m, e1_small_m);
  std::printf("1st order: error ratio over the first halving of eps %.2f (O(eps^2) bias: 4)\n", e1[0] / e1[1]);
  for (std::size_t k = 1; k < noises.size(); ++k) EXPECT_LT(e1[k], e1[k - 1]);
  EXPECT_GT(e1[0] / e1[1], 2.5);
  EXPECT_LT(e1.back(), 0.01);
  EXPECT_LT(e0.back(), 0.05);
  // The sampling floor: 16x the samples, ~4x less error.
  EXPECT_GT(e0_small_m / e0.back(), 2.5);
  EXPECT_GT(e1_small_m / e1.back(), 2.5);
}

// Polytopes: where a's witness is a vertex the analytic Jacobian of a's witness w.r.t. b's twist is exactly zero (the
// witness is a vertex, fixed on a); the first-order smoothed one is not, nor is the normal's at a vertex-face
// contact (the face normal does not turn, the smoothed one does).
TEST(DerivativesSmoothing, FirstOrderIsInformativeOnPolytopes) {
  Rng rng(6);
  ShapeTable shapes;
  // 1000 pairs: vertex-face contacts whose face normal is fixed are rare (~1.6% of random pairs), and the checks
  // below want at least 10 of them whatever the random stream.
  const PairBatch batch = random_separated_pairs(rng, shapes, {ShapeType::box, ShapeType::convex}, 1000);
  const DerivativeResults analytic = run(shapes, batch, DerivativeMethod::analytic, 1, 1.0);
  // Directions noise of 0.3 rad: a vertex's normal cone spans about a radian on these hulls, and smaller noise
  // rarely leaves it (the smoothed Jacobian is then zero too, only with a smaller probability).
  const DerivativeResults first = run(shapes, batch, DerivativeMethod::smoothed1, 64, 0.3);
  int vertex_pairs = 0, face_pairs = 0, informative_vertex = 0, informative_face = 0;
  for (std::size_t i = 0; i < batch.size(); ++i) {
    const double scale = 1.0;  // witness Jacobians w.r.t. translation are dimensionless
    if (analytic.status[i] == DerivativeStatus::zero_curvature) {
      const auto A = analytic.witness_a_wrt_b[i], F = first.witness_a_wrt_b[i];
      if (A.cwiseAbs().maxCoeff() != 0.0) continue;  // b is the vertex, a is curved or on a face
      ++vertex_pairs;
      informative_vertex += F.leftCols<3>().cwiseAbs().maxCoeff() > 1e-2 * scale;
    }
    // A face's normal does not turn when the other body (the vertex's) moves: zero up to rounding.
    for (const Mat36Array* m : {&analytic.normal_wrt_a, &analytic.normal_wrt_b}) {
      if (analytic.status[i] != DerivativeStatus::smooth || (*m)[i].cwiseAbs().maxCoeff() >= 1e-12) continue;
      ++face_pairs;
      const Mat36Array& smoothed = m == &analytic.normal_wrt_a ? first.normal_wrt_a : first.normal_wrt_b;
      informative_face += smoothed[i].cwiseAbs().maxCoeff() > 1e-2;
    }
  }
  int counts[6] = {};
  for (DerivativeStatus st : analytic.status) ++counts[static_cast<int>(st)];
  std::printf("analytic statuses: smooth %d, zero_curvature %d, nonsmooth %d, singular %d\n", counts[0], counts[1],
              counts[2], counts[3]);
  std::printf("pairs whose witness a is a vertex %d (%d with a non-zero smoothed1 Jacobian), face normals %d (%d) "
              "of %zu\n",
              vertex_pairs, informative_vertex, face_pairs, informative_face, batch.size());
  EXPECT_GE(vertex_pairs, 10);
  EXPECT_GE(face_pairs, 10);
  EXPECT_GE(informative_vertex, 0.9 * vertex_pairs);
  EXPECT_GE(informative_face, 0.9 * face_pairs);
}

// Standard error of witness_b w.r.t. b (relative to the mean over seeds) over 40 seeds, per M.
double standard_error(const ShapeTable& shapes, const PairBatch& batch, DerivativeMethod method, int M, double eps) {
  const int seeds = 40;
  std::vector<Mat36> values;
  Mat36 mean = Mat36::Zero();
  for (int s = 0; s < seeds; ++s) {
    values.push_back(run(shapes, batch, method, M, eps, 1000 + s).witness_b_wrt_b[0]);
    mean += values.back() / seeds;
  }
  double var = 0;
  for (const Mat36& v : values) var += (v - mean).squaredNorm() / (seeds - 1);
  return std::sqrt(var) / mean.norm();
}

TEST(DerivativesSmoothing, FirstOrderNeedsFarFewerSamples) {
  ShapeTable shapes;
  Rng rng(3);
  PairBatch ellipsoids, hulls;
  ellipsoids.add(shapes.add(Shape::ellipsoid(0.1, 0.2, 0.3)), Pose::identity(),
                 shapes.add(Shape::ellipsoid(0.3, 0.15, 0.1)), {Eigen::Vector3d(0.5, 0.2, 0.1), random_rotation(rng)});
  hulls.add(shapes.add(Shape::convex(random_hull_points(rng, 8, 0.1, 0.3))), Pose::identity(),
            shapes.add(Shape::convex(random_hull_points(rng, 8, 0.1, 0.3))),
            {Eigen::Vector3d(0.6, 0.1, 0.2), random_rotation(rng)});
  std::printf("pair        M   SE 0th order   SE 1st order  (relative standard error of d witness_b / d xi_b, "
              "eps = 0.05, 40 seeds)\n");
  for (const auto* b : {&ellipsoids, &hulls}) {
    const char* name = b == &ellipsoids ? "ellipsoids" : "hulls";
    for (int M : {4, 16, 64, 256}) {
      const double se0 = standard_error(shapes, *b, DerivativeMethod::smoothed0, M, 0.05);
      const double se1 = standard_error(shapes, *b, DerivativeMethod::smoothed1, M, 0.05);
      std::printf("%-10s %4d   %12.3e   %12.3e\n", name, M, se0, se1);
      EXPECT_LT(se1 * 3, se0) << name << " M=" << M;
    }
  }
}

}  // namespace
}  // namespace batchcol::testing
