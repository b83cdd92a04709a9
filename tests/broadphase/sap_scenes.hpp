// Seeded AABB scenes shared by the broad-phase tests: uniform, clustered and degenerate layouts. Drawn from the
// testkit's PortableRandom, one draw per statement, so a seed gives the same scene with every standard library and
// compiler (std:: distributions and the order of evaluation of function arguments do not).
#pragma once

#include "batchcol/shapes.hpp"  // batchcol::Aabb: the broad phase itself sees only plain types
#include "broadphase/aabb_soa.hpp"
#include "broadphase/pairs.hpp"
#include "testkit/portable_random.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <ostream>
#include <vector>

namespace batchcol::broadphase {
// GoogleTest prints pairs as (a,b) (found by argument-dependent lookup).
inline void PrintTo(const CandidatePair& p, std::ostream* os) { *os << "(" << p.a << "," << p.b << ")"; }
}  // namespace batchcol::broadphase

namespace batchcol::broadphase::testing {

using Rng = testkit::PortableRandom;

inline double uniform(Rng& rng, double lo, double hi) { return rng.uniform(lo, hi); }

/// Uniform in [lo, hi]^3, x drawn first.
inline Eigen::Vector3d uniform3(Rng& rng, double lo, double hi) {
  const double x = uniform(rng, lo, hi);
  const double y = uniform(rng, lo, hi);
  const double z = uniform(rng, lo, hi);
  return {x, y, z};
}

/// Standard normal deviate (Box-Muller from the portable source).
inline double gauss(Rng& rng) {
  const double u = std::max(rng.uniform(), 1e-300), v = rng.uniform();
  return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * 3.14159265358979323846 * v);
}

inline Aabb box_at(const Eigen::Vector3d& centre, const Eigen::Vector3d& half) { return {centre - half, centre + half}; }

inline AabbSoa to_soa(const std::vector<Aabb>& boxes, double margin = 0.0) {
  AabbSoa s;
  s.assign(boxes, margin);
  return s;
}

/// n boxes with centres uniform in [lo, lo + side]^3 and half sizes uniform in [0.5, 1.5] * half_size.
inline std::vector<Aabb> uniform_boxes(Rng& rng, std::size_t n, double side, double half_size, double lo = 0.0) {
  std::vector<Aabb> b;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d c = uniform3(rng, lo, lo + side);
    const Eigen::Vector3d h = uniform3(rng, 0.5, 1.5) * half_size;
    b.push_back(box_at(c, h));
  }
  return b;
}

/// Half size giving about `overlaps` other boxes overlapping each box for n equal boxes in a unit cube.
inline double half_size_for(std::size_t n, double overlaps) {
  return 0.25 * std::cbrt(overlaps / static_cast<double>(std::max<std::size_t>(n, 2) - 1));
}

/// Gaussian clusters of boxes.
inline std::vector<Aabb> clustered_boxes(Rng& rng, std::size_t n, int clusters) {
  std::vector<Eigen::Vector3d> centres;
  for (int k = 0; k < clusters; ++k) centres.push_back(uniform3(rng, -50, 50).cwiseProduct(Eigen::Vector3d(1, 1, 0.1)));
  std::vector<Aabb> b;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& centre = centres[rng() % centres.size()];
    const double gx = gauss(rng);
    const double gy = gauss(rng);
    const double gz = gauss(rng);
    const Eigen::Vector3d c = centre + Eigen::Vector3d(gx, gy, gz);
    b.push_back(box_at(c, Eigen::Vector3d::Constant(uniform(rng, 0.02, 0.2))));
  }
  return b;
}

/// Random group/mask bits (a few bits, so that both outcomes are common) and bodies of 1..3 objects (-1 for some).
inline FilterSoa random_filter(Rng& rng, std::size_t n) {
  FilterSoa f;
  std::int32_t body = 0;
  for (std::size_t i = 0; i < n; ++i) {
    f.group.push_back(1u << (rng() % 4));
    f.mask.push_back(static_cast<std::uint32_t>(rng() % 16) | 1u);
    if (rng() % 4 == 0) f.body.push_back(-1);
    else {
      if (rng() % 3 == 0) ++body;
      f.body.push_back(body);
    }
  }
  return f;
}

}  // namespace batchcol::broadphase::testing
