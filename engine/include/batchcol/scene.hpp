// Scenes: many objects (a shape of a ShapeTable + a pose + a collision filter) whose candidate pairs come from the
// broad phase and go through the batched narrow phase in one call.
//
// Scene::collide(options) runs, every frame:
//   1. world AABBs of all objects from their poses (structure of arrays, one vectorised loop for the primitives),
//      inflated by options.margin and rounded outward to float;
//   2. the parallel sweep-and-prune broad phase (full rebuild on the first frame or after objects were added or
//      removed, incremental update after) plus, for halfspaces (infinite boxes, kept out of the sweep), a test of
//      each halfspace against every object's box; a rebuild also renumbers the objects internally in the broad
//      phase's spatial order (handles do not change), so that every per-object pass of the following frames reads
//      memory nearly sequentially;
//   3. one PairBatch of all candidate pairs -> batchcol::collide() at options.level;
// and returns every candidate pair with its objects and its narrow-phase result. Buffers are kept from frame to
// frame: after the first frames (warm-up), a frame with about as many objects and pairs allocates nothing in the
// scene (the narrow-phase executor keeps a small per-task index buffer of its own).
//
// Conventions as in batch.hpp: for candidate k, the normal points from object_a[k] to object_b[k]; witness points
// are in the world frame; the signed distance is negative when the objects overlap. A pair is reported as
// colliding when its distance is <= options.margin. Results are identical (bitwise, same order) for any thread
// count, for a given sequence of add/remove/update calls.
#pragma once

#include "batchcol/export.hpp"

#include "batchcol/batch.hpp"
#include "batchcol/pose.hpp"
#include "batchcol/shapes.hpp"

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

namespace batchcol {

/// Which pairs may collide (Bullet-style): objects a and b are tested iff (a.group & b.mask) != 0 and
/// (b.group & a.mask) != 0, and they are not two parts of one rigid body (same body id >= 0).
struct CollisionFilter {
  std::uint32_t group = 1;
  std::uint32_t mask = 0xffffffffu;
  std::int32_t body = -1;  // -1: not part of a multi-shape body
};

/// Stable reference to a scene object: unchanged by other objects' additions and removals. A removed object's
/// handle stays invalid forever (its slot is reused with a new generation).
struct ObjectHandle {
  std::uint32_t slot = std::numeric_limits<std::uint32_t>::max();
  std::uint32_t generation = 0;

  friend bool operator==(const ObjectHandle& x, const ObjectHandle& y) {
    return x.slot == y.slot && x.generation == y.generation;
  }
  friend bool operator!=(const ObjectHandle& x, const ObjectHandle& y) { return !(x == y); }
  friend bool operator<(const ObjectHandle& x, const ObjectHandle& y) {
    return x.slot < y.slot || (x.slot == y.slot && x.generation < y.generation);
  }
};

/// Wall-clock milliseconds of the stages of the last Scene::collide().
struct SceneTimings {
  double renumber_ms = 0;      // objects renumbered in the broad phase's spatial order (frames that rebuilt it)
  double aabb_ms = 0;          // world AABBs from the poses
  double sap_bucket_ms = 0;    // sweep-and-prune: grid choice and bucketing into cells
  double sap_sweep_ms = 0;     //   per-cell sort and sweep
  double sap_emit_ms = 0;      //   merging and sorting the pairs
  double halfspace_ms = 0;     // halfspaces against all objects
  double batch_ms = 0;         // filling the PairBatch of candidates
  double narrowphase_ms = 0;   // batchcol::collide() on the candidates
  double total_ms = 0;         // the whole call
  double broadphase_ms() const {
    return renumber_ms + aabb_ms + sap_bucket_ms + sap_sweep_ms + sap_emit_ms + halfspace_ms;
  }
};

/// Everything Scene::collide() reports. Candidate k is the pair (object_a[k], object_b[k]); pairs.*[k] is its
/// narrow-phase result at the requested level (arrays of values the level does not compute are empty: PairResults).
struct SceneResults {
  std::vector<ObjectHandle> object_a, object_b;
  PairResults pairs;
  std::vector<std::uint32_t> colliding;  // indices k with pairs.collide[k], increasing
  SceneTimings timings;
  bool incremental = false;  // the broad phase updated the previous frame's grid instead of rebuilding

  std::size_t candidate_count() const { return object_a.size(); }
  std::size_t colliding_count() const { return colliding.size(); }
};

namespace detail {
struct SceneHooks;  // engine/src/scene_hooks.hpp: what the tests and tools read beyond the API
}

class BATCHCOL_API Scene {
 public:
  /// The scene keeps `shapes` alive; objects refer to its shapes by index. Throws InputError when null.
  explicit Scene(std::shared_ptr<const ShapeTable> shapes);
  ~Scene();
  Scene(Scene&&) noexcept;
  Scene& operator=(Scene&&) noexcept;
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  /// Adds an object. Throws InputError for a shape index out of range, a non-finite translation or one beyond
  /// 1e30 m (the broad phase stores float boxes), or a quaternion that is not unit within kUnitTolerance (within it,
  /// it is normalised).
  ObjectHandle add(std::uint32_t shape, const Pose& pose, const CollisionFilter& filter = {});
  /// Removes an object; throws InputError for an invalid handle.
  void remove(ObjectHandle object);
  /// Moves an object (same checks as add()).
  void set_pose(ObjectHandle object, const Pose& pose);
  void set_filter(ObjectHandle object, const CollisionFilter& filter);

  bool contains(ObjectHandle object) const;
  std::size_t size() const;
  std::uint32_t shape(ObjectHandle object) const;
  Pose pose(ObjectHandle object) const;  // as stored (normalised quaternion)
  CollisionFilter filter(ObjectHandle object) const;
  const ShapeTable& shapes() const;

  /// Runs the pipeline described at the top of this file. Throws InputError for invalid options.
  /// options.threads applies to every stage (0 = all cores).
  void collide(const QueryOptions& options, SceneResults& results);

  /// Bytes held by the scene's buffers (capacities), excluding the shape table and the caller's results.
  std::size_t memory_bytes() const;

 private:
  struct State;                // private implementation (engine/src/scene_state.hpp)
  friend class RaySceneIndex;  // reads the objects and poses to build its ray acceleration (batchcol/rays.hpp)
  friend struct detail::SceneHooks;
  std::unique_ptr<State> state_;
};

}  // namespace batchcol
