// Seeded AABB scenes shared by the broad-phase tests: uniform, clustered and degenerate layouts.
#pragma once

#include "broadphase/aabb_soa.hpp"
#include "broadphase/pairs.hpp"

#include <cmath>
#include <cstdint>
#include <ostream>
#include <random>
#include <vector>

namespace batchcol::broadphase {
// GoogleTest prints pairs as (a,b) (found by argument-dependent lookup).
inline void PrintTo(const CandidatePair& p, std::ostream* os) { *os << "(" << p.a << "," << p.b << ")"; }
}  // namespace batchcol::broadphase

namespace batchcol::broadphase::testing {

using Rng = std::mt19937_64;

inline double uniform(Rng& rng, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }

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
    const Eigen::Vector3d c(uniform(rng, lo, lo + side), uniform(rng, lo, lo + side), uniform(rng, lo, lo + side));
    const Eigen::Vector3d h(uniform(rng, 0.5, 1.5) * half_size, uniform(rng, 0.5, 1.5) * half_size,
                            uniform(rng, 0.5, 1.5) * half_size);
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
  for (int k = 0; k < clusters; ++k) centres.emplace_back(uniform(rng, -50, 50), uniform(rng, -50, 50), uniform(rng, -5, 5));
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<Aabb> b;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d c = centres[rng() % centres.size()] + Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
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
