// Batch files: JSON text -> ShapeTable + PairBatch + optional query settings, validated completely before anything
// is returned. Every error names the file and the JSON pointer of the offending field; syntax errors also give the
// line and column.
#include "batchcol/io.hpp"

#include "batch_json.hpp"
#include "printable.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace batchcol {
namespace {

using json = nlohmann::json;
namespace fs = std::filesystem;

using detail::pointer_token;
using detail::printable;

// Turns the streamed elements and the top-level DOM into a BatchFile. Pointers are built only along the path being
// read. Shapes and pairs are read as the parser completes them; a pair read before the shapes array ended has its
// shape indices range-checked in finish().
class BatchReader {
 public:
  static constexpr const char* kTopLevelKeys[] = {"shapes", "pairs", "rays", "objects", "query", "solver",
                                                  "tolerance", "precision", "margin"};

  BatchReader(const std::string& source, const std::string& base_dir, std::size_t text_bytes)
      : source_(source), base_dir_(base_dir), text_bytes_(text_bytes) {}

  void element(const std::string& array, std::size_t i, const json& v) {
    // The pair count is not known while streaming: reserve for the most pairs the text can hold (a pair is at least
    // the 14 bytes of `{"a":0,"b":0},`). Pages never written are never resident, so this costs address space only,
    // and the arrays never reallocate (growth by doubling would briefly hold them twice).
    if (array == "pairs" && i == 0) file_.pairs.reserve(text_bytes_ / 14 + 1);
    if (array == "shapes") file_.shapes.add(read_shape(v, "/shapes/" + std::to_string(i)));
    else if (array == "rays") read_ray(v, "/rays/" + std::to_string(i), file_);
    else if (array == "objects") objects_seen_ = true, read_object(v, "/objects/" + std::to_string(i), file_);
    else read_pair(v, "/pairs/" + std::to_string(i), file_);
  }
  void array_end(const std::string& array) {
    if (array == "shapes") shapes_done_ = true;
    if (array == "objects") objects_seen_ = true;
  }

  BatchFile finish(const json& root) {
    if (!root.is_object()) fail("", "the top level must be an object, got " + describe(root));
    check_keys(root, "", kTopLevelKeys);
    array_field(root, "", "shapes");
    // A file of rays or a ray scene needs no pairs.
    if (root.contains("pairs") || !(root.contains("rays") || root.contains("objects"))) array_field(root, "", "pairs");
    if (root.contains("rays")) array_field(root, "", "rays");
    file_.has_objects = root.contains("objects");
    if (file_.has_objects) array_field(root, "", "objects");
    // Whether rays are scene rays depends on a key that may come after them: checked once the whole file is read.
    if (file_.has_objects && first_shape_ray_) scene_ray_with_shape(*first_shape_ray_);
    if (!file_.has_objects && first_scene_ray_) {
      fail("/rays/" + std::to_string(*first_scene_ray_) + "/shape",
           "required field is missing (rays without a shape need \"objects\" to be cast against)");
    }
    if (!shapes_checked_) {  // pairs came before the shapes: check their indices now
      for (std::size_t i = 0; i < file_.pairs.size(); ++i) {
        late_index(file_.pairs.shape_a[i], "/pairs/" + std::to_string(i) + "/a");
        late_index(file_.pairs.shape_b[i], "/pairs/" + std::to_string(i) + "/b");
      }
    }
    if (!objects_checked_)  // objects came before the shapes
      for (std::size_t i = 0; i < file_.objects.size(); ++i)
        late_index(file_.objects[i].shape, "/objects/" + std::to_string(i) + "/shape");
    if (!rays_checked_)  // rays came before the shapes
      for (std::size_t i = 0; i < file_.rays.shape.size(); ++i)
        late_index(file_.rays.shape[i], "/rays/" + std::to_string(i) + "/shape");
    if (root.contains("query")) file_.query = parse_named(root["query"], "/query", parse_query_level);
    if (root.contains("solver")) file_.solver = parse_named(root["solver"], "/solver", parse_solver);
    if (root.contains("precision")) file_.precision = parse_named(root["precision"], "/precision", parse_precision);
    if (root.contains("tolerance")) file_.tolerance = non_negative(root["tolerance"], "/tolerance");
    if (root.contains("margin")) file_.margin = non_negative(root["margin"], "/margin");
    return std::move(file_);
  }

 private:
  [[noreturn]] void fail(const std::string& pointer, const std::string& message) const {
    throw InputError(source_ + ": " + (pointer.empty() ? std::string("top level") : pointer) + ": " + message);
  }

  // "string \"nan\"", "array of 2 elements", ... (containers are not printed: they may be huge).
  static std::string describe(const json& v) {
    if (v.is_array()) return "array of " + std::to_string(v.size()) + " elements";
    if (v.is_object()) return "object";
    std::string text = v.dump(-1, ' ', false, json::error_handler_t::replace);
    if (text.size() > 40) text = text.substr(0, 37) + "...";
    return std::string(v.type_name()) + " " + text;
  }

  template <std::size_t N>
  void check_keys(const json& object, const std::string& pointer, const char* const (&allowed)[N]) const {
    for (const auto& item : object.items()) {
      bool known = false;
      for (const char* name : allowed) known = known || item.key() == name;
      if (known) continue;
      std::string list;
      for (const char* name : allowed) list += (list.empty() ? "" : ", ") + std::string(name);
      fail(pointer + "/" + pointer_token(item.key()), "unknown key '" + printable(item.key(), 64) + "' (allowed here: " + list + ")");
    }
  }

  const json& field(const json& object, const std::string& pointer, const char* key) const {
    const auto it = object.find(key);
    if (it == object.end()) fail(pointer + "/" + key, "required field is missing");
    return *it;
  }

  const json& array_field(const json& object, const std::string& pointer, const char* key) const {
    const json& v = field(object, pointer, key);
    if (!v.is_array()) fail(pointer + "/" + key, "expected an array, got " + describe(v));
    return v;
  }

  const json& object_value(const json& v, const std::string& pointer) const {
    if (!v.is_object()) fail(pointer, "expected an object, got " + describe(v));
    return v;
  }

  double number(const json& v, const std::string& pointer) const {
    if (!v.is_number()) fail(pointer, "expected a number, got " + describe(v));
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(pointer, "the number must be finite");
    return x;
  }

  double positive(const json& v, const std::string& pointer) const {
    const double x = number(v, pointer);
    if (!(x > 0.0)) fail(pointer, "must be > 0, got " + v.dump());
    return x;
  }

  double non_negative(const json& v, const std::string& pointer) const {
    const double x = number(v, pointer);
    if (x < 0.0) fail(pointer, "must be >= 0, got " + v.dump());
    return x;
  }

  const json& sized_array(const json& v, const std::string& pointer, std::size_t n) const {
    if (!v.is_array()) fail(pointer, "expected an array of " + std::to_string(n) + " numbers, got " + describe(v));
    if (v.size() != n) {
      fail(pointer, "expected " + std::to_string(n) + " elements, got " + std::to_string(v.size()));
    }
    return v;
  }

  Eigen::Vector3d vec3(const json& v, const std::string& pointer) const {
    sized_array(v, pointer, 3);
    Eigen::Vector3d out;
    for (int i = 0; i < 3; ++i) out[i] = number(v[i], pointer + "/" + std::to_string(i));
    return out;
  }

  Eigen::Vector3d positive_vec3(const json& v, const std::string& pointer) const {
    sized_array(v, pointer, 3);
    Eigen::Vector3d out;
    for (int i = 0; i < 3; ++i) out[i] = positive(v[i], pointer + "/" + std::to_string(i));
    return out;
  }

  std::vector<Eigen::Vector3d> points(const json& v, const std::string& pointer, std::size_t min_count) const {
    if (!v.is_array()) fail(pointer, "expected an array of [x, y, z] points, got " + describe(v));
    if (v.size() < min_count) {
      fail(pointer, "expected at least " + std::to_string(min_count) + " points, got " + std::to_string(v.size()));
    }
    std::vector<Eigen::Vector3d> out;
    out.reserve(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) out.push_back(vec3(v[i], pointer + "/" + std::to_string(i)));
    return out;
  }

  template <typename Enum>
  Enum parse_named(const json& v, const std::string& pointer, Enum (*parse)(const std::string&)) const {
    if (!v.is_string()) fail(pointer, "expected a string, got " + describe(v));
    try {
      return parse(v.get<std::string>());
    } catch (const InputError& e) {
      fail(pointer, e.what());
    }
  }

  // Runs a Shape factory, prefixing its InputError with the pointer it concerns (and dropping the factory's own
  // "field: " prefix when it repeats the pointer's last token).
  template <typename Make>
  Shape build(const std::string& pointer, Make make, const std::string& context = "") const {
    try {
      return make();
    } catch (const InputError& e) {
      std::string message = e.what();
      const std::string field = pointer.substr(pointer.rfind('/') + 1) + ": ";
      if (message.rfind(field, 0) == 0) message.erase(0, field.size());
      fail(pointer, context + message);
    }
  }

  Shape read_shape(const json& v, const std::string& p) const {
    object_value(v, p);
    const json& type_value = field(v, p, "type");
    if (!type_value.is_string()) fail(p + "/type", "expected a string, got " + describe(type_value));
    const std::string type = type_value.get<std::string>();
    Shape shape;
    if (type == "sphere") {
      check_keys(v, p, {"type", "radius", "inflation"});
      const double r = positive(field(v, p, "radius"), p + "/radius");
      shape = build(p, [&] { return Shape::sphere(r); });
    } else if (type == "capsule" || type == "cylinder" || type == "cone") {
      check_keys(v, p, {"type", "radius", "half_length", "inflation"});
      const double r = positive(field(v, p, "radius"), p + "/radius");
      const double h = positive(field(v, p, "half_length"), p + "/half_length");
      shape = build(p, [&] {
        return type == "capsule" ? Shape::capsule(r, h) : type == "cylinder" ? Shape::cylinder(r, h) : Shape::cone(r, h);
      });
    } else if (type == "box") {
      check_keys(v, p, {"type", "half_extents", "inflation"});
      const Eigen::Vector3d h = positive_vec3(field(v, p, "half_extents"), p + "/half_extents");
      shape = build(p + "/half_extents", [&] { return Shape::box(h); });
    } else if (type == "ellipsoid") {
      check_keys(v, p, {"type", "radii", "inflation"});
      const Eigen::Vector3d r = positive_vec3(field(v, p, "radii"), p + "/radii");
      shape = build(p + "/radii", [&] { return Shape::ellipsoid(r.x(), r.y(), r.z()); });
    } else if (type == "convex") {
      check_keys(v, p, {"type", "vertices", "inflation"});
      const auto pts = points(field(v, p, "vertices"), p + "/vertices", 4);
      shape = build(p + "/vertices", [&] { return Shape::convex(pts); });
    } else if (type == "mesh") {
      check_keys(v, p, {"type", "file", "inflation"});
      shape = read_mesh(field(v, p, "file"), p + "/file");
    } else if (type == "triangle") {
      check_keys(v, p, {"type", "vertices", "inflation"});
      const json& vertices = field(v, p, "vertices");
      if (vertices.is_array() && vertices.size() != 3) {
        fail(p + "/vertices", "a triangle needs exactly 3 vertices, got " + std::to_string(vertices.size()));
      }
      const auto pts = points(vertices, p + "/vertices", 3);
      shape = build(p + "/vertices", [&] { return Shape::triangle_shape(pts[0], pts[1], pts[2]); });
    } else if (type == "halfspace") {
      check_keys(v, p, {"type", "normal", "offset", "inflation"});
      const Eigen::Vector3d n = vec3(field(v, p, "normal"), p + "/normal");
      if (n.norm() == 0.0) fail(p + "/normal", "the normal must not be zero");
      const double offset = number(field(v, p, "offset"), p + "/offset");
      shape = build(p, [&] { return Shape::halfspace(n, offset); });
    } else {
      fail(p + "/type",
           "unknown shape type '" + printable(type, 64) +
               "' (valid: sphere, capsule, box, cylinder, cone, ellipsoid, convex, mesh, triangle, halfspace)");
    }
    if (v.contains("inflation")) {
      const double r = non_negative(v["inflation"], p + "/inflation");
      shape = build(p + "/inflation", [&] { return shape.inflated(r); });
    }
    return shape;
  }

  Shape read_mesh(const json& v, const std::string& pointer) const {
    if (!v.is_string() || v.get<std::string>().empty()) fail(pointer, "expected a file name, got " + describe(v));
    const std::string path = (fs::path(base_dir_) / v.get<std::string>()).string();
    std::vector<Eigen::Vector3d> pts;
    try {
      pts = load_mesh_points(path);
    } catch (const InputError& e) {
      fail(pointer, e.what());
    }
    // The hull is named after the mesh file (not "vertices") so a flat mesh's message says which file is flat.
    return build(pointer, [&] { return Shape::convex(compute_convex_hull(pts, "mesh '" + printable(path, 200) + "'")); });
  }

  std::uint32_t shape_index(const json& v, const std::string& pointer, std::size_t shape_count) const {
    if (!v.is_number_integer()) fail(pointer, "expected a shape index (non-negative integer), got " + describe(v));
    if (v.is_number_unsigned() && v.get<std::uint64_t>() < shape_count) return v.get<std::uint32_t>();
    fail(pointer, "shape index " + v.dump() + " is out of range (the batch has " + std::to_string(shape_count) +
                      " shapes)");
  }

  Eigen::Quaterniond quaternion(const json& v, const std::string& pointer) const {
    sized_array(v, pointer, 4);
    double q[4];
    for (int i = 0; i < 4; ++i) q[i] = number(v[i], pointer + "/" + std::to_string(i));
    try {
      return checked_unit_quaternion(Eigen::Quaterniond(q[0], q[1], q[2], q[3]));
    } catch (const InputError& e) {
      fail(pointer, e.what());
    }
  }

  Eigen::Quaterniond rotation_matrix(const json& v, const std::string& pointer) const {
    if (!v.is_array() || v.size() != 3) fail(pointer, "expected 3 rows of 3 numbers, got " + describe(v));
    Eigen::Matrix3d r;
    for (int i = 0; i < 3; ++i) r.row(i) = vec3(v[i], pointer + "/" + std::to_string(i)).transpose();
    try {
      return rotation_from_matrix(r);
    } catch (const InputError& e) {
      fail(pointer, e.what());
    }
  }

  Pose read_pose(const json& v, const std::string& p) const {
    object_value(v, p);
    check_keys(v, p, {"translation", "quaternion", "rotation"});
    Pose pose;
    if (v.contains("translation")) pose.translation = vec3(v["translation"], p + "/translation");
    if (v.contains("quaternion") && v.contains("rotation")) fail(p, "give either 'quaternion' or 'rotation', not both");
    if (v.contains("quaternion")) pose.rotation = quaternion(v["quaternion"], p + "/quaternion");
    if (v.contains("rotation")) pose.rotation = rotation_matrix(v["rotation"], p + "/rotation");
    return pose;
  }

  void read_pair(const json& v, const std::string& p, BatchFile& file) {
    object_value(v, p);
    check_keys(v, p, {"a", "b", "pose_a", "pose_b"});
    // Before the shapes array has ended, only the index's type is checked here (finish() checks the range).
    shapes_checked_ = shapes_checked_ && shapes_done_;
    const std::size_t count = shapes_done_ ? file.shapes.size() : std::size_t{1} << 32;
    const std::uint32_t a = shape_index(field(v, p, "a"), p + "/a", count);
    const std::uint32_t b = shape_index(field(v, p, "b"), p + "/b", count);
    const Pose pose_a = v.contains("pose_a") ? read_pose(v["pose_a"], p + "/pose_a") : Pose::identity();
    const Pose pose_b = v.contains("pose_b") ? read_pose(v["pose_b"], p + "/pose_b") : Pose::identity();
    file.pairs.add(a, pose_a, b, pose_b);
  }

  // A ray against one posed shape (the shape form of batchcol/rays.hpp). A file states its rays, so a bad one is an
  // error naming it rather than the per-ray invalid status of the API: a zero direction, a negative t_max.
  void read_ray(const json& v, const std::string& p, BatchFile& file) {
    object_value(v, p);
    if (!v.contains("shape") && !v.contains("pose")) return read_scene_ray(v, p, file);
    if (!first_shape_ray_) first_shape_ray_ = file.rays.size() + file.scene_rays.size();
    if (objects_seen_) scene_ray_with_shape(*first_shape_ray_);  // else finish() decides
    check_keys(v, p, {"shape", "pose", "origin", "direction", "t_max"});
    // As for pairs: before the shapes array has ended, finish() checks the index's range.
    rays_checked_ = rays_checked_ && shapes_done_;
    const std::size_t count = shapes_done_ ? file.shapes.size() : std::size_t{1} << 32;
    const std::uint32_t shape = shape_index(field(v, p, "shape"), p + "/shape", count);
    const Pose pose = v.contains("pose") ? read_pose(v["pose"], p + "/pose") : Pose::identity();
    const Ray ray = read_ray_line(v, p);
    file.rays.add(shape, pose, ray.origin, ray.direction, ray.t_max);
  }

  // The range check of a shape index read before the "shapes" array had ended (shape_index() could not do it then).
  void late_index(std::uint32_t index, const std::string& pointer) const {
    const std::size_t n = file_.shapes.size();
    if (index >= n)
      fail(pointer, "shape index " + std::to_string(index) + " is out of range (the batch has " + std::to_string(n) +
                        " shapes)");
  }

  [[noreturn]] void scene_ray_with_shape(std::size_t i) const {
    fail("/rays/" + std::to_string(i) + "/shape",
         "the rays of a file with \"objects\" are cast against the objects: give no 'shape' or 'pose'");
  }

  // A ray of a scene file (one with "objects"): origin, direction and t_max only.
  void read_scene_ray(const json& v, const std::string& p, BatchFile& file) {
    if (!first_scene_ray_) first_scene_ray_ = file.rays.size() + file.scene_rays.size();
    check_keys(v, p, {"origin", "direction", "t_max"});
    const Ray ray = read_ray_line(v, p);
    file.scene_rays.add(ray.origin, ray.direction, ray.t_max);
  }

  struct Ray {
    Eigen::Vector3d origin, direction;
    double t_max;
  };

  // The checks are those of detail::ray_is_valid() (a ray it would mark invalid_input is an error here): JSON numbers
  // are finite already; |d|^2 must not underflow to 0 (the kernels divide by it), so a direction of 1e-200 counts as
  // zero.
  Ray read_ray_line(const json& v, const std::string& p) const {
    const Eigen::Vector3d origin = vec3(field(v, p, "origin"), p + "/origin");
    const Eigen::Vector3d direction = vec3(field(v, p, "direction"), p + "/direction");
    if (!(direction.squaredNorm() > 0.0)) fail(p + "/direction", "the direction must not be zero");
    // JSON has no infinity: an absent t_max is +inf.
    const double t_max = v.contains("t_max") ? non_negative(v["t_max"], p + "/t_max") : INFINITY;
    return {origin, direction, t_max};
  }

  // An object of a ray scene: a shape index and a pose.
  void read_object(const json& v, const std::string& p, BatchFile& file) {
    object_value(v, p);
    check_keys(v, p, {"shape", "pose"});
    objects_checked_ = objects_checked_ && shapes_done_;
    const std::size_t count = shapes_done_ ? file.shapes.size() : std::size_t{1} << 32;
    const std::uint32_t shape = shape_index(field(v, p, "shape"), p + "/shape", count);
    file.objects.push_back({shape, v.contains("pose") ? read_pose(v["pose"], p + "/pose") : Pose::identity()});
  }

  const std::string& source_;
  const std::string& base_dir_;
  std::size_t text_bytes_;
  BatchFile file_;
  bool shapes_done_ = false;
  bool shapes_checked_ = true;  // no pair has skipped the range check so far
  bool rays_checked_ = true;    // no ray has skipped the range check so far
  bool objects_checked_ = true;  // no object has skipped the range check so far
  bool objects_seen_ = false;    // an "objects" element or the array's end has been read
  std::optional<std::size_t> first_shape_ray_, first_scene_ray_;  // index in "rays" of the first of each kind
};

}  // namespace

void BatchFile::apply_to(QueryOptions& options) const {
  if (query) options.level = *query;
  if (solver) options.solver = *solver;
  if (tolerance) options.tolerance = *tolerance;
  if (precision) options.precision = *precision;
  if (margin) options.margin = *margin;
}

BatchFile parse_batch_json(const std::string& text, const std::string& source, const std::string& base_dir) {
  json root;
  BatchReader reader(source, base_dir, text.size());
  std::vector<std::string> allowed;
  for (const char* key : BatchReader::kTopLevelKeys) allowed.emplace_back(key);
  detail::JsonConsumer consumer{[&](const std::string& array, std::size_t i, const json& v) { reader.element(array, i, v); },
                                [&](const std::string& array) { reader.array_end(array); }};
  detail::StreamingDom builder(text, root, {"shapes", "pairs", "rays", "objects"}, allowed, consumer);
  if (!json::sax_parse(text, &builder)) {
    std::string where;
    if (builder.error_index) {
      const auto [line, column] = detail::line_and_column(text, *builder.error_index);
      where = "line " + std::to_string(line) + ", column " + std::to_string(column) + ": ";
    }
    if (!builder.error_pointer.empty()) where += builder.error_pointer + ": ";
    throw InputError(source + ": " + where + builder.error_message);
  }
  return reader.finish(root);
}

BatchFile load_batch_file(const std::string& path) {
  const std::string name = printable(path, 200);  // for messages
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw InputError(name + ": no such file");
  if (fs::is_directory(status)) throw InputError(name + ": is a directory, expected a batch file (.json)");
  if (!fs::is_regular_file(status)) throw InputError(name + ": not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(name + ": cannot open: " + std::strerror(errno));
  // Read straight into one string of the file's size (a stringstream would hold the text twice).
  std::string text(static_cast<std::size_t>(fs::file_size(path, ec)), '\0');
  if (ec) throw InputError(name + ": cannot read the file size: " + ec.message());
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (static_cast<std::size_t>(in.gcount()) != text.size() || in.bad()) throw InputError(name + ": read error");
  const fs::path parent = fs::path(path).parent_path();
  return parse_batch_json(text, name, parent.empty() ? std::string(".") : parent.string());
}

}  // namespace batchcol
