// SmoothLanes builds the rotations of sphere and ellipsoid sides itself, eight poses per register, from the pose's
// quaternion (derivative_lanes.inl). The analytic derivatives must keep the bits they had when each pair converted
// its quaternions with Eigen's q.normalized().toRotationMatrix(): a lane given the quaternion must write what a lane
// given that Eigen rotation's curvature matrix writes.
#include "derivative_ift.hpp"      // engine/src
#include "derivative_support.hpp"  // engine/src
#include "support/same_results.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace batchcol::testing {
namespace {

// world_support_jacobian()'s formula in the lanes' order of operations (derivative_lanes.inl, curvature()), with
// the rotation from Eigen: H = 0 + B / m - (B n)(B n)^T / m^3 + r (I - n n^T), B = R diag(radii2) R^T. Never -0
// (0 + x is +0 for x = -0, and the later terms cannot make a -0 of a +0 or a non-zero), so a lane given it as H0
// (H0 + 0, SmoothLanes' path without curvature) computes with exactly these bits.
Eigen::Matrix3d eigen_curvature(const Eigen::Quaterniond& q, const Eigen::Vector3d& radii2, double r,
                                const Eigen::Vector3d& n) {
  const Eigen::Matrix3d R = q.normalized().toRotationMatrix();
  double B[3][3], Bn[3];
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j)  // the upper triangle, mirrored
      B[i][j] = B[j][i] = R(i, 0) * radii2[0] * R(j, 0) + R(i, 1) * radii2[1] * R(j, 1) + R(i, 2) * radii2[2] * R(j, 2);
  for (int i = 0; i < 3; ++i) Bn[i] = B[i][0] * n[0] + B[i][1] * n[1] + B[i][2] * n[2];
  const double m2 = n[0] * Bn[0] + n[1] * Bn[1] + n[2] * Bn[2];
  const double inv_m = m2 > 0.0 ? 1.0 / std::sqrt(m2) : 0.0, inv_m3 = inv_m * inv_m * inv_m;
  Eigen::Matrix3d H;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      H(i, j) = 0.0 + B[i][j] * inv_m - Bn[i] * Bn[j] * inv_m3 + r * ((i == j ? 1.0 : 0.0) - n[i] * n[j]);
  return H;
}

// A quaternion of any magnitude for the direction tests: unit (a tenth), with a zero coefficient, all zero,
// identity, or scaled by 10^[-3, 3].
Eigen::Quaterniond any_quaternion(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> coefficient(-1.0, 1.0), exponent(-3.0, 3.0);
  std::uniform_int_distribution<int> pick(0, 9);
  Eigen::Quaterniond q(coefficient(rng), coefficient(rng), coefficient(rng), coefficient(rng));
  const int kind = pick(rng);
  if (kind == 0) q.normalize();
  else if (kind == 1) q.coeffs()[pick(rng) % 4] = 0.0;
  else if (kind == 2) q.coeffs().setZero();
  else if (kind == 3) q = Eigen::Quaterniond::Identity();
  else q.coeffs() *= std::pow(10.0, exponent(rng));
  return q;
}

// Random separated geometry with sphere / ellipsoid sides on unnormalised quaternions of magnitudes 1e-3 .. 1e3
// (and some exactly unit, some with zero coefficients): every lane of a whole block of curved sides against the
// same block given Eigen's curvature matrices, on the baseline lanes (a partial block) and on every wide set here.
TEST(DerivativesLanes, LaneRotationsGiveEigensBits) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), positive(0.05, 2.0);
  constexpr std::size_t L = detail::SmoothLanes::kLanes;
  std::vector<InstructionSet> sets = {InstructionSet::scalar};
  for (const auto isa : vector_isas_here()) sets.push_back(isa);
  int compared = 0, nonzero = 0;
  for (int block = 0; block < 400; ++block) {
    detail::SmoothLanes curved{}, given{};
    for (std::size_t l = 0; l < L; ++l) {
      detail::PairGeometry g;
      g.normal = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
      g.witness_a = Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
      g.distance = positive(rng);
      g.witness_b = g.witness_a + g.distance * g.normal;
      detail::CurvedSide side[2];
      for (auto& s : side) {
        Eigen::Vector4d c(unit(rng), unit(rng), unit(rng), unit(rng));
        if (l % 4 == 1) c[rng() % 4] = 0.0;
        if (l % 4 == 2) c.normalize();
        else c *= std::pow(10.0, 3.0 * unit(rng));
        for (int k = 0; k < 4; ++k) s.q[k] = c[k];
        const bool sphere = l % 5 == 4;
        if (!sphere) s.radii2 = Eigen::Vector3d(positive(rng), positive(rng), positive(rng)).cwiseAbs2();
        s.round = sphere || l % 3 == 0 ? positive(rng) : 0.0;
      }
      curved.add(l, g, &side[0], &side[1]);
      const auto quaternion = [](const detail::CurvedSide& s) {
        return Eigen::Quaterniond(s.q[3], s.q[0], s.q[1], s.q[2]);
      };
      g.H_a = eigen_curvature(quaternion(side[0]), side[0].radii2, side[0].round, g.normal);
      g.H_b = eigen_curvature(quaternion(side[1]), side[1].radii2, side[1].round, g.normal);
      given.add(l, g);
    }
    for (const auto isa : sets)
      for (const bool whole : {true, false}) {
        // A partial block (the last lane left out) takes the baseline lanes on every set.
        if (!whole) curved.count = given.count = L - 1;
        double a[detail::StoreEntries][L] = {}, b[detail::StoreEntries][L] = {};
        double *ra[detail::StoreEntries], *rb[detail::StoreEntries];
        for (int e = 0; e < detail::StoreEntries; ++e) ra[e] = a[e], rb[e] = b[e];
        curved.solve(ra, false, isa);
        given.solve(rb, false, isa);
        for (int e = 0; e < detail::StoreEntries; ++e)
          for (std::size_t l = 0; l < curved.count; ++l) {
            ASSERT_EQ(std::memcmp(&a[e][l], &b[e][l], sizeof(double)), 0)
                << "block " << block << " lane " << l << " entry " << e << " " << to_string(isa) << ": "
                << a[e][l] << " vs " << b[e][l];
            nonzero += a[e][l] != 0.0;
          }
        ++compared;
        curved.count = given.count = L;
      }
  }
  EXPECT_GT(nonzero, compared * int(L - 1) * 60);  // the outputs are not trivially zero
  std::printf("%d blocks compared\n", compared);
}

// hull_pair_directions() (two sides per SSE2 register) must give the bits of the Eigen expressions hull_pair()
// evaluated per side: q.normalized(), sign * (q.normalized().conjugate() * n), on quaternions of any magnitude
// (1e-3 .. 1e3, unit, with zero coefficients, all zero) and normals with signed zeros.
TEST(DerivativesLanes, HullPairDirectionsGiveEigensBits) {
  std::mt19937_64 rng(20261127);
  std::uniform_real_distribution<double> coefficient(-1.0, 1.0);
  std::uniform_int_distribution<int> pick(0, 9);
  const auto quaternion = [&] { return any_quaternion(rng); };
  const auto same = [](const double* x, const double* y, int count) { return std::memcmp(x, y, count * sizeof(double)) == 0; };
  int mismatches = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    const Eigen::Quaterniond q_a = quaternion(), q_b = quaternion();
    Eigen::Vector3d n(coefficient(rng), coefficient(rng), coefficient(rng));
    if (pick(rng) == 0) n[pick(rng) % 3] = pick(rng) % 2 ? 0.0 : -0.0;
    n.normalize();
    Eigen::Quaterniond unit_a, unit_b;
    Eigen::Vector3d u_a, u_b;
    detail::hull_pair_directions(q_a, q_b, n, unit_a, unit_b, u_a, u_b);
    const Eigen::Quaterniond ea = q_a.normalized(), eb = q_b.normalized();
    const Eigen::Vector3d eu_a = 1.0 * (ea.conjugate() * n), eu_b = -1.0 * (eb.conjugate() * n);
    const bool ok = same(unit_a.coeffs().data(), ea.coeffs().data(), 4) &&
                    same(unit_b.coeffs().data(), eb.coeffs().data(), 4) && same(u_a.data(), eu_a.data(), 3) &&
                    same(u_b.data(), eu_b.data(), 3);
    if (!ok && ++mismatches <= 3)
      ADD_FAILURE() << "trial " << trial << ": u_a " << u_a.transpose() << " vs " << eu_a.transpose() << ", u_b "
                    << u_b.transpose() << " vs " << eu_b.transpose();
  }
  EXPECT_EQ(mismatches, 0);
}

// hull_directions_block() (8 pairs' directions in AVX2 lanes, on the wide sets) must give each pair the bits of
// hull_pair_directions(), for every block length 1..8 (the short tail reads copies of the last pair), at any start,
// on quaternions of any magnitude, zero and unit, and normals with signed zeros.
TEST(DerivativesLanes, HullDirectionsBlockGivesEachPairsBits) {
  if (vector_isas_here().empty()) GTEST_SKIP() << "no AVX2 on this CPU: the block is not used";
  std::mt19937_64 rng(20261128);
  std::uniform_real_distribution<double> coefficient(-1.0, 1.0);
  std::uniform_int_distribution<int> pick(0, 9);
  const auto quaternion = [&] { return any_quaternion(rng); };
  constexpr std::size_t kPairs = 4000;
  QuatArray ra, rb;
  Vec3Array normal;
  for (std::size_t i = 0; i < kPairs; ++i) {
    ra.push_back(quaternion()), rb.push_back(quaternion());
    Eigen::Vector3d n(coefficient(rng), coefficient(rng), coefficient(rng));
    if (pick(rng) == 0) n[pick(rng) % 3] = pick(rng) % 2 ? 0.0 : -0.0;
    n.normalize();
    normal.push_back(n);
  }
  int mismatches = 0, compared = 0;
  detail::HullDirections d;
  for (std::size_t first = 0; first + 8 <= kPairs; first += 7) {
    const std::size_t count = 1 + first % 8;
    detail::hull_directions_block(ra, rb, normal, first, count, d);
    for (std::size_t j = 0; j < count; ++j) {
      const std::size_t i = first + j;
      Eigen::Quaterniond unit[2];
      Eigen::Vector3d u[2];
      detail::hull_pair_directions(ra[i], rb[i], normal[i], unit[0], unit[1], u[0], u[1]);
      bool ok = d.first == first;
      for (int s = 0; s < 2; ++s) {
        const double got_unit[4] = {d.unit[s][0][j], d.unit[s][1][j], d.unit[s][2][j], d.unit[s][3][j]};
        const double got_u[3] = {d.u[s][0][j], d.u[s][1][j], d.u[s][2][j]};
        ok = ok && std::memcmp(got_unit, unit[s].coeffs().data(), sizeof got_unit) == 0 &&
             std::memcmp(got_u, u[s].data(), sizeof got_u) == 0;
      }
      ++compared;
      if (!ok && ++mismatches <= 3) ADD_FAILURE() << "pair " << i << " of the block at " << first << " (" << count << ")";
    }
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(compared, 2000);
}

// edge_flat() (the rotation and projection written out) must give the bits of the Eigen expressions it replaced in
// hull_pair(): e = unit * edge, e -= n.dot(e) * n, a flat where e.norm() > 1e-6 * length, e.normalized(); on unit
// quaternions, edges of any length (some along n, so that no flat is left) and normals with signed zeros.
TEST(DerivativesLanes, EdgeFlatGivesEigensBits) {
  std::mt19937_64 rng(20261128);
  std::uniform_real_distribution<double> coefficient(-1.0, 1.0), exponent(-3.0, 3.0);
  std::uniform_int_distribution<int> pick(0, 9);
  int mismatches = 0, flats = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    const Eigen::Quaterniond unit =
        Eigen::Quaterniond(coefficient(rng), coefficient(rng), coefficient(rng), coefficient(rng)).normalized();
    Eigen::Vector3d n(coefficient(rng), coefficient(rng), coefficient(rng));
    if (pick(rng) == 0) n[pick(rng) % 3] = pick(rng) % 2 ? 0.0 : -0.0;
    n.normalize();
    Eigen::Vector3d edge = Eigen::Vector3d(coefficient(rng), coefficient(rng), coefficient(rng)) * std::pow(10.0, exponent(rng));
    if (pick(rng) == 0) edge = (unit.conjugate() * n) * std::pow(10.0, exponent(rng));  // along n: no flat
    Eigen::Vector3d e = unit * edge;
    const double length = e.norm();
    e -= n.dot(e) * n;
    const bool expected = e.norm() > 1e-6 * length;
    Eigen::Vector3d flat = Eigen::Vector3d::Constant(7.0), expected_flat = flat;
    if (expected) expected_flat = e.normalized(), ++flats;
    const bool got = detail::edge_flat(unit, edge, n, flat);
    if ((got != expected || std::memcmp(flat.data(), expected_flat.data(), sizeof(double) * 3) != 0) &&
        ++mismatches <= 3)
      ADD_FAILURE() << "trial " << trial << ": " << got << " " << flat.transpose() << " vs " << expected << " "
                    << expected_flat.transpose();
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(flats, 150000);
  EXPECT_LT(flats, 199000);
}

// The exposed feature by its definition, in plain loops: the vertices whose height <u, v> (the production's
// expression and order) is >= max - tolerance, in index order; none or one: a vertex (0); a third off the line of the
// first two (the same collinearity expression): a face (2); else an edge (1), second - first.
int reference_feature(const std::vector<double>& v, const Eigen::Vector3d& u, double tolerance, Eigen::Vector3d& edge) {
  const std::size_t n = v.size() / 3;
  const auto vertex = [&](std::size_t k) { return Eigen::Vector3d(v[3 * k], v[3 * k + 1], v[3 * k + 2]); };
  std::vector<double> h(n);
  double top = -std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < n; ++k) {
    h[k] = u.x() * v[3 * k] + u.y() * v[3 * k + 1] + u.z() * v[3 * k + 2];
    top = std::max(top, h[k]);
  }
  std::vector<std::size_t> exposed;
  for (std::size_t k = 0; k < n; ++k)
    if (h[k] >= top - tolerance) exposed.push_back(k);
  if (exposed.size() < 2) return 0;
  const Eigen::Vector3d e1 = vertex(exposed[1]) - vertex(exposed[0]);
  for (std::size_t m = 2; m < exposed.size(); ++m) {
    const Eigen::Vector3d e2 = vertex(exposed[m]) - vertex(exposed[0]);
    if (e1.cross(e2).squaredNorm() > 1e-12 * e1.squaredNorm() * e2.squaredNorm()) return 2;
  }
  edge = e1;
  return 1;
}

// hull_pair_flats() (both hulls' directions, height passes, walks and edge flats in one AVX2 call on the wide sets,
// the SSE2 code per side on the baseline) must find the flats of the plain reference above and of the Eigen
// expressions of hull_pair()'s edge (e = unit * edge, e -= n.dot(e) * n, a flat where e.norm() > 1e-6 * length,
// e.normalized()), bit for bit: hulls of 4..16 vertices on a coarse integer grid (so that directions along the axes
// and diagonals tie exactly: vertices, edges, faces, and three or more collinear exposed vertices) seen through the
// identity or a half turn about an axis (exact quaternions: the local directions stay on the grid), and random
// normals and rotations.
TEST(DerivativesLanes, HullPairFlatsFindEachSidesFeature) {
  std::mt19937_64 rng(20261128);
  std::uniform_int_distribution<int> grid(-2, 2), size(4, 16), pick(0, 3);
  std::uniform_real_distribution<double> coefficient(-1.0, 1.0);
  const auto hull = [&] {
    std::vector<double> v(3 * std::size_t(size(rng)));
    for (double& c : v) c = 0.5 * grid(rng);
    return v;
  };
  const auto view = [](const std::vector<double>& v) {
    HullView h;
    h.vertices = v.data();
    h.vertex_count = std::uint32_t(v.size() / 3);
    return h;
  };
  int mismatches = 0, features[3] = {0, 0, 0}, flats_seen[3] = {0, 0, 0};
  for (int trial = 0; trial < 20000; ++trial) {
    const std::vector<double> va = hull(), vb = hull();
    const bool random = pick(rng) == 0;
    Eigen::Vector3d n = random ? Eigen::Vector3d(coefficient(rng), coefficient(rng), coefficient(rng))
                               : Eigen::Vector3d(grid(rng), grid(rng), grid(rng));
    if (n.isZero()) n = Eigen::Vector3d::UnitZ();
    n.normalize();
    const auto rotation = [&] {
      if (random) return Eigen::Quaterniond(coefficient(rng), coefficient(rng), coefficient(rng), coefficient(rng));
      Eigen::Quaterniond q(0.0, 0.0, 0.0, 0.0);
      q.coeffs()[pick(rng)] = 1.0;  // the identity (w) or a half turn about x, y or z
      return q;
    };
    const Eigen::Quaterniond q[2] = {rotation(), rotation()};
    const double tolerance[2] = {1e-9, 1e-9};
    const std::vector<double>* vertices[2] = {&va, &vb};
    int want[2];
    Eigen::Vector3d want_flat[2];
    for (int s = 0; s < 2; ++s) {
      const Eigen::Quaterniond unit = q[s].normalized();
      const Eigen::Vector3d u = (s == 0 ? 1.0 : -1.0) * (unit.conjugate() * n);
      Eigen::Vector3d edge;
      want[s] = reference_feature(*vertices[s], u, tolerance[s], edge);
      ++features[want[s]];
      if (want[s] == 1) {
        Eigen::Vector3d e = unit * edge;
        const double length = e.norm();
        e -= n.dot(e) * n;
        if (e.norm() > 1e-6 * length) want_flat[s] = e.normalized();
        else want[s] = 0;
      }
      ++flats_seen[want[s]];
    }
    std::vector<InstructionSet> isas = vector_isas_here();
    isas.insert(isas.begin(), InstructionSet::scalar);
    for (const auto isa : isas) {
      int got[2];
      Eigen::Vector3d flat[2];
      QuatArray ra, rb;
      ra.push_back(q[0]), rb.push_back(q[1]);
      detail::hull_pair_flats(ra, rb, 0, n, view(va), view(vb), tolerance, got, flat, isa);
      for (int s = 0; s < 2; ++s) {
        const bool ok = got[s] == want[s] &&
                        (want[s] != 1 || std::memcmp(flat[s].data(), want_flat[s].data(), 3 * sizeof(double)) == 0);
        if (!ok && ++mismatches <= 3)
          ADD_FAILURE() << "trial " << trial << " side " << s << " " << to_string(isa) << ": flats " << got[s]
                        << " vs " << want[s];
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
  // The grid ties vertices along the axes and diagonals: each kind of feature must be common, so that the test is
  // one of edges and faces too.
  std::printf("sides: %d vertices, %d edges, %d faces; flats 0 / 1 / 2: %d / %d / %d\n", features[0], features[1],
              features[2], flats_seen[0], flats_seen[1], flats_seen[2]);
  for (int f = 0; f < 3; ++f) EXPECT_GT(features[f], 1000) << "feature " << f;
  EXPECT_GT(flats_seen[1], 1000);
}

}  // namespace
}  // namespace batchcol::testing
