// batchcol::Scene: object bookkeeping (stable handles over dense arrays) and the per-frame pipeline
// world AABBs -> sweep-and-prune (+ halfspaces) -> one PairBatch -> batchcol::collide().
#include "scene_hooks.hpp"
#include "scene_state.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <chrono>
#include <cmath>
#include <sstream>
#include <string>
#include <type_traits>

namespace batchcol {
namespace {

// Translations beyond this cannot be stored as float boxes with room for the object's size (float max ~3.4e38).
constexpr double kMaxCoordinate = 1e30;
// Objects are renumbered in spatial order after a rebuild when at least 1/kRenumberFraction of them were added or
// removed since the last renumbering: a few additions barely disturb the order, and renumbering costs a pass of
// random gathers over every per-object array.
constexpr std::size_t kRenumberFraction = 8;

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

Pose checked_pose(const Pose& pose, const char* what) {
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(pose.translation[a]) || std::fabs(pose.translation[a]) > kMaxCoordinate) {
      std::ostringstream s;
      s << "scene: " << what << ": translation[" << a << "] = " << pose.translation[a]
        << " must be finite and within 1e30";
      throw InputError(s.str());
    }
  if (!is_unit_quaternion(pose.rotation))
    throw InputError(std::string("scene: ") + what + ": rotation quaternion is not finite or not unit within 1e-6");
  return {pose.translation, checked_unit_quaternion(pose.rotation)};
}

template <class T> std::size_t bytes(const std::vector<T>& v) { return v.capacity() * sizeof(T); }

}  // namespace

bool filters_pass(const CollisionFilter& a, const CollisionFilter& b) {
  if ((a.group & b.mask) == 0 || (b.group & a.mask) == 0) return false;
  return !(a.body >= 0 && a.body == b.body);
}

bool is_default(const CollisionFilter& f) {
  const CollisionFilter d;
  return f.group == d.group && f.mask == d.mask && f.body == d.body;
}

// ---- FiniteObjects -------------------------------------------------------------------------------------------

void FiniteObjects::push_back(std::uint32_t shape_index, std::uint32_t slot_index, const Pose& pose,
                              const LocalBound& b, const CollisionFilter& f) {
  shape.push_back(shape_index), slot.push_back(slot_index);
  for (auto* v : {&tx, &ty, &tz, &qw, &qx, &qy, &qz, &cx, &cy, &cz, &bx, &by, &bz, &ex, &ey, &ez, &ball})
    v->push_back(0.0);
  exact_path.push_back(b.exact_path ? 1 : 0);
  filter.group.push_back(0), filter.mask.push_back(0), filter.body.push_back(0);
  const std::size_t i = size() - 1;
  set_pose(i, pose);
  set_filter(i, f);
  cx[i] = b.centre.x(), cy[i] = b.centre.y(), cz[i] = b.centre.z();
  bx[i] = b.box.x(), by[i] = b.box.y(), bz[i] = b.box.z();
  ex[i] = b.ellipse.x(), ey[i] = b.ellipse.y(), ez[i] = b.ellipse.z();
  ball[i] = b.ball;
}

void FiniteObjects::set_pose(std::size_t i, const Pose& p) {
  tx[i] = p.translation.x(), ty[i] = p.translation.y(), tz[i] = p.translation.z();
  qw[i] = p.rotation.w(), qx[i] = p.rotation.x(), qy[i] = p.rotation.y(), qz[i] = p.rotation.z();
}

void FiniteObjects::set_filter(std::size_t i, const CollisionFilter& f) {
  filter.group[i] = f.group, filter.mask[i] = f.mask, filter.body[i] = f.body;
}

void FiniteObjects::swap_remove(std::size_t i) {
  const auto move_last = [i](auto& v) {
    v[i] = v.back();
    v.pop_back();
  };
  move_last(shape), move_last(slot), move_last(exact_path);
  for (auto* v : {&tx, &ty, &tz, &qw, &qx, &qy, &qz, &cx, &cy, &cz, &bx, &by, &bz, &ex, &ey, &ez, &ball}) move_last(*v);
  move_last(filter.group), move_last(filter.mask), move_last(filter.body);
}

void FiniteObjects::permute(const std::vector<std::uint32_t>& order) {
  const auto gather = [&order](auto& v) {
    std::remove_reference_t<decltype(v)> out(v.size());
    for (std::size_t k = 0; k < order.size(); ++k) out[k] = v[order[k]];
    v.swap(out);
  };
  gather(shape), gather(slot), gather(exact_path);
  for (auto* v : {&tx, &ty, &tz, &qw, &qx, &qy, &qz, &cx, &cy, &cz, &bx, &by, &bz, &ex, &ey, &ez, &ball}) gather(*v);
  gather(filter.group), gather(filter.mask), gather(filter.body);
}

Pose FiniteObjects::pose(std::size_t i) const {
  return {Eigen::Vector3d(tx[i], ty[i], tz[i]), Eigen::Quaterniond(qw[i], qx[i], qy[i], qz[i])};
}

CollisionFilter FiniteObjects::get_filter(std::size_t i) const {
  return {filter.group[i], filter.mask[i], filter.body[i]};
}

// ---- State ---------------------------------------------------------------------------------------------------

const Slot& Scene::State::checked(ObjectHandle object) const {
  if (object.slot >= slots.size() || slots[object.slot].kind == SlotKind::free ||
      slots[object.slot].generation != object.generation) {
    std::ostringstream s;
    s << "scene: object handle (slot " << object.slot << ", generation " << object.generation
      << ") does not refer to an object of this scene (removed or never added)";
    throw InputError(s.str());
  }
  return slots[object.slot];
}

std::size_t Scene::State::frame_buffer_bytes() const {
  std::size_t b = sap.memory_bytes() + bytes(sap_pairs) + bytes(halfspace_pairs) + bytes(world_halfspaces) +
                  bytes(halfspace_chunks) + bytes(batch.shape_a) + bytes(batch.shape_b) + bytes(pose_records);
  for (const auto& c : halfspace_chunks) b += bytes(c);
  for (const auto* v : {&boxes.min_x, &boxes.min_y, &boxes.min_z, &boxes.max_x, &boxes.max_y, &boxes.max_z})
    b += bytes(*v);
  for (const Vec3Array* v : {&batch.translation_a, &batch.translation_b}) b += bytes(v->x) + bytes(v->y) + bytes(v->z);
  for (const QuatArray* q : {&batch.rotation_a, &batch.rotation_b})
    b += bytes(q->w) + bytes(q->x) + bytes(q->y) + bytes(q->z);
  return b;
}

void Scene::State::renumber_spatially() {
  if (changes_since_renumber * kRenumberFraction < finite.size()) return;
  std::vector<std::uint32_t> order, new_index;
  sap.spatial_order(order);
  if (order.size() != finite.size()) return;  // the broad phase has no complete order (nothing to gain anyway)
  finite.permute(order);
  new_index.resize(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    new_index[order[k]] = static_cast<std::uint32_t>(k);
    slots[finite.slot[k]].index = static_cast<std::uint32_t>(k);
  }
  sap.renumber(new_index);
  changes_since_renumber = 0;
  // This frame's boxes and pose records, gathered into the new order (the same values: no recomputation).
  for (auto* v : {&boxes.min_x, &boxes.min_y, &boxes.min_z, &boxes.max_x, &boxes.max_y, &boxes.max_z}) {
    std::vector<float> out(v->size());
    for (std::size_t k = 0; k < order.size(); ++k) out[k] = (*v)[order[k]];
    v->swap(out);
  }
  std::vector<PoseRecord> poses(pose_records.size());
  for (std::size_t k = 0; k < order.size(); ++k) poses[k] = pose_records[order[k]];
  pose_records.swap(poses);
  // This frame's pairs in the new numbering, sorted again (a < b, lexicographic: the broad phase's contract).
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sap_pairs.size(), 16384),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t k = r.begin(); k < r.end(); ++k) {
                        const std::uint32_t a = new_index[sap_pairs[k].a], b = new_index[sap_pairs[k].b];
                        sap_pairs[k] = a < b ? broadphase::CandidatePair{a, b} : broadphase::CandidatePair{b, a};
                      }
                    });
  tbb::parallel_sort(sap_pairs.begin(), sap_pairs.end());  // keys are unique: one answer for any thread count
}

// ---- Scene ---------------------------------------------------------------------------------------------------

Scene::Scene(std::shared_ptr<const ShapeTable> shapes) : state_(std::make_unique<State>()) {
  if (!shapes) throw InputError("scene: the shape table is null");
  state_->shapes = std::move(shapes);
  for (const Shape& s : state_->shapes->shapes()) state_->shape_bounds.push_back(local_bound(s));
}

Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

ObjectHandle Scene::add(std::uint32_t shape, const Pose& pose, const CollisionFilter& filter) {
  State& s = *state_;
  if (shape >= s.shapes->size()) {
    throw InputError("scene: shape index " + std::to_string(shape) + " is out of range (the table has " +
                     std::to_string(s.shapes->size()) + " shapes)");
  }
  const Pose p = checked_pose(pose, "add");
  if (s.finite.size() >= (kHalfspaceBit - 2)) throw InputError("scene: at most 2^31 - 2 objects");
  std::uint32_t slot;
  if (!s.free_slots.empty()) {
    slot = s.free_slots.back();
    s.free_slots.pop_back();
  } else {
    slot = static_cast<std::uint32_t>(s.slots.size());
    s.slots.emplace_back();
  }
  Slot& entry = s.slots[slot];
  if ((*s.shapes)[shape].type == ShapeType::halfspace) {
    entry.kind = SlotKind::halfspace;
    entry.index = static_cast<std::uint32_t>(s.halfspaces.size());
    s.halfspaces.push_back({shape, slot, p, filter});
  } else {
    entry.kind = SlotKind::finite;
    entry.index = static_cast<std::uint32_t>(s.finite.size());
    s.finite.push_back(shape, slot, p, s.shape_bounds[shape], filter);
    s.filtered_objects += is_default(filter) ? 0 : 1;
  }
  s.topology_changed = true;
  ++s.changes_since_renumber;
  return s.handle_of(slot);
}

void Scene::remove(ObjectHandle object) {
  State& s = *state_;
  const std::uint32_t index = s.checked(object).index;
  Slot& entry = s.slots[object.slot];
  if (entry.kind == SlotKind::halfspace) {
    s.halfspaces[index] = s.halfspaces.back();
    s.halfspaces.pop_back();
    if (index < s.halfspaces.size()) s.slots[s.halfspaces[index].slot].index = index;
  } else {
    s.filtered_objects -= is_default(s.finite.get_filter(index)) ? 0 : 1;
    s.finite.swap_remove(index);
    if (index < s.finite.size()) s.slots[s.finite.slot[index]].index = index;
  }
  entry.kind = SlotKind::free;
  ++entry.generation;  // the old handle never becomes valid again (up to 2^32 reuses of one slot)
  s.free_slots.push_back(object.slot);
  s.topology_changed = true;
  ++s.changes_since_renumber;
}

void Scene::set_pose(ObjectHandle object, const Pose& pose) {
  State& s = *state_;
  const Slot& entry = s.checked(object);
  const Pose p = checked_pose(pose, "set_pose");
  if (entry.kind == SlotKind::halfspace) s.halfspaces[entry.index].pose = p;
  else s.finite.set_pose(entry.index, p);
}

void Scene::set_filter(ObjectHandle object, const CollisionFilter& filter) {
  State& s = *state_;
  const Slot& entry = s.checked(object);
  if (entry.kind == SlotKind::halfspace) {
    s.halfspaces[entry.index].filter = filter;
    return;
  }
  s.filtered_objects -= is_default(s.finite.get_filter(entry.index)) ? 0 : 1;
  s.finite.set_filter(entry.index, filter);
  s.filtered_objects += is_default(filter) ? 0 : 1;
}

bool Scene::contains(ObjectHandle object) const {
  const State& s = *state_;
  return object.slot < s.slots.size() && s.slots[object.slot].kind != SlotKind::free &&
         s.slots[object.slot].generation == object.generation;
}

std::size_t Scene::size() const { return state_->finite.size() + state_->halfspaces.size(); }

std::uint32_t Scene::shape(ObjectHandle object) const {
  const Slot& e = state_->checked(object);
  return e.kind == SlotKind::halfspace ? state_->halfspaces[e.index].shape : state_->finite.shape[e.index];
}

Pose Scene::pose(ObjectHandle object) const {
  const Slot& e = state_->checked(object);
  return e.kind == SlotKind::halfspace ? state_->halfspaces[e.index].pose : state_->finite.pose(e.index);
}

CollisionFilter Scene::filter(ObjectHandle object) const {
  const Slot& e = state_->checked(object);
  return e.kind == SlotKind::halfspace ? state_->halfspaces[e.index].filter : state_->finite.get_filter(e.index);
}

const ShapeTable& Scene::shapes() const { return *state_->shapes; }

void Scene::collide(const QueryOptions& options, SceneResults& results) {
  validate(options);
  if (!(options.margin <= kMaxCoordinate))
    throw InputError("scene: margin " + std::to_string(options.margin) + " must be within 1e30");
  State& s = *state_;
  const std::size_t bytes_before = s.frame_buffer_bytes();
  const auto start = Clock::now();
  const int threads = options.threads > 0 ? options.threads : tbb::task_arena::automatic;
  if (!s.arena || s.arena_threads != threads) {
    s.arena = std::make_unique<tbb::task_arena>(threads);
    s.arena_threads = threads;
  }
  SceneTimings& t = results.timings;
  t = SceneTimings{};
  s.arena->execute([&] {
    auto stage = Clock::now();
    compute_world_boxes(*s.shapes, s.finite, options.margin, s.boxes, s.pose_records);
    t.aabb_ms = ms_since(stage);

    const broadphase::FilterSoa& filter = s.filtered_objects > 0 ? s.finite.filter : s.no_filter;
    if (s.topology_changed) {
      s.sap.rebuild(s.boxes, filter, s.sap_pairs);
      stage = Clock::now();
      s.renumber_spatially();
      t.renumber_ms = ms_since(stage);
    } else {
      s.sap.update(s.boxes, filter, s.sap_pairs);
    }
    s.topology_changed = false;
    results.incremental = s.sap.stats().incremental;
    t.sap_bucket_ms = s.sap.stats().bucket_ms;
    t.sap_sweep_ms = s.sap.stats().sweep_ms;
    t.sap_emit_ms = s.sap.stats().emit_ms;

    stage = Clock::now();
    s.find_halfspace_pairs();
    t.halfspace_ms = ms_since(stage);

    stage = Clock::now();
    s.fill_batch(results);
    t.batch_ms = ms_since(stage);
  });
  auto stage = Clock::now();
  batchcol::collide(*s.shapes, s.batch, options, results.pairs);
  t.narrowphase_ms = ms_since(stage);
  results.colliding.clear();
  for (std::size_t k = 0; k < results.pairs.size(); ++k)
    if (results.pairs.collide[k]) results.colliding.push_back(static_cast<std::uint32_t>(k));
  t.total_ms = ms_since(start);
  if (s.frame_buffer_bytes() != bytes_before) ++s.reallocations;
}

void detail::SceneHooks::last_aabbs(const Scene& scene, std::vector<Aabb>& boxes, std::vector<ObjectHandle>& objects) {
  const Scene::State& s = *scene.state_;
  if (s.topology_changed || s.boxes.size() != s.finite.size())
    throw InputError("scene: last_aabbs() needs a collide() after the last add() or remove()");
  const std::size_t n = s.finite.size();
  boxes.resize(n);
  objects.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) boxes[i].min[a] = s.boxes.min(a)[i], boxes[i].max[a] = s.boxes.max(a)[i];
    objects[i] = s.handle_of(s.finite.slot[i]);
  }
}

std::size_t Scene::memory_bytes() const {
  const State& s = *state_;
  const FiniteObjects& f = s.finite;
  std::size_t b = s.frame_buffer_bytes() + bytes(s.slots) + bytes(s.free_slots) + bytes(s.halfspaces) +
                  bytes(s.shape_bounds) + bytes(f.shape) + bytes(f.slot) + bytes(f.exact_path) +
                  bytes(f.filter.group) + bytes(f.filter.mask) + bytes(f.filter.body);
  for (const auto* v : {&f.tx, &f.ty, &f.tz, &f.qw, &f.qx, &f.qy, &f.qz, &f.cx, &f.cy, &f.cz, &f.bx, &f.by, &f.bz,
                        &f.ex, &f.ey, &f.ez, &f.ball})
    b += bytes(*v);
  return b;
}

std::size_t detail::SceneHooks::buffer_reallocations(const Scene& scene) { return scene.state_->reallocations; }

}  // namespace batchcol
