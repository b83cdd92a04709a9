// The embedded scene of `batchcol demo`: a deterministic mix of primitive and convex-hull pairs, half of them
// separated and half overlapping by construction.
#pragma once

#include <batchcol/batch.hpp>
#include <batchcol/shapes.hpp>

#include <cstddef>
#include <cstdint>

namespace batchcol::testkit {

struct DemoScene {
  ShapeTable shapes;
  PairBatch pairs;
  std::size_t overlapping = 0;  // pairs placed so that they certainly overlap; all others are certainly separated
};

DemoScene make_demo_scene(std::size_t pair_count, std::uint64_t seed = 20240601);

}  // namespace batchcol::testkit
