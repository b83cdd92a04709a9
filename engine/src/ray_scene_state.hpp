// Private state of batchcol::RaySceneIndex: a snapshot of the scene's objects in BVH leaf order, the LBVH and its
// 16-wide collapse.
#pragma once

#include "batchcol/rays.hpp"
#include "broadphase/aabb_soa.hpp"
#include "kernels/math.hpp"
#include "ray_bvh.hpp"
#include "ray_cast_arena.hpp"
#include "ray_huge_pages.hpp"
#include "ray_prepared.hpp"
#include "ray_wide_bvh.hpp"
#include "scene_state.hpp"

#include <memory>
#include <vector>

namespace batchcol {

/// One object as the ray traversal reads it: x_world = R x_local + t.
struct RayObject {
  kernels::Mat3<double> R;
  kernels::Vec3<double> t;
  std::uint32_t shape = 0;
  ObjectHandle handle;
};

/// A leaf as the cast reads it: the wide traversal's float ball filter (make_leaf_ball) and the object, in one
/// record of two cache lines aligned as a pair. A ray reaching a leaf reads the ball and, when the ball does not
/// reject it (most visits), the object: from two arrays that was two dependent misses on large scenes (1.6 MB of
/// balls and 11 MB of objects for 100k objects), here one (the second line of an aligned pair comes with the first).
struct alignas(128) RayLeaf {
  float ball[4];
  RayObject object;
};
static_assert(sizeof(RayLeaf) == 128, "RayLeaf layout");

struct RaySceneIndex::State {
  std::shared_ptr<const ShapeTable> shapes;
  std::size_t prepared_shape_count = 0;
  detail::PreparedRayShapes<double> prepared;

  // What the last update saw, to tell a refit (same objects, new poses) from a rebuild.
  std::vector<std::uint32_t> finite_slots, finite_shapes;
  std::vector<ObjectHandle> halfspace_handles;

  broadphase::AabbSoa boxes;  // by scene object index
  std::vector<PoseRecord> poses;
  RayBvh bvh;       // binary LBVH: built, refitted, and traversed (in double) by rays the float test cannot take
  WideBvh wide;     // its 16-wide collapse, traversed by every other ray
  // Read at random by the rays (a leaf each visit): on huge pages when large (ray_huge_pages.hpp).
  std::vector<RayLeaf, detail::HugePageAllocator<RayLeaf>> leaves;  // leaf k = object bvh.leaf_object()[k]
  std::vector<RayObject> halfspaces;  // tested against every ray
  // The ordered cast's scratch memory, kept from one cast to the next (written by const casts, hence mutable; the
  // arena's mutex lets one cast at a time use it).
  mutable detail::RayCastArena cast_arena;
  RaySceneTimings timings;
  bool rebuilt = false;
  bool ready = false;
};

}  // namespace batchcol
