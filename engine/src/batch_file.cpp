// Batch files: JSON text -> ShapeTable + PairBatch + optional query settings, validated completely before anything
// is returned. Every error names the file and the JSON pointer of the offending field; syntax errors also give the
// line and column.
#include "batchcol/io.hpp"

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

std::string pointer_token(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

// Builds the DOM like json::parse, but also rejects duplicate keys (json::parse keeps the last silently) and keeps
// the byte offset and JSON pointer of a parse error.
class DomBuilder final : public nlohmann::json_sax<json> {
 public:
  DomBuilder(const std::string& text, json& root) : text_(text), root_(root) {}

  bool null() override { return add(json(nullptr)); }
  bool boolean(bool v) override { return add(json(v)); }
  bool number_integer(number_integer_t v) override { return add(json(v)); }
  bool number_unsigned(number_unsigned_t v) override { return add(json(v)); }
  bool number_float(number_float_t v, const string_t&) override { return add(json(v)); }
  bool string(string_t& v) override { return add(json(std::move(v))); }
  bool binary(binary_t&) override { return false; }  // JSON text never holds binary values
  bool start_object(std::size_t) override { return open(json::object()); }
  bool start_array(std::size_t) override { return open(json::array()); }
  bool end_object() override { return close(); }
  bool end_array() override { return close(); }

  bool key(string_t& k) override {
    Frame& frame = stack_.back();
    if (frame.value->contains(k)) {
      error_pointer = container_pointer() + "/" + pointer_token(k);
      error_message = "duplicate key";
      return false;
    }
    frame.key = std::move(k);
    return true;
  }

  bool parse_error(std::size_t position, const std::string& last_token, const json::exception& ex) override {
    // `position` counts the characters read, i.e. it is just past the offending token; point at the token's start.
    error_index = position > 0 ? position - 1 : 0;
    if (!last_token.empty() && position >= last_token.size() &&
        text_.compare(position - last_token.size(), last_token.size(), last_token) == 0) {
      error_index = position - last_token.size();
    }
    // A number overflow is a complete value, so the pointer of that value is exact; other errors name the container.
    error_pointer = ex.id == 406 ? value_pointer() : container_pointer();
    std::string what = ex.what();
    const auto bracket = what.find("] ");
    if (bracket != std::string::npos) what.erase(0, bracket + 2);
    if (what.rfind("parse error", 0) == 0) {  // drop nlohmann's own "parse error at line L, column C: "
      const auto colon = what.find(": ");
      if (colon != std::string::npos) what.erase(0, colon + 2);
    }
    error_message = "invalid JSON: " + what;
    return false;
  }

  std::optional<std::size_t> error_index;  // index into the text, for syntax errors only
  std::string error_pointer;
  std::string error_message;

 private:
  struct Frame {
    json* value;
    std::string key;  // key of the member being read (objects only)
  };

  json* insert(json v) {
    if (stack_.empty()) {
      root_ = std::move(v);
      return &root_;
    }
    Frame& parent = stack_.back();
    if (parent.value->is_array()) {
      parent.value->push_back(std::move(v));
      return &parent.value->back();
    }
    json& slot = (*parent.value)[parent.key];
    slot = std::move(v);
    return &slot;
  }
  bool add(json v) {
    insert(std::move(v));
    return true;
  }
  bool open(json v) {
    stack_.push_back({insert(std::move(v)), {}});
    return true;
  }
  bool close() {
    stack_.pop_back();
    return true;
  }
  std::string child_token(const Frame& frame, bool next) const {
    if (!frame.value->is_array()) return pointer_token(frame.key);
    const std::size_t n = frame.value->size();
    return std::to_string(next ? n : n - 1);
  }
  std::string container_pointer() const {
    std::string out;
    for (std::size_t i = 1; i < stack_.size(); ++i) out += "/" + child_token(stack_[i - 1], false);
    return out;
  }
  std::string value_pointer() const {
    return stack_.empty() ? std::string() : container_pointer() + "/" + child_token(stack_.back(), true);
  }

  const std::string& text_;
  json& root_;
  std::vector<Frame> stack_;
};

// 1-based line and column of the character at `index` (index == size means the end of the text).
std::pair<std::size_t, std::size_t> line_and_column(const std::string& text, std::size_t index) {
  index = std::min(index, text.size());
  std::size_t line = 1, line_start = 0;
  for (std::size_t i = 0; i < index; ++i) {
    if (text[i] == '\n') {
      ++line;
      line_start = i + 1;
    }
  }
  return {line, index - line_start + 1};
}

// Turns the DOM into a BatchFile. Pointers are built only along the path being read.
class BatchReader {
 public:
  BatchReader(const std::string& source, const std::string& base_dir) : source_(source), base_dir_(base_dir) {}

  BatchFile read(const json& root) const {
    if (!root.is_object()) fail("", "the top level must be an object, got " + describe(root));
    check_keys(root, "", {"shapes", "pairs", "rays", "query", "solver", "tolerance", "precision", "margin"});
    BatchFile file;
    const json& shapes = array_field(root, "", "shapes");
    for (std::size_t i = 0; i < shapes.size(); ++i) file.shapes.add(read_shape(shapes[i], "/shapes/" + std::to_string(i)));
    if (root.contains("pairs") || !root.contains("rays")) {  // a file of rays needs no pairs
      const json& pairs = array_field(root, "", "pairs");
      file.pairs.reserve(pairs.size());
      for (std::size_t i = 0; i < pairs.size(); ++i) read_pair(pairs[i], "/pairs/" + std::to_string(i), file);
    }
    if (root.contains("rays")) {
      const json& rays = array_field(root, "", "rays");
      for (std::size_t i = 0; i < rays.size(); ++i) read_ray(rays[i], "/rays/" + std::to_string(i), file);
    }
    if (root.contains("query")) file.query = parse_named(root["query"], "/query", parse_query_level);
    if (root.contains("solver")) file.solver = parse_named(root["solver"], "/solver", parse_solver);
    if (root.contains("precision")) file.precision = parse_named(root["precision"], "/precision", parse_precision);
    if (root.contains("tolerance")) file.tolerance = non_negative(root["tolerance"], "/tolerance");
    if (root.contains("margin")) file.margin = non_negative(root["margin"], "/margin");
    return file;
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

  void check_keys(const json& object, const std::string& pointer, std::initializer_list<const char*> allowed) const {
    for (const auto& item : object.items()) {
      bool known = false;
      for (const char* name : allowed) known = known || item.key() == name;
      if (known) continue;
      std::string list;
      for (const char* name : allowed) list += (list.empty() ? "" : ", ") + std::string(name);
      fail(pointer + "/" + pointer_token(item.key()), "unknown key '" + item.key() + "' (allowed here: " + list + ")");
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
           "unknown shape type '" + type +
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
    return build(pointer, [&] { return Shape::convex(compute_convex_hull(pts, "mesh '" + path + "'")); });
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

  void read_pair(const json& v, const std::string& p, BatchFile& file) const {
    object_value(v, p);
    check_keys(v, p, {"a", "b", "pose_a", "pose_b"});
    const std::uint32_t a = shape_index(field(v, p, "a"), p + "/a", file.shapes.size());
    const std::uint32_t b = shape_index(field(v, p, "b"), p + "/b", file.shapes.size());
    const Pose pose_a = v.contains("pose_a") ? read_pose(v["pose_a"], p + "/pose_a") : Pose::identity();
    const Pose pose_b = v.contains("pose_b") ? read_pose(v["pose_b"], p + "/pose_b") : Pose::identity();
    file.pairs.add(a, pose_a, b, pose_b);
  }

  // A ray against one posed shape (the shape form of batchcol/rays.hpp). A file states its rays, so a bad one is an
  // error naming it rather than the per-ray invalid status of the API: a zero direction, a negative t_max.
  void read_ray(const json& v, const std::string& p, BatchFile& file) const {
    object_value(v, p);
    check_keys(v, p, {"shape", "pose", "origin", "direction", "t_max"});
    const std::uint32_t shape = shape_index(field(v, p, "shape"), p + "/shape", file.shapes.size());
    const Pose pose = v.contains("pose") ? read_pose(v["pose"], p + "/pose") : Pose::identity();
    const Eigen::Vector3d origin = vec3(field(v, p, "origin"), p + "/origin");
    const Eigen::Vector3d direction = vec3(field(v, p, "direction"), p + "/direction");
    if (!(direction.squaredNorm() > 0.0)) fail(p + "/direction", "the direction must not be zero");
    // JSON has no infinity: an absent t_max is +inf.
    const double t_max = v.contains("t_max") ? non_negative(v["t_max"], p + "/t_max") : INFINITY;
    file.rays.add(shape, pose, origin, direction, t_max);
  }

  const std::string& source_;
  const std::string& base_dir_;
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
  DomBuilder builder(text, root);
  if (!json::sax_parse(text, &builder)) {
    std::string where;
    if (builder.error_index) {
      const auto [line, column] = line_and_column(text, *builder.error_index);
      where = "line " + std::to_string(line) + ", column " + std::to_string(column) + ": ";
    }
    if (!builder.error_pointer.empty()) where += builder.error_pointer + ": ";
    throw InputError(source + ": " + where + builder.error_message);
  }
  return BatchReader(source, base_dir).read(root);
}

BatchFile load_batch_file(const std::string& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw InputError(path + ": no such file");
  if (fs::is_directory(status)) throw InputError(path + ": is a directory, expected a batch file (.json)");
  if (!fs::is_regular_file(status)) throw InputError(path + ": not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open: " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(path + ": read error");
  const fs::path parent = fs::path(path).parent_path();
  return parse_batch_json(text.str(), path, parent.empty() ? std::string(".") : parent.string());
}

}  // namespace batchcol
