// Embree 3 as the reference for ray queries (tests and `batchcol rays --peers` only; optional: libembree-dev).
// The objects are handed over as shapes + poses and turned into Embree geometry: hulls (their qhull faces), boxes and
// triangles exactly as triangles; spheres as Embree sphere points and capsules as round linear curves (Embree's own
// curved primitives, in float); cylinders, cones and ellipsoids tessellated with vertices on the surface (inscribed,
// see tessellation_error()). Inflated shapes and halfspaces are not supported (InputError).
// This header does not include Embree: it compiles without it, and have_embree() says whether it was found.
#pragma once

#include <batchcol/rays.hpp>
#include <batchcol/shapes.hpp>

#include <cstdint>
#include <memory>
#include <vector>

namespace batchcol::peers {

bool have_embree();

struct EmbreeObject {
  const Shape* shape = nullptr;
  Pose pose;
};

/// Rings and segments of the tessellated curved shapes (cylinder and cone: `segments` around the axis; ellipsoid: a
/// UV sphere of `segments` around and segments / 2 rings, scaled).
struct Tessellation {
  int segments = 64;
};

/// Largest distance between a tessellated shape's surface and the exact one, for shapes of largest radius `radius`:
/// a chord of angle 2 pi / segments lies within r (1 - cos(pi / segments)) of its arc (ellipsoids: the same bound
/// along each of the two angles, added).
double tessellation_error(ShapeType type, double radius, const Tessellation& tessellation);

struct EmbreeHits {
  std::vector<std::uint8_t> hit;
  std::vector<double> t;           // NaN when no hit
  std::vector<std::uint32_t> object;  // index into the objects given to build(); UINT32_MAX when no hit
  std::vector<float> nx, ny, nz;    // Embree's geometric normal, not normalised
};

class EmbreeRayScene {
 public:
  /// threads = 0: all cores (Embree's own TBB build threads).
  explicit EmbreeRayScene(int threads);
  ~EmbreeRayScene();
  EmbreeRayScene(const EmbreeRayScene&) = delete;
  EmbreeRayScene& operator=(const EmbreeRayScene&) = delete;

  /// Converts and commits the scene (Embree's BVH build). Returns the milliseconds of rtcCommitScene alone and of the
  /// whole call (tessellation included).
  struct BuildTimes {
    double commit_ms = 0, total_ms = 0;
  };
  BuildTimes build(const std::vector<EmbreeObject>& objects, const Tessellation& tessellation = {});
  std::size_t triangle_count() const;

  /// Closest hits (any = occlusion: hit only) of the valid rays, in parallel on `threads` TBB threads with
  /// rtcIntersect1 / rtcOccluded1. Invalid rays (see batchcol/rays.hpp) report no hit.
  void cast(const RayBatch& rays, bool any, int threads, EmbreeHits& hits) const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace batchcol::peers
