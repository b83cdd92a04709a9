// The scene of `batchcol stress`: mixed shapes (spheres, boxes, capsules, cylinders, small convex hulls) placed by a
// distribution, sized so that each object's box overlaps about `density` others, and moved a little every step.
#pragma once

#include <batchcol/scene.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace batchcol::testkit {

enum class Distribution { uniform, clustered, layered };

/// Throws InputError naming the flag for anything but uniform, clustered, layered.
Distribution parse_distribution(const std::string& name);

struct StressSceneSpec {
  std::size_t objects = 10000;
  Distribution distribution = Distribution::uniform;
  double density = 0.4;  // expected AABB overlaps per object (uniform placement; clusters are denser, see .cpp)
  double move = 0.05;    // per step: translation of move x object size, rotation of move radians
  std::uint64_t seed = 1;
};

struct StressScene {
  std::shared_ptr<ShapeTable> shapes;
  std::unique_ptr<Scene> scene;
  std::vector<ObjectHandle> handles;
  std::vector<Pose> poses;                 // current pose of each handle
  std::vector<Eigen::Vector3d> velocity;   // translation per step
  std::vector<Eigen::Quaterniond> spin;    // rotation per step
  double world_side = 0;                   // edge of the cube (or layer side) the centres were drawn in
};

StressScene make_stress_scene(const StressSceneSpec& spec);

/// Advances every object by one step (poses and scene).
void step_stress_scene(StressScene& s);

}  // namespace batchcol::testkit
