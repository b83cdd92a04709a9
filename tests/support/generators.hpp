// Seeded generators of shapes, poses and pairs shared by the tests and the benchmarks. They draw from the testkit's
// PortableRandom, so a seed gives the same shapes and poses with every standard library (std:: distributions and
// Eigen's Random(), which calls std::rand, do not).
#pragma once

#include "batchcol/batchcol.hpp"
#include "testkit/portable_random.hpp"

#include <ostream>
#include <vector>

namespace batchcol::testing {

using Rng = testkit::PortableRandom;

double uniform(Rng& rng, double lo, double hi);
/// Uniform in the cube [-scale, scale]^3 (what testing::random_vector(rng) * scale draws, but seeded and portable).
Eigen::Vector3d random_vector(Rng& rng, double scale = 1.0);
Eigen::Quaterniond random_rotation(Rng& rng);
Eigen::Vector3d random_unit_vector(Rng& rng);

/// Every bounded shape type (halfspace excluded).
std::vector<ShapeType> bounded_shape_types();

/// A random shape of `type` with sizes in [min_size, max_size] metres (hulls: random points on a sphere).
Shape random_shape(Rng& rng, ShapeType type, double min_size = 0.02, double max_size = 0.4);

/// Points of a convex polytope: `n` random points on an ellipsoid with radii in [min_size, max_size].
std::vector<Eigen::Vector3d> random_hull_points(Rng& rng, int n, double min_size, double max_size);

/// A shape of `type` with reflection symmetry in the three coordinate planes of its frame (cones: in the two
/// planes containing their axis). Hulls are `seeds` random points mirrored in the three planes.
Shape symmetric_shape(Rng& rng, ShapeType type, int seeds = 6);

/// Reference signed distance of two shapes by a slow, independent route: for separated pairs, long-double
/// projected-gradient on the support functions is not independent enough, so the tests use closed forms instead;
/// this helper returns the extent of a shape along local direction d: max <x, d> over the shape (inflation
/// included), computed from the shape definition (not from the kernels).
double extent(const Shape& shape, const Eigen::Vector3d& d);

/// Runs one pair through the public API.
struct SingleResult {
  Status status;
  bool collide;
  double distance;
  Eigen::Vector3d witness_a, witness_b, normal;
  int iterations;
};
SingleResult run_pair(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, const QueryOptions& options);

}  // namespace batchcol::testing

namespace batchcol {
// Readable enum values in GoogleTest messages (found by argument-dependent lookup).
inline void PrintTo(Status s, std::ostream* os) { *os << to_string(s); }
inline void PrintTo(Solver s, std::ostream* os) { *os << to_string(s); }
inline void PrintTo(ShapeType s, std::ostream* os) { *os << to_string(s); }
inline void PrintTo(QueryLevel s, std::ostream* os) { *os << to_string(s); }
}  // namespace batchcol
