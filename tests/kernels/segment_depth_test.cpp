// Penetration depth of a capsule whose core segment overlaps a cylinder or cone (issue #16, item 10a): EPA ended
// max_iterations with depth errors of ~1e-5 x the size; the closed form (kernels/segment_depth.hpp) must converge.
// The reference is a brute-force search, in long double, of min over unit n of h_A(n) + h_S(-n) (support
// functions written here from the shape definitions): a compass search on the sphere from the best of 4000
// directions, plus dense 1D searches along the creases where that function has a kink (the great circle
// orthogonal to the segment, the cylinder's equator, the cone's side-normal circle), where a compass search can
// stall. Both the reference and the engine evaluate the function at some direction, so each is an upper bound of
// the depth; the engine must never be worse than the search, and the search must come within a bound of it.
#include "support/generators.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace batchcol {
namespace {

using LD = long double;
using V3 = Eigen::Matrix<LD, 3, 1>;

struct Config {
  bool cone;
  double R, h;          // A: radius, half length (core frame = A's frame)
  Eigen::Vector3d p0, p1;  // the capsule's core segment in A's frame
  double radius;        // capsule radius
};

LD support_a(const Config& c, const V3& n) {
  const LD rho = std::hypot(n.x(), n.y());
  if (!c.cone) return LD(c.R) * rho + LD(c.h) * std::abs(n.z());
  return std::max(LD(c.h) * n.z(), LD(c.R) * rho - LD(c.h) * n.z());
}

LD objective(const Config& c, V3 n) {
  n /= n.norm();
  return support_a(c, n) + std::max(-n.dot(c.p0.cast<LD>()), -n.dot(c.p1.cast<LD>()));
}

/// Dense samples of t -> objective(point(t)) on [0, 2 pi), then golden-section refinement around the 4 best local
/// minima of the samples.
template <class Curve> LD search_curve(const Config& c, const Curve& point) {
  const int n = 20000;
  std::vector<LD> v(n);
  for (int i = 0; i < n; ++i) v[i] = objective(c, point(2 * M_PI * i / n));
  std::vector<int> minima;
  for (int i = 0; i < n; ++i)
    if (v[i] <= v[(i + 1) % n] && v[i] <= v[(i + n - 1) % n]) minima.push_back(i);
  std::sort(minima.begin(), minima.end(), [&](int a, int b) { return v[a] < v[b]; });
  LD best = *std::min_element(v.begin(), v.end());
  const LD step = 2 * M_PI / n, g = (std::sqrt(LD(5)) - 1) / 2;
  for (std::size_t k = 0; k < std::min<std::size_t>(4, minima.size()); ++k) {
    LD lo = minima[k] * step - step, hi = minima[k] * step + step;
    for (int it = 0; it < 200; ++it) {
      const LD x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
      if (objective(c, point(x1)) < objective(c, point(x2))) hi = x2;
      else lo = x1;
    }
    best = std::min(best, objective(c, point((lo + hi) / 2)));
  }
  return best;
}

LD reference_core_depth(const Config& c, testing::Rng& rng) {
  // Compass search from the best sample directions (Fibonacci sphere), 16 directions rotated at random per step.
  const int samples = 4000;
  std::vector<std::pair<LD, V3>> start;
  for (int i = 0; i < samples; ++i) {
    const LD z = 1 - (2 * i + LD(1)) / samples, r = std::sqrt(1 - z * z), phi = i * LD(2.399963229728653);
    const V3 n(r * std::cos(phi), r * std::sin(phi), z);
    start.emplace_back(objective(c, n), n);
  }
  std::partial_sort(start.begin(), start.begin() + 16, start.end(),
                    [](const auto& a, const auto& b) { return a.first < b.first; });
  LD best = start[0].first;
  for (int s = 0; s < 16; ++s) {
    V3 n = start[s].second;
    LD value = start[s].first, step = 0.05;
    for (int it = 0; it < 4000 && step > 1e-13; ++it) {
      const V3 t1 = (std::abs(n.x()) < 0.9 ? V3::UnitX() : V3::UnitY()).cross(n).normalized(), t2 = n.cross(t1);
      const LD phase = testing::uniform(rng, 0, 2 * M_PI);
      bool moved = false;
      for (int k = 0; k < 16; ++k) {
        const LD a = phase + k * M_PI / 8;
        const V3 m = (n + step * (std::cos(a) * t1 + std::sin(a) * t2)).normalized();
        const LD f = objective(c, m);
        if (f < value) value = f, n = m, moved = true;
      }
      if (!moved) step *= 0.7L;
    }
    best = std::min(best, value);
  }
  // The creases.
  const V3 d = (c.p1 - c.p0).cast<LD>();
  if (d.norm() > 0) {
    const V3 u = d.normalized(), e1 = (std::abs(u.x()) < 0.9 ? V3::UnitX() : V3::UnitY()).cross(u).normalized();
    const V3 e2 = u.cross(e1);
    best = std::min(best, search_curve(c, [&](LD t) { return V3(std::cos(t) * e1 + std::sin(t) * e2); }));
  }
  // Cylinder: the equator; cone: the side normals (2h r + R z) / L.
  const LD zc = c.cone ? LD(c.R) / std::hypot(LD(c.R), 2 * LD(c.h)) : 0, rc = std::sqrt(1 - zc * zc);
  best = std::min(best, search_curve(c, [&](LD t) { return V3(rc * std::cos(t), rc * std::sin(t), zc); }));
  return best;
}

/// Random segment through a random point inside A (so the cores overlap), partly or wholly inside; `along_axis`:
/// parallel to the axis, off it, short and wholly inside (the depth is then on the curved side or a cap).
Config random_config(testing::Rng& rng, bool cone, bool along_axis = false) {
  Config c;
  c.cone = cone;
  c.R = testing::uniform(rng, 0.1, 1.0);
  c.h = testing::uniform(rng, 0.1, 1.0);
  c.radius = testing::uniform(rng, 0.01, 0.3);
  const double z = testing::uniform(rng, -c.h + 1e-3, c.h - 1e-3) * (along_axis ? 0.8 : 1.0);
  const double max_rho = std::max(1e-4, (cone ? c.R * (c.h - z) / (2 * c.h) : c.R) - 1e-3);
  const double rho = testing::uniform(rng, 0.0, max_rho), phi = testing::uniform(rng, 0.0, 2 * M_PI);
  const Eigen::Vector3d centre(rho * std::cos(phi), rho * std::sin(phi), z);
  // Directions: random, and 1 in 5 along or across the axis (degenerate projections of the rims).
  Eigen::Vector3d u = testing::random_unit_vector(rng);
  const int kind = static_cast<int>(testing::uniform(rng, 0, 10));
  if (kind == 0) u = Eigen::Vector3d::UnitZ();
  if (kind == 1) u = Eigen::Vector3d(u.x(), u.y(), 0).normalized();
  double half = testing::uniform(rng, 0.01, 1.0);
  double t = testing::uniform(rng, -1.0, 1.0) * half;  // the centre's position along the segment
  if (along_axis) u = Eigen::Vector3d::UnitZ(), half = 0.1 * c.h * testing::uniform(rng, 0.01, 1.0), t = 0;
  c.p0 = centre + (t - half) * u;
  c.p1 = centre + (t + half) * u;
  return c;
}

struct CapsuleRun {
  testing::SingleResult r;
  Eigen::Vector3d core_a_point, segment[2];  // in world
};

CapsuleRun run(const Config& c, testing::Rng& rng, bool capsule_first, Precision precision, double tolerance) {
  const Pose body{Eigen::Vector3d(0.3, -0.2, 0.1), testing::random_rotation(rng)};
  const Eigen::Vector3d mid = (c.p0 + c.p1) / 2, axis = c.p1 - c.p0;
  const double half = axis.norm() / 2;
  const Eigen::Quaterniond local = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis);
  const Pose capsule{body.translation + body.rotation * mid, body.rotation * local};
  const Shape a = c.cone ? Shape::cone(c.R, c.h) : Shape::cylinder(c.R, c.h), b = Shape::capsule(c.radius, half);
  QueryOptions o;
  o.level = QueryLevel::penetration;
  o.precision = precision;
  o.tolerance = tolerance;
  CapsuleRun out;
  out.r = capsule_first ? testing::run_pair(b, capsule, a, body, o) : testing::run_pair(a, body, b, capsule, o);
  out.segment[0] = body.translation + body.rotation * c.p0;
  out.segment[1] = body.translation + body.rotation * c.p1;
  // The witness on A (in A's local frame, then checked against A's boundary).
  const Eigen::Vector3d wa = capsule_first ? out.r.witness_b : out.r.witness_a;
  out.core_a_point = body.rotation.inverse() * (wa - body.translation);
  return out;
}

double segment_distance(const Eigen::Vector3d& x, const Eigen::Vector3d& s0, const Eigen::Vector3d& s1) {
  const Eigen::Vector3d d = s1 - s0;
  const double t = d.squaredNorm() > 0 ? std::clamp((x - s0).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
  return (s0 + t * d - x).norm();
}

/// Signed distance of a local point to the boundary of the cylinder or cone (0 on it).
double boundary_offset(const Config& c, const Eigen::Vector3d& x) {
  const double rho = std::hypot(x.x(), x.y());
  if (!c.cone) return std::max(rho - c.R, std::abs(x.z()) - c.h);
  const double L = std::hypot(c.R, 2 * c.h);
  return std::max(-c.h - x.z(), (2 * c.h * rho - c.R * (c.h - x.z())) / L);
}

void check_capsules(std::uint64_t seed, bool along_axis, const char* what) {
  testing::Rng rng(seed);
  double worst[2] = {0, 0}, worst_ahead = 0;
  for (bool cone : {false, true})
    for (int i = 0; i < 60; ++i) {
      const Config c = random_config(rng, cone, along_axis);
      const double depth = double(reference_core_depth(c, rng)) + c.radius;
      for (Precision precision : {Precision::float64, Precision::float32})
        for (bool capsule_first : {false, true}) {
          SCOPED_TRACE(std::string(cone ? "cone" : "cylinder") + " " + to_string(precision) + " pair " +
                       std::to_string(i) + (capsule_first ? " capsule first" : " capsule second"));
          const bool single = precision == Precision::float32;
          const CapsuleRun r = run(c, rng, capsule_first, precision, 1e-12);
          ASSERT_EQ(r.r.status, Status::converged);
          EXPECT_TRUE(r.r.collide);
          // Double: the engine is never worse than the search (1e-13 of rounding) and the search comes within
          // 1e-10 of the engine (its compass steps end at 1e-13 rad, crease golden sections at 1e-16).
          const double error = r.r.distance + depth;  // > 0: the engine's depth is smaller
          if (!single) {
            EXPECT_GT(error, -1e-13);
            EXPECT_LT(error, 1e-10);
          } else {
            EXPECT_NEAR(error, 0.0, 5e-6);  // float: about 10 float epsilons of the ~1 m size
          }
          worst[single] = std::max(worst[single], std::abs(error));
          if (!single) worst_ahead = std::max(worst_ahead, error);
          // Witnesses: on A's boundary and on the capsule's surface, their gap the distance along the normal.
          const double bound = single ? 5e-6 : 1e-10;
          EXPECT_NEAR(boundary_offset(c, r.core_a_point), 0.0, bound);
          const Eigen::Vector3d wb = capsule_first ? r.r.witness_a : r.r.witness_b;
          EXPECT_NEAR(segment_distance(wb, r.segment[0], r.segment[1]), c.radius, bound);
          const Eigen::Vector3d gap = r.r.witness_b - r.r.witness_a;
          EXPECT_LT((gap - r.r.distance * r.r.normal).norm(), bound);
        }
    }
  std::printf("[measured] %s, |depth - search| double %.3g m (engine ahead by up to %.3g m), float %.3g m\n", what,
              worst[0], worst_ahead, worst[1]);
}


TEST(SegmentDepth, CapsuleOverlappingCylinderOrConeConvergesToTheReference) {
  check_capsules(16, false, "capsule overlapping cylinder/cone");
}

TEST(SegmentDepth, CapsuleInsideAlongTheAxisConvergesToTheReference) {
  check_capsules(17, true, "capsule inside cylinder/cone along its axis");
}

}  // namespace
}  // namespace batchcol
