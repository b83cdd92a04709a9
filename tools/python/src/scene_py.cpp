// Scenes from Python in bulk: objects are added, moved and removed by arrays, and a handle is one uint64
// (slot | generation << 32). Every bulk call is all or nothing: a bad row raises ValueError naming it and leaves
// the scene as it was.
#include "arrays.hpp"
#include "collide_py.hpp"
#include "module.hpp"

#include "batchcol/scene.hpp"

#include <pybind11/stl.h>

#include <limits>
#include <set>

namespace batchcol::python {
namespace {

using namespace pybind11::literals;

struct SceneHolder {
  explicit SceneHolder(std::shared_ptr<TableHolder> t) : table(std::move(t)), scene(table->table) {}
  std::shared_ptr<TableHolder> table;
  Scene scene;
  int busy = 0;  // a collide() runs with the GIL released: the scene must not change meanwhile

  void check_idle(const char* what) const {
    if (busy > 0) throw std::runtime_error(std::string("Scene.") + what + ": the scene is in use by a running collide()");
  }
};

struct SceneResultsHolder {
  std::vector<ObjectHandle> object_a, object_b;
  std::vector<std::uint32_t> colliding;
  py::object pairs;
  SceneTimings timings;
  bool incremental = false;
};

std::uint64_t pack(ObjectHandle h) { return std::uint64_t{h.slot} | (std::uint64_t{h.generation} << 32); }
ObjectHandle unpack(std::uint64_t v) {
  return {static_cast<std::uint32_t>(v & 0xffffffffu), static_cast<std::uint32_t>(v >> 32)};
}

std::vector<std::uint64_t> handles_of(const py::handle& obj) {
  const py::array a = py::module_::import("numpy").attr("asarray")(obj);
  const char kind = a.dtype().kind();
  if ((kind != 'u' && kind != 'i') || a.ndim() != 1)
    throw ArgumentError("handles must be a 1-D integer array (as returned by Scene.add), got " +
                        py::str(a.dtype()).cast<std::string>() + " with " + std::to_string(a.ndim()) + " dimensions");
  return py::array_t<std::uint64_t, py::array::forcecast>::ensure(a).cast<std::vector<std::uint64_t>>();
}

/// n values of a filter argument: None (the default), one int, or an (n,) integer array, each in [lo, hi].
std::vector<long long> filter_values(const py::handle& obj, const char* name, std::size_t n, long long fallback,
                                     long long lo, long long hi) {
  if (obj.is_none()) return std::vector<long long>(n, fallback);
  const py::module_ np = py::module_::import("numpy");
  py::array a = np.attr("asarray")(obj);
  if (a.dtype().kind() != 'i' && a.dtype().kind() != 'u')
    throw ArgumentError(std::string(name) + " must be an integer or an array of integers");
  a = np.attr("broadcast_to")(a.attr("astype")("int64"), py::make_tuple(n));
  std::vector<long long> v = py::array_t<long long, py::array::forcecast>::ensure(a).cast<std::vector<long long>>();
  for (std::size_t i = 0; i < n; ++i)
    if (v[i] < lo || v[i] > hi)
      throw ArgumentError(std::string(name) + "[" + std::to_string(i) + "] = " + std::to_string(v[i]) +
                          " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

/// The n poses of (translation, quaternion) arguments, read row by row.
std::vector<Pose> poses_of(const py::handle& translation, const py::handle& quaternion, std::size_t n) {
  KeepAlive keep;
  const Vec3View t = vec3_input(translation, "translation", n, true, keep);
  const QuatView q = quat_input(quaternion, "quaternion", n, true, keep);
  std::vector<Pose> poses(n);
  for (std::size_t i = 0; i < n; ++i) poses[i] = {t[i], q[i]};
  return poses;
}

py::array handle_array(const std::vector<ObjectHandle>& h, const py::handle& owner) {
  static_assert(sizeof(ObjectHandle) == sizeof(std::uint64_t), "a handle is two uint32");
  // Viewed as uint64 without a copy: slot in the low half, generation in the high half on little-endian x86-64.
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "handle views assume little-endian");
  return view_array(reinterpret_cast<const std::uint64_t*>(h.data()), h.size(), owner);
}

}  // namespace

void register_scene(py::module_& m) {
  py::class_<SceneResultsHolder, std::shared_ptr<SceneResultsHolder>>(
      m, "SceneResults", "Candidate pairs of a Scene.collide(): arrays are views of the engine's buffers.")
      .def("__len__", [](const SceneResultsHolder& r) { return r.object_a.size(); })
      .def_property_readonly("object_a", [](py::object self) { return handle_array(self.cast<SceneResultsHolder&>().object_a, self); })
      .def_property_readonly("object_b", [](py::object self) { return handle_array(self.cast<SceneResultsHolder&>().object_b, self); })
      .def_property_readonly("colliding", [](py::object self) {
        const auto& c = self.cast<SceneResultsHolder&>().colliding;
        return view_array(c.data(), c.size(), self);
      }, "indices of the colliding candidates, increasing")
      .def_property_readonly("pairs", [](const SceneResultsHolder& r) { return r.pairs; },
                             "the candidates' narrow-phase Results")
      .def_property_readonly("incremental", [](const SceneResultsHolder& r) { return r.incremental; })
      .def_property_readonly("timings", [](const SceneResultsHolder& r) {
        const SceneTimings& t = r.timings;
        return py::dict("broadphase_ms"_a = t.broadphase_ms(), "narrowphase_ms"_a = t.narrowphase_ms,
                        "total_ms"_a = t.total_ms);
      });

  py::class_<SceneHolder, std::shared_ptr<SceneHolder>>(
      m, "Scene", "Objects (shape index, pose, filter) whose candidate pairs come from the broad phase.")
      .def(py::init([](std::shared_ptr<TableHolder> shapes) {
             if (!shapes) throw ArgumentError("Scene: shapes must be a ShapeTable");
             return std::make_shared<SceneHolder>(std::move(shapes));
           }),
           "shapes"_a)
      .def("__len__", [](const SceneHolder& s) { return s.scene.size(); })
      .def(
          "add",
          [](SceneHolder& s, const py::handle& shape, const py::handle& translation, const py::handle& quaternion,
             const py::handle& group, const py::handle& mask, const py::handle& body) {
            s.check_idle("add");
            const std::size_t n = rows_of(translation, "translation", 3);
            KeepAlive keep;
            const ConstSpan<std::uint32_t> index = index_input(shape, "shape", n, true, keep);
            const std::vector<Pose> poses = poses_of(translation, quaternion, n);
            constexpr long long u32 = std::numeric_limits<std::uint32_t>::max();
            const auto groups = filter_values(group, "group", n, 1, 0, u32);
            const auto masks = filter_values(mask, "mask", n, u32, 0, u32);
            const auto bodies = filter_values(body, "body", n, -1, -1, std::numeric_limits<std::int32_t>::max());
            py::array_t<std::uint64_t> handles(static_cast<py::ssize_t>(n));
            std::uint64_t* out = handles.mutable_data();
            std::size_t i = 0;
            try {
              for (; i < n; ++i) {
                const CollisionFilter f{static_cast<std::uint32_t>(groups[i]), static_cast<std::uint32_t>(masks[i]),
                                        static_cast<std::int32_t>(bodies[i])};
                out[i] = pack(s.scene.add(index[i], poses[i], f));
              }
            } catch (const InputError& e) {
              for (std::size_t k = 0; k < i; ++k) s.scene.remove(unpack(out[k]));
              throw ArgumentError("Scene.add: row " + std::to_string(i) + ": " + e.what() + " (no object added)");
            }
            return handles;
          },
          "shape"_a, "translation"_a, "quaternion"_a, "group"_a = py::none(), "mask"_a = py::none(),
          "body"_a = py::none(), "adds N objects; returns their handles (uint64)")
      .def(
          "set_poses",
          [](SceneHolder& s, const py::handle& handles, const py::handle& translation, const py::handle& quaternion) {
            s.check_idle("set_poses");
            const std::vector<std::uint64_t> h = handles_of(handles);
            const std::vector<Pose> poses = poses_of(translation, quaternion, h.size());
            std::vector<Pose> before(h.size());
            for (std::size_t i = 0; i < h.size(); ++i) {
              if (!s.scene.contains(unpack(h[i])))
                throw ArgumentError("Scene.set_poses: handles[" + std::to_string(i) + "] is not an object of this scene");
              before[i] = s.scene.pose(unpack(h[i]));
            }
            std::size_t i = 0;
            try {
              for (; i < h.size(); ++i) s.scene.set_pose(unpack(h[i]), poses[i]);
            } catch (const InputError& e) {
              for (std::size_t k = 0; k < i; ++k) s.scene.set_pose(unpack(h[k]), before[k]);
              throw ArgumentError("Scene.set_poses: row " + std::to_string(i) + ": " + e.what() + " (no pose changed)");
            }
          },
          "handles"_a, "translation"_a, "quaternion"_a)
      .def(
          "remove",
          [](SceneHolder& s, const py::handle& handles) {
            s.check_idle("remove");
            const std::vector<std::uint64_t> h = handles_of(handles);
            std::set<std::uint64_t> seen;
            for (std::size_t i = 0; i < h.size(); ++i)
              if (!s.scene.contains(unpack(h[i])) || !seen.insert(h[i]).second)
                throw ArgumentError("Scene.remove: handles[" + std::to_string(i) + "] is not an object of this scene"
                                    " (or is repeated); nothing removed");
            for (const auto v : h) s.scene.remove(unpack(v));
          },
          "handles"_a)
      .def(
          "contains",
          [](const SceneHolder& s, const py::handle& handles) {
            const std::vector<std::uint64_t> h = handles_of(handles);
            py::array_t<bool> in(static_cast<py::ssize_t>(h.size()));
            for (std::size_t i = 0; i < h.size(); ++i) in.mutable_data()[i] = s.scene.contains(unpack(h[i]));
            return in;
          },
          "handles"_a)
      .def(
          "poses",
          [](const SceneHolder& s, const py::handle& handles) {
            const std::vector<std::uint64_t> h = handles_of(handles);
            const auto n = static_cast<py::ssize_t>(h.size());
            py::array_t<double> t({n, py::ssize_t{3}}), q({n, py::ssize_t{4}});
            for (std::size_t i = 0; i < h.size(); ++i) {
              if (!s.scene.contains(unpack(h[i])))
                throw ArgumentError("Scene.poses: handles[" + std::to_string(i) + "] is not an object of this scene");
              const Pose p = s.scene.pose(unpack(h[i]));
              for (int c = 0; c < 3; ++c) t.mutable_at(i, c) = p.translation[c];
              const double qv[4] = {p.rotation.w(), p.rotation.x(), p.rotation.y(), p.rotation.z()};
              for (int c = 0; c < 4; ++c) q.mutable_at(i, c) = qv[c];
            }
            return py::make_tuple(t, q);
          },
          "handles"_a, "(translation (N, 3), quaternion (N, 4) [w, x, y, z]) as stored (copies)")
      .def(
          "collide",
          [](SceneHolder& s, const std::string& level, const std::string& solver, const std::string& precision,
             double tolerance, double margin, int threads) {
            s.check_idle("collide");
            const QueryOptions o =
                options_from(level, solver, precision, tolerance, 0.0, margin, 128, 1000, true, threads, "automatic");
            SceneResults r;
            {
              TableUse use(*s.table);
              ++s.busy;
              struct Done {
                int& busy;
                ~Done() { --busy; }
              } done{s.busy};
              py::gil_scoped_release release;
              s.scene.collide(o, r);
            }
            auto out = std::make_shared<SceneResultsHolder>();
            out->object_a = std::move(r.object_a);
            out->object_b = std::move(r.object_b);
            out->colliding = std::move(r.colliding);
            out->timings = r.timings;
            out->incremental = r.incremental;
            auto pairs = std::make_shared<ResultsHolder>();
            pairs->results = std::move(r.pairs);  // moved, not copied
            pairs->level = o.level;
            out->pairs = py::cast(pairs);
            return out;
          },
          py::kw_only(), "level"_a = "boolean", "solver"_a = "automatic", "precision"_a = "double",
          "tolerance"_a = 1e-8, "margin"_a = 0.0, "threads"_a = 0);
}

}  // namespace batchcol::python
