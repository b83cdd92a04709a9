// Batched ray queries: rays against one shape with a pose per ray, and rays against a whole Scene.
//
// Conventions: ray i is x(t) = origin[i] + t direction[i] for t in [0, t_max[i]]; the direction need not be unit and
// t is in units of its length (hit point = origin + t direction). A hit is the smallest t in that range where the
// ray is inside the closed solid; its normal is the outward unit surface normal there (world frame). A ray that
// starts inside (or on) a solid hits it at t = 0 with normal -direction/|direction| (there is no entry surface).
// Triangles are two-sided 2-D solids: a ray lying in the triangle's plane does not hit it.
//
// Invalid rays get RayStatus::invalid_input (hit = 0, t = NaN) and are otherwise ignored, never an exception:
// a non-finite origin, a zero or non-finite direction, or a t_max that is NaN or negative (t_max = +inf is valid).
// The shape form also marks rays with a shape index out of range or a pose that is not finite / not a unit quaternion
// within kUnitTolerance. Exceptions (InputError) are only for the call itself: arrays of different sizes, invalid
// options.
//
// Exactness: spheres, capsules, boxes, cylinders, cones, ellipsoids, hulls (their face planes), triangles and
// halfspaces are intersected in closed form (see kernels/rays/). Inflated spheres, capsules and halfspaces too. Other
// inflated shapes use the GJK ray cast (van den Bergen 2004): its hit point is certified to lie outside the shape
// and within RayOptions::tolerance of it (t is a lower bound of the exact hit); RayStatus::max_iterations flags a ray
// whose cast ran out of iterations. Results are bitwise identical for any thread count.
#pragma once

#include "batchcol/export.hpp"

#include "batchcol/batch.hpp"
#include "batchcol/pose.hpp"
#include "batchcol/scene.hpp"
#include "batchcol/shapes.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace batchcol {

/// Rays in structure-of-arrays form.
struct BATCHCOL_API RayBatch {
  Vec3Array origin, direction;
  std::vector<double> t_max;

  std::size_t size() const { return t_max.size(); }
  void reserve(std::size_t n);
  /// Appends a ray and returns its index (no validation here: bad rays get RayStatus::invalid_input).
  std::size_t add(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double t_max);
};

/// Rays against one shape each, with a pose per ray: ray i is tested against shapes[shape[i]] placed at
/// (translation[i], rotation[i]). The batched narrow-phase form, without a scene.
struct ShapeRayBatch {
  RayBatch rays;
  std::vector<std::uint32_t> shape;
  Vec3Array translation;
  QuatArray rotation;

  std::size_t size() const { return rays.size(); }
  std::size_t add(std::uint32_t shape_index, const Pose& pose, const Eigen::Vector3d& origin,
                  const Eigen::Vector3d& direction, double t_max);
};

enum class RayQuery : std::uint8_t {
  closest,  // the first hit along the ray
  any,      // whether anything is hit (occlusion): stops at the first hit found, which need not be the closest
  all,      // every object hit in [0, t_max], sorted by (t, object slot)
};
BATCHCOL_API const char* to_string(RayQuery query);
BATCHCOL_API RayQuery parse_ray_query(const std::string& name);  // throws InputError naming the value

enum class RayStatus : std::uint8_t {
  ok,              // exact (closed form) or certified to the tolerance
  max_iterations,  // a GJK ray cast (inflated shape) ran out of iterations: t is its last lower bound
  invalid_input,   // see the top of this file; nothing computed
};
BATCHCOL_API const char* to_string(RayStatus status);

struct RayOptions {
  RayQuery query = RayQuery::closest;
  Precision precision = Precision::float64;  // shape form only; scene queries run in double
  double tolerance = 1e-9;  // GJK ray cast: distance (metres) of the reported hit point to the surface, at most
  int max_iterations = 64;  // GJK ray cast iterations per ray and shape
  int threads = 0;          // 0 = all cores
  // Instruction set of the scene traversal (and its ray setup) and of the shape form's lane kernels (automatic: the
  // best this CPU runs, capped by BATCHCOL_ISA as for collide()); every set gives bitwise the same results. A set
  // this CPU lacks throws InputError. The hulls' plane clipping inside the exact kernels keeps the CPU's best.
  InstructionSet isa = InstructionSet::automatic;
};
/// Throws InputError naming the option (tolerance not finite or <= 0, max_iterations < 1, threads < 0).
BATCHCOL_API void validate(const RayOptions& options);

/// Per-ray results in input order. For closest and all queries, hit/t/normal/object describe the closest hit; for
/// any, the hit found first. Rays without a hit have hit = 0, t = NaN, normal NaN and an invalid ObjectHandle{}.
/// For RayQuery::all, the hits of ray i are rows [hit_begin[i], hit_begin[i + 1]) of all_t / all_normal / all_object
/// (sorted by t, then object slot); these arrays are empty for the other queries.
struct RayResults {
  std::vector<RayStatus> status;
  std::vector<std::uint8_t> hit;
  std::vector<double> t;
  Vec3Array normal;
  std::vector<ObjectHandle> object;  // scene queries only (empty for the shape form)

  std::vector<std::uint64_t> hit_begin;
  std::vector<double> all_t;
  Vec3Array all_normal;
  std::vector<ObjectHandle> all_object;

  std::size_t size() const { return status.size(); }
};

/// Rays against one posed shape each (ShapeRayBatch). options.query is ignored (one shape: closest = any = all).
BATCHCOL_API void cast_rays(const ShapeTable& shapes, const ShapeRayBatch& batch, const RayOptions& options, RayResults& results);

/// Wall-clock milliseconds of the last RaySceneIndex::update().
struct RaySceneTimings {
  double boxes_ms = 0;    // world boxes and object transforms from the scene
  double build_ms = 0;    // Morton codes, radix sort, hierarchy, 16-wide collapse (0 when refitted)
  double refit_ms = 0;    // bottom-up box refit and the wide nodes' box copy (0 when rebuilt)
  double wide_ms = 0;     // the part of build_ms / refit_ms spent on the 16-wide nodes (collapse or box copy)
  double total_ms = 0;
};

/// The scene's acceleration structure for rays: a linear BVH (Karras 2012) over the objects' world boxes, built in
/// parallel from Morton codes and collapsed into a 16-wide BVH (float boxes, one SIMD test per node), both refitted
/// (boxes only) when only poses changed since the last update. It snapshots the
/// scene's objects and poses at update(): later scene changes are seen at the next update().
class BATCHCOL_API RaySceneIndex {
 public:
  RaySceneIndex();
  ~RaySceneIndex();
  RaySceneIndex(RaySceneIndex&&) noexcept;
  RaySceneIndex& operator=(RaySceneIndex&&) noexcept;

  /// Rebuilds when objects were added, removed or renumbered since the last update (or `force_rebuild`), else refits.
  /// threads = 0: all cores.
  void update(const Scene& scene, int threads = 0, bool force_rebuild = false);
  /// Casts the rays against the snapshot. Throws InputError before the first update() or for invalid options.
  void cast(const RayBatch& rays, const RayOptions& options, RayResults& results) const;

  const RaySceneTimings& timings() const;
  bool last_update_rebuilt() const;
  std::size_t object_count() const;  // objects of the snapshot (halfspaces included)

  struct State;

 private:
  std::unique_ptr<State> state_;
};

}  // namespace batchcol
