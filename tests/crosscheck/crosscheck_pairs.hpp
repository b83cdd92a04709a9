// Random pairs for the cross-checks against FCL and Bullet.
#pragma once

#include "support/generators.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace batchcol::crosscheck {

struct CrossPairs {
  ShapeTable shapes;
  PairBatch batch;
  std::vector<double> plane_gap;  // g of each pair (see make_pairs); the exact signed distance for halfspace pairs
};

/// `count` pairs, each made of one shape of type `primary` and one of a type drawn uniformly from `partners`, the
/// primary shape on side a or b with equal probability. Shapes are 2-40 cm (testing::random_shape), poses are
/// random. Shape b is placed along a random unit direction u so that the planes orthogonal to u touching a and b
/// are a gap g apart (g > 0: separated by at least g). Half the pairs get g log-uniform in [1e-5, 0.2] m; the other
/// half g = -f * (width_a(u) + width_b(u)), f uniform in [0, 0.5], which overlaps in most cases (about 40% of all
/// pairs overlap; 30% with triangles, which miss each other more easily). When one shape is a halfspace, u is its
/// normal and g is the exact signed distance. Reproducible from `seed`.
CrossPairs make_pairs(std::uint64_t seed, ShapeType primary, const std::vector<ShapeType>& partners,
                      std::size_t count);

}  // namespace batchcol::crosscheck
