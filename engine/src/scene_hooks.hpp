// What the tests and the tools (testkit, `batchcol stress`) read of a Scene beyond the public API: its last broad-
// phase boxes and its reallocation counter. Kept out of batchcol/scene.hpp, which holds what a user calls; in-tree
// code reaches this header through the batchcol_internal target (engine/CMakeLists.txt).
#pragma once

#include "batchcol/scene.hpp"

#include <cstddef>
#include <vector>

namespace batchcol::detail {

struct SceneHooks {
  /// The float world boxes of the scene's last collide() (margin included) of all objects except halfspaces,
  /// widened to double exactly, with their objects: for checks and benchmarks against other broad phases. Throws
  /// InputError when objects were added or removed since that collide().
  static void last_aabbs(const Scene& scene, std::vector<Aabb>& boxes, std::vector<ObjectHandle>& objects);
  /// How many collide() calls moved one of the scene's frame buffers (a reallocation). Stays constant once the
  /// buffers are warm and the object and pair counts do not grow: the no-allocation-per-frame check.
  static std::size_t buffer_reallocations(const Scene& scene);
};

}  // namespace batchcol::detail
