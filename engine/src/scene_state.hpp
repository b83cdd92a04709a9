// Private state of batchcol::Scene: object storage (structure of arrays), handle slots and the per-frame buffers.
#pragma once

#include "batchcol/scene.hpp"
#include "broadphase/aabb_soa.hpp"
#include "broadphase/pairs.hpp"
#include "broadphase/sweep_and_prune.hpp"

#include <tbb/task_arena.h>

#include <cstdint>
#include <memory>
#include <vector>

namespace batchcol {

/// A shape's AABB in closed form, in its local frame: the world box under rotation R and translation t is centred
/// at t + R centre with half extent, along world axis i,
///   sum_j |R_ij| box_j  +  sqrt(sum_j (R_ij ellipse_j)^2)  +  ball,
/// i.e. the shape is bounded by the Minkowski sum of a box, an ellipsoid and a ball. That sum is exact (tight) for
/// spheres (ball), boxes (box + inflation ball), capsules (box (0, 0, h) + ball), ellipsoids (ellipse) and cylinders
/// (box (0, 0, h) + flat ellipse (r, r, 0): a disc); hulls get their rotated local box (box around the local box
/// centre). Cones and triangles have no such form and set `exact_path`: their box comes from compute_aabb().
struct LocalBound {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero(), box = Eigen::Vector3d::Zero(), ellipse = Eigen::Vector3d::Zero();
  double ball = 0.0;
  bool exact_path = false;
};

LocalBound local_bound(const Shape& shape);

/// The objects with a finite box (every shape type but halfspace), one array per field; dense indices, removal
/// swaps the last object into the hole.
struct FiniteObjects {
  std::vector<std::uint32_t> shape, slot;
  std::vector<double> tx, ty, tz, qw, qx, qy, qz;               // pose
  std::vector<double> cx, cy, cz, bx, by, bz, ex, ey, ez, ball;  // LocalBound of the shape, copied per object
  std::vector<std::uint8_t> exact_path;
  broadphase::FilterSoa filter;                                   // always sized (group, mask, body per object)

  std::size_t size() const { return shape.size(); }
  void push_back(std::uint32_t shape_index, std::uint32_t slot_index, const Pose& pose, const LocalBound& bound,
                 const CollisionFilter& f);
  void set_pose(std::size_t i, const Pose& pose);
  void set_filter(std::size_t i, const CollisionFilter& f);
  /// Moves the last object to index i and drops the last slot.
  void swap_remove(std::size_t i);
  /// Renumbers the objects: the object at index order[k] moves to index k (order is a permutation).
  void permute(const std::vector<std::uint32_t>& order);
  Pose pose(std::size_t i) const;
  CollisionFilter get_filter(std::size_t i) const;
};

struct HalfspaceObject {
  std::uint32_t shape = 0, slot = 0;
  Pose pose;
  CollisionFilter filter;
};

/// A candidate pair in scene storage: finite object indices, or halfspace indices with kHalfspaceBit set.
constexpr std::uint32_t kHalfspaceBit = 0x80000000u;
struct ScenePair {
  std::uint32_t a = 0, b = 0;
};

/// A halfspace in the world frame: the solid {x : normal . x <= offset}, inflation included.
struct WorldHalfspace {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;
};

enum class SlotKind : std::uint8_t { free, finite, halfspace };
struct Slot {
  std::uint32_t generation = 0;
  SlotKind kind = SlotKind::free;
  std::uint32_t index = 0;  // into FiniteObjects or halfspaces
};

bool filters_pass(const CollisionFilter& a, const CollisionFilter& b);
bool is_default(const CollisionFilter& f);

/// One object's pose in one 56-byte record: the pair batch gathers poses in pair order (random object order), and
/// one record costs one or two cache lines where the seven SoA arrays cost seven.
struct PoseRecord {
  double tx, ty, tz, qw, qx, qy, qz;
};

/// World boxes of all finite objects (margin included), rounded outward to float, and the pose records, in one pass
/// over the objects (scene_aabb.cpp).
void compute_world_boxes(const ShapeTable& shapes, const FiniteObjects& objects, double margin,
                         broadphase::AabbSoa& boxes, std::vector<PoseRecord>& poses);

struct Scene::State {
  std::shared_ptr<const ShapeTable> shapes;
  std::vector<LocalBound> shape_bounds;  // per shape of the table
  std::vector<Slot> slots;
  std::vector<std::uint32_t> free_slots;
  FiniteObjects finite;
  std::vector<HalfspaceObject> halfspaces;
  std::size_t filtered_objects = 0;  // finite objects with a non-default filter: 0 lets the sweep skip the filter
  bool topology_changed = true;      // objects added or removed since the last frame: the broad phase rebuilds
  std::size_t changes_since_renumber = 0;  // adds and removes since the last renumber_spatially()

  // Frame buffers, kept across frames.
  broadphase::AabbSoa boxes;
  std::vector<PoseRecord> pose_records;  // copy of the finite objects' poses, by object, for the pair gather
  broadphase::FilterSoa no_filter;
  broadphase::SweepAndPrune sap;
  std::vector<broadphase::CandidatePair> sap_pairs;
  std::vector<std::vector<ScenePair>> halfspace_chunks;  // per fixed chunk of objects
  std::vector<ScenePair> halfspace_pairs;
  std::vector<WorldHalfspace> world_halfspaces;
  PairBatch batch;
  std::unique_ptr<tbb::task_arena> arena;
  int arena_threads = -1;
  std::size_t reallocations = 0;

  ObjectHandle handle_of(std::uint32_t slot) const { return {slot, slots[slot].generation}; }
  const Slot& checked(ObjectHandle object) const;  // throws InputError for an invalid handle
  std::size_t frame_buffer_bytes() const;
  /// Right after a broad-phase rebuild, when at least 1/8 of the objects were added or removed since it last ran
  /// (added objects take the last indices, removals move the last object into the hole): numbers the finite objects in the sweep-and-prune's spatial order (objects of
  /// one grid cell get neighbouring indices) and renumbers this frame's boxes, pose records and pairs (sorted again)
  /// and the sweep-and-prune's cells. Random insertion order otherwise makes every per-object pass of a frame (boxes
  /// refreshed in the cells, pair gathers for the narrow phase) a random memory access. Handles are unchanged.
  void renumber_spatially();
  /// Halfspaces against every finite box and against each other (scene_pairs.cpp).
  void find_halfspace_pairs();
  /// Fills `batch` and the result handles from sap_pairs then halfspace_pairs (scene_pairs.cpp).
  void fill_batch(SceneResults& results);
};

}  // namespace batchcol
