// The reference every `batchcol accuracy` measurement is compared with: per pair, the signed distance, witness
// points and normal of a tight double-precision solution, analytic where a closed form exists (see
// analytic_reference.hpp), else plain GJK/EPA in double at tolerance 1e-12 (bench_pairs.hpp reference_options),
// trusted only when its duality gap certified it (status converged).
#pragma once

#include "testkit/bench_pairs.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace batchcol::testkit {

struct ReferencePair {
  double distance = 0;  // signed: negative is a penetration depth
  Eigen::Vector3d witness_a = Eigen::Vector3d::Zero(), witness_b = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, from a to b
  bool certified = false;  // analytic, or the numeric reference converged; uncertified pairs are not scored
  bool analytic = false;
};

struct ReferenceSet {
  std::vector<ReferencePair> pairs;
  /// "analytic", "gjk-1e-12" or "analytic+gjk-1e-12" (closed form where it applies, numeric fallback elsewhere).
  std::string kind;
  /// Witness points are unique when one shape is strictly convex (sphere, ellipsoid) or the reference is analytic
  /// (generic poses); elsewhere (polytope faces, cylinder caps, ...) a whole face may be closest.
  bool unique_witnesses = false;
  /// Largest |analytic - numeric| distance over the analytic pairs: the two references checked against each other.
  double analytic_vs_numeric = 0;
};

/// References for every pair of `p` (the numeric one is recomputed to get witness points and normals).
ReferenceSet compute_references(const BenchPairs& p, int threads);

}  // namespace batchcol::testkit
