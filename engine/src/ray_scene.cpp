// RaySceneIndex::update(): snapshot of the scene's objects, world boxes (the scene's own vectorised AABB pass) and
// the LBVH and its 16-wide collapse, rebuilt when the set of objects changed and refitted otherwise.
#include "ray_scene_state.hpp"
#include "ray_wide_traverse.hpp"
#include "rays_common.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>

namespace batchcol {
namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

RayObject make_object(const PoseRecord& p, std::uint32_t shape, ObjectHandle handle) {
  RayObject o;
  o.R = kernels::rotation_matrix<double>(p.qw, p.qx, p.qy, p.qz);
  o.t = kernels::Vec3<double>(p.tx, p.ty, p.tz);
  o.shape = shape;
  o.handle = handle;
  return o;
}

// The scene's world box of a hull is its local box turned with the pose (|R| times the half extents): for a hull
// close to a ball, such as the 250-vertex hulls of the benchmark, ~1.4 times the ball's box along each axis when
// the rotation is far from the axes, so ~2x the area a ray must cross to reach it, and the tree's boxes above it
// grow with it. The ray index clips each box to the box of the object's bounding ball (the ball of the cast's
// filters: centre at the pose's translation, radius `bound`, the shape's bounding radius about its origin); both
// contain the object, so their intersection does. Outward rounding as compute_world_boxes(): the double bounds are
// widened by 2^-22 of their size (plus 2^-126 for values that round to subnormal floats) before the cast to float.
// Spheres, capsules, boxes and cylinders already have their exact boxes and are left as they are (the ball box is
// never smaller there). Only the ray index's copy changes: the broad phase keeps its own boxes.
void clip_to_balls(RaySceneIndex::State& s, const FiniteObjects& f) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, f.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    float* lo[3] = {s.boxes.min_x.data(), s.boxes.min_y.data(), s.boxes.min_z.data()};
    float* hi[3] = {s.boxes.max_x.data(), s.boxes.max_y.data(), s.boxes.max_z.data()};
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      const double bound = s.prepared.shapes[f.shape[i]].bound;
      if (!(bound > 0.0) || !std::isfinite(bound)) continue;
      const double c[3] = {s.poses[i].tx, s.poses[i].ty, s.poses[i].tz};
      for (int a = 0; a < 3; ++a) {
        const double l = c[a] - bound, h = c[a] + bound;
        const double pad = 0x1p-22 * std::fmax(std::fabs(l), std::fabs(h)) + 0x1p-126;
        lo[a][i] = std::fmax(lo[a][i], static_cast<float>(l - pad));
        hi[a][i] = std::fmin(hi[a][i], static_cast<float>(h + pad));
      }
    }
  });
}

}  // namespace

RaySceneIndex::RaySceneIndex() : state_(std::make_unique<State>()) {}
RaySceneIndex::~RaySceneIndex() = default;
RaySceneIndex::RaySceneIndex(RaySceneIndex&&) noexcept = default;
RaySceneIndex& RaySceneIndex::operator=(RaySceneIndex&&) noexcept = default;

const RaySceneTimings& RaySceneIndex::timings() const { return state_->timings; }
bool RaySceneIndex::last_update_rebuilt() const { return state_->rebuilt; }
std::size_t RaySceneIndex::object_count() const { return state_->leaves.size() + state_->halfspaces.size(); }

void RaySceneIndex::update(const Scene& scene, int threads, bool force_rebuild) {
  if (threads < 0) throw InputError("RaySceneIndex::update: threads must be >= 0 (got " + std::to_string(threads) + ")");
  const Scene::State& sc = *scene.state_;
  State& s = *state_;
  const auto start = std::chrono::steady_clock::now();
  if (s.shapes != sc.shapes || s.prepared_shape_count != sc.shapes->size()) {
    s.shapes = sc.shapes;
    s.prepared.prepare(*s.shapes);
    s.prepared_shape_count = s.shapes->size();
    force_rebuild = true;
  }
  const FiniteObjects& f = sc.finite;
  std::vector<ObjectHandle> halfspace_handles;
  halfspace_handles.reserve(sc.halfspaces.size());
  for (const HalfspaceObject& h : sc.halfspaces) halfspace_handles.push_back(sc.handle_of(h.slot));
  const bool rebuild = force_rebuild || !s.ready || s.finite_slots != f.slot || s.finite_shapes != f.shape ||
                       s.halfspace_handles != halfspace_handles;
  // Slots are compared, not handles: a slot of a removed object is reused with a new generation, so the handles of
  // the leaves are refreshed on every update below anyway.
  detail::run_with_threads(threads, [&] {
    compute_world_boxes(*s.shapes, f, 0.0, s.boxes, s.poses);
    clip_to_balls(s, f);
    s.timings.boxes_ms = ms_since(start);
    const auto build_start = std::chrono::steady_clock::now();
    if (rebuild) {
      s.bvh.build(s.boxes);
      const auto wide_start = std::chrono::steady_clock::now();
      s.wide.collapse(s.bvh, s.boxes);
      s.timings.wide_ms = ms_since(wide_start);
      s.timings.build_ms = ms_since(build_start);
      s.timings.refit_ms = 0.0;  // build() includes its refit
    } else {
      s.bvh.refit(s.boxes);
      const auto wide_start = std::chrono::steady_clock::now();
      s.wide.refit(s.bvh, s.boxes);
      s.timings.wide_ms = ms_since(wide_start);
      s.timings.build_ms = 0.0;
      s.timings.refit_ms = ms_since(build_start);
    }
    const auto leaf_start = std::chrono::steady_clock::now();
    const std::vector<std::uint32_t>& order = s.bvh.leaf_object();
    s.leaves.resize(order.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t k = r.begin(); k < r.end(); ++k) {
                          const std::uint32_t i = order[k];
                          RayLeaf& leaf = s.leaves[k];
                          leaf.object = make_object(s.poses[i], f.shape[i], sc.handle_of(f.slot[i]));
                          // The same centre and bound as the cast's double ball filter (Caster::ball_misses).
                          make_leaf_ball(leaf.object.t.data(), s.prepared.shapes[f.shape[i]].bound, leaf.ball);
                        }
                      });
    s.timings.boxes_ms += ms_since(leaf_start);
  });
  s.halfspaces.clear();
  for (std::size_t h = 0; h < sc.halfspaces.size(); ++h) {
    const HalfspaceObject& o = sc.halfspaces[h];
    const Pose& p = o.pose;
    const PoseRecord rec{p.translation.x(), p.translation.y(), p.translation.z(), p.rotation.w(),
                         p.rotation.x(),    p.rotation.y(),    p.rotation.z()};
    s.halfspaces.push_back(make_object(rec, o.shape, halfspace_handles[h]));
  }
  if (rebuild) {
    s.finite_slots = f.slot;
    s.finite_shapes = f.shape;
    s.halfspace_handles = std::move(halfspace_handles);
  }
  s.rebuilt = rebuild;
  s.ready = true;
  s.timings.total_ms = ms_since(start);
}

}  // namespace batchcol
