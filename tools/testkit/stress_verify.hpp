// The `verified` check of `batchcol stress`: the scene's candidate pairs equal the brute-force pairs of the same
// float boxes, on the whole scene (up to kWholeSceneLimit objects) or, beyond, among the objects lying fully inside
// a random sub-volume (pairs between two such objects depend on nothing outside it).
#pragma once

#include <batchcol/scene.hpp>

#include <cstdint>
#include <string>

namespace batchcol::testkit {

constexpr std::size_t kWholeSceneLimit = 20000;

struct Verification {
  bool equal = false;
  std::string scope;                // "whole scene" or "sub-volume"
  std::size_t objects = 0;          // objects compared
  std::size_t pairs = 0;            // brute-force pairs among them
  std::size_t missing = 0, extra = 0;  // brute-force pairs the scene missed / scene pairs brute force lacks
};

/// Compares the candidates of the scene's last collide() (`results`) with brute force.
Verification verify_candidates(const Scene& scene, const SceneResults& results, std::uint64_t seed);

}  // namespace batchcol::testkit
