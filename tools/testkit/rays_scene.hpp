// Scenes and rays of `batchcol rays`: seeded, the same for batchcol and Embree.
#pragma once

#include <batchcol/io.hpp>
#include <batchcol/rays.hpp>
#include <batchcol/scene.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace batchcol::testkit {

struct RaysSceneSpec {
  std::int64_t objects = 10000;
  std::string shapes = "hull";  // hull (convex hulls of `hull_vertices` points on a sphere) or mixed
  int hull_vertices = 250;
  double fill = 1.2;  // expected objects crossed per ray (hit fraction ~ 1 - exp(-fill))
  std::uint64_t seed = 1;
};

struct RaysScene {
  std::shared_ptr<ShapeTable> table;
  std::unique_ptr<Scene> scene;
  std::vector<ObjectHandle> handles;
  double half_extent = 0;  // objects lie in the cube [-half_extent, half_extent]^3
};

/// Objects of radius ~0.5 m spread uniformly in a cube sized so that a ray crossing it meets `fill` objects on
/// average (cross-section pi r^2 per object). Hulls: 16 distinct hulls shared by the objects.
RaysScene make_rays_scene(const RaysSceneSpec& spec);
/// The "objects" of a ray scene file, added in file order (object k gets slot k, generation 0); takes the file's
/// shapes. half_extent: the largest |coordinate| of an object's position.
RaysScene make_rays_scene(BatchFile&& file);
/// Rays from a sphere of radius 2 x half_extent towards uniform points of the cube, unit directions, t_max = inf.
RayBatch make_crossing_rays(std::int64_t n, double half_extent, std::uint64_t seed);
/// Moves every object by up to `step` metres and a small rotation (the refit benchmark's frame).
void move_objects(RaysScene& s, double step, std::uint64_t seed);

}  // namespace batchcol::testkit
