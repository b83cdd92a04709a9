// Pair batches of `batchcol bench` and `batchcol accuracy`: one shape-type pair per case, placed at a prescribed
// reference signed distance (the regime), seeded and identical on every machine.
#pragma once

#include <batchcol/batch.hpp>
#include <batchcol/shapes.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace batchcol::testkit {

/// A shape type of the bench; hulls carry their vertex count (convex8, convex250, convex940).
struct BenchShapeKind {
  ShapeType type = ShapeType::sphere;
  int hull_vertices = 0;  // convex only
  std::string name;
};

struct BenchCase {
  BenchShapeKind a, b;
  std::string name() const { return a.name + "-" + b.name; }
};

/// "TYPE-TYPE" (sphere, capsule, box, cylinder, cone, ellipsoid, convex/convex8, convex250, convex940) or "all":
/// every unordered pair of the first seven plus convex250-convex250 and convex940-convex940. Throws InputError.
std::vector<BenchCase> parse_bench_cases(const std::string& spec);

enum class Regime { distant, close, overlap };
Regime parse_regime(const std::string& name);  // throws InputError
const char* to_string(Regime regime);

/// Signed-distance range of a regime: distant [0.1, 1] m, close [1e-4, 1e-2] m, overlap [-1e-2, -1e-4] m.
struct DistanceRange {
  double lo, hi;
};
DistanceRange regime_range(Regime regime);

/// The reference every bench number is compared with: double precision, tolerance 1e-12, plain GJK, closed forms
/// off, penetration level (so overlapping pairs get their EPA depth).
QueryOptions reference_options(int threads);

struct BenchPairs {
  ShapeTable shapes;
  PairBatch pairs;
  std::vector<double> reference;  // reference signed distance of each pair (reference_options)
};

/// `count` pairs of `bench_case`: shapes of 2-40 cm drawn from a seeded pool, random rotations, and shape b moved
/// from the centre of a along a random direction until the reference signed distance equals a target drawn
/// uniformly in the regime's range (safeguarded Newton on the offset, bracketed by bisection).
BenchPairs make_bench_pairs(const BenchCase& bench_case, Regime regime, std::size_t count, std::uint64_t seed,
                            int threads);

}  // namespace batchcol::testkit
