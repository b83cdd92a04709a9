// Private state of batchcol::RaySceneIndex: a snapshot of the scene's objects in BVH leaf order, the LBVH and its
// 8-wide collapse.
#pragma once

#include "batchcol/rays.hpp"
#include "broadphase/aabb_soa.hpp"
#include "kernels/math.hpp"
#include "ray_bvh.hpp"
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
  WideBvh wide;     // its 8-wide collapse, traversed by every other ray
  // Read at random by the rays (a leaf each visit): on huge pages when large (ray_huge_pages.hpp).
  std::vector<RayObject, detail::HugePageAllocator<RayObject>> leaves;  // leaf k = object bvh.leaf_object()[k]
  std::vector<float, detail::HugePageAllocator<float>> leaf_balls;  // per leaf: the float ball filter (make_leaf_ball)
  std::vector<RayObject> halfspaces;  // tested against every ray
  RaySceneTimings timings;
  bool rebuilt = false;
  bool ready = false;
};

}  // namespace batchcol
