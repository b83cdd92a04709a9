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

// Smooth pairs (ellipsoids): the smoothed derivative is the derivative of the smoothed function, whose bias is
// O(eps^2) for a C^3 function; with M large the sampling error stays below it down to eps = 0.025.
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
  const double rate0 = std::log2(e0[0] / e0[2]) / 2, rate1 = std::log2(e1[0] / e1[2]) / 2;
  std::printf("measured rate (log2 of the error ratio per halving, eps 0.2 -> 0.05): 0th %.2f, 1st %.2f\n", rate0,
              rate1);
  for (std::size_t k = 1; k < noises.size(); ++k) {
    EXPECT_LT(e1[k], e1[k - 1]);
  }
  EXPECT_LT(e1.back(), 0.01);
  EXPECT_LT(e0.back(), 0.05);
  EXPECT_GT(rate1, 1.5);  // O(eps^2) bias
  EXPECT_GT(rate0, 1.0);
}

// Polytopes: at vertex-vertex contacts the analytic Jacobian of a's witness w.r.t. b's twist is exactly zero (the
// witness is a vertex, fixed on a); the first-order smoothed one is not, nor is the normal's at a vertex-face
// contact (the face normal does not turn, the smoothed one does).
TEST(DerivativesSmoothing, FirstOrderIsInformativeOnPolytopes) {
  Rng rng(6);
  ShapeTable shapes;
  const PairBatch batch = random_separated_pairs(rng, shapes, {ShapeType::box, ShapeType::convex}, 500);
  const DerivativeResults analytic = run(shapes, batch, DerivativeMethod::analytic, 1, 1.0);
  const DerivativeResults first = run(shapes, batch, DerivativeMethod::smoothed1, 64, 0.05);
  int vertex_pairs = 0, face_pairs = 0;
  for (std::size_t i = 0; i < batch.size(); ++i) {
    const double scale = 1.0;  // witness Jacobians w.r.t. translation are dimensionless
    if (analytic.status[i] == DerivativeStatus::zero_curvature) {
      const auto A = analytic.witness_a_wrt_b[i], F = first.witness_a_wrt_b[i];
      if (A.cwiseAbs().maxCoeff() != 0.0) continue;  // b is the vertex, a is curved or on a face
      ++vertex_pairs;
      EXPECT_GT(F.leftCols<3>().cwiseAbs().maxCoeff(), 1e-2 * scale) << i;
    }
    if (analytic.status[i] == DerivativeStatus::smooth && analytic.normal_wrt_b[i].cwiseAbs().maxCoeff() == 0.0) {
      ++face_pairs;
      EXPECT_GT(first.normal_wrt_b[i].cwiseAbs().maxCoeff(), 1e-2) << i;
    }
  }
  std::printf("vertex-vertex pairs %d, vertex-face pairs %d (of %zu)\n", vertex_pairs, face_pairs, batch.size());
  EXPECT_GE(vertex_pairs, 10);
  EXPECT_GE(face_pairs, 10);
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
  ellipsoids.add(shapes.add(Shape::ellipsoid(0.1, 0.2, 0.3)), Pose::identity(), shapes.add(Shape::ellipsoid(0.3, 0.15, 0.1)),
                 {Eigen::Vector3d(0.5, 0.2, 0.1), random_rotation(rng)});
  hulls.add(shapes.add(Shape::convex(random_hull_points(rng, 8, 0.1, 0.3))), Pose::identity(),
            shapes.add(Shape::convex(random_hull_points(rng, 8, 0.1, 0.3))), {Eigen::Vector3d(0.6, 0.1, 0.2), random_rotation(rng)});
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
