// smoothed_support_estimate() (smoothed1's support-map Jacobian estimate) is, on every instruction set and every
// shape path (scanned hull, inflated hull, ellipsoid, the general support call; M = 4's register path and the
// buffered one), through a ShapeView and through the shape table, bit for bit the antithetic-difference form
//   S = sym(1/(M e) sum_k (S(u + e z_k) - S(u - e z_k)) z_k^T)   (+ (S(u + e z) - S(u)) z^T for an odd M's last draw)
// with the sums taken draw after draw from +0. The form before (each sample against the baseline S(u), both
// samples of a pair summed separately) rounds differently and fails this test.
#include "derivative_smoothed1.hpp"    // engine/src
#include "derivative_support.hpp"      // engine/src
#include "kernels/shape_core.hpp"
#include "kernels/support.hpp"
#include "shape_table_access.hpp"      // engine/src
#include "support/generators.hpp"
#include "support/same_results.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace batchcol::testing {
namespace {

Eigen::Matrix3d reference_estimate(const ShapeView& view, const Eigen::Vector3d& u, double e, int samples,
                                   const std::vector<std::vector<double>>& z) {
  const auto core = kernels::make_core<double>(view);
  const auto support = [&](const Eigen::Vector3d& d) {
    kernels::SupportHint hint;
    Eigen::Vector3d p = kernels::support(core, d, hint);
    detail::add_swept_radius(p, core.radius, d);
    return p;
  };
  double sum[3][3] = {};
  const int draws = (samples + 1) / 2;
  for (int k = 0; k < draws; ++k) {
    const Eigen::Vector3d ez(e * z[0][k], e * z[1][k], e * z[2][k]);
    const Eigen::Vector3d plus(u[0] + ez[0], u[1] + ez[1], u[2] + ez[2]);
    const Eigen::Vector3d minus(u[0] - ez[0], u[1] - ez[1], u[2] - ez[2]);
    const bool paired = 2 * k + 1 < samples;
    const Eigen::Vector3d a = support(plus), b = paired ? support(minus) : support(u);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) sum[r][c] = sum[r][c] + (a[r] - b[r]) * z[c][k];
  }
  Eigen::Matrix3d H, S;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) H(r, c) = sum[r][c] / (static_cast<double>(samples) * e);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) S(r, c) = 0.5 * (H(r, c) + H(c, r));
  return S;
}

TEST(DerivativesSmoothed1Estimate, IsTheAntitheticDifferenceFormOnEveryPathAndSet) {
  Rng rng(31);
  ShapeTable shapes;
  std::vector<std::pair<std::size_t, std::string>> cases;
  cases.emplace_back(shapes.add(Shape::ellipsoid(0.1, 0.2, 0.3)), "ellipsoid");
  cases.emplace_back(shapes.add(Shape::convex(random_hull_points(rng, 8, 0.1, 0.3))), "hull 8");
  cases.emplace_back(shapes.add(Shape::convex(random_hull_points(rng, 20, 0.1, 0.3))), "hull 20");
  Shape inflated = Shape::convex(random_hull_points(rng, 8, 0.1, 0.3));
  inflated.inflation = 0.02;
  cases.emplace_back(shapes.add(inflated), "inflated hull");
  Shape round = Shape::ellipsoid(0.3, 0.1, 0.2);
  round.inflation = 0.01;
  cases.emplace_back(shapes.add(round), "inflated ellipsoid");
  cases.emplace_back(shapes.add(Shape::capsule(0.1, 0.2)), "capsule");
  std::vector<InstructionSet> sets = vector_isas_here();
  sets.insert(sets.begin(), InstructionSet::scalar);
  std::mt19937_64 noise(7);
  std::normal_distribution<double> normal;
  int compared = 0;
  for (const auto& [id, name] : cases) {
    const ShapeView view = detail::ShapeTableAccess::view(shapes, id);
    for (const int samples : {2, 3, 4, 5, 16}) {
      for (int trial = 0; trial < 50; ++trial) {
        const Eigen::Vector3d u = random_unit_vector(rng);
        const double e = 0.05 + 0.3 * trial / 50.0;
        const int draws = (samples + 1) / 2;
        std::vector<std::vector<double>> z(4, std::vector<double>(draws));
        for (auto& row : z)
          for (double& x : row) x = normal(noise);
        const double* const zp[4] = {z[0].data(), z[1].data(), z[2].data(), z[3].data()};
        const Eigen::Matrix3d want = reference_estimate(view, u, e, samples, z);
        for (const InstructionSet isa : sets) {
          const Eigen::Matrix3d got =
              detail::smoothed_support_estimate(shapes, static_cast<std::uint32_t>(id), u, e, samples, zp, isa);
          ++compared;
          ASSERT_EQ(std::memcmp(got.data(), want.data(), sizeof(double) * 9), 0)
              << name << " M = " << samples << " trial " << trial << " " << to_string(isa) << "\n"
              << got << "\nwant\n"
              << want;
        }
      }
    }
  }
  std::printf("%d estimates compared bit for bit\n", compared);
}

}  // namespace
}  // namespace batchcol::testing
