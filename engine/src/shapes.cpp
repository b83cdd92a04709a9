#include "batchcol/shapes.hpp"
#include "convex_hull_search.hpp"
#include "shape_table_access.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace batchcol {
namespace {

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

const std::string kLimits = " (input limits: sizes from " + number(kMinLength) + " to " + number(kMaxLength) + " m)";

void require_positive(double v, const char* field) {
  if (!std::isfinite(v)) throw InputError(std::string(field) + " must be a finite number, got " + number(v));
  if (!(v > 0.0)) throw InputError(std::string(field) + " must be > 0, got " + number(v));
  if (v < kMinLength || v > kMaxLength) throw InputError(std::string(field) + " = " + number(v) + " is out of range" + kLimits);
}

void require_finite(const Eigen::Vector3d& v, const std::string& field) {
  if (!v.allFinite()) throw InputError(field + " must be finite");
  if (v.cwiseAbs().maxCoeff() > kMaxLength)
    throw InputError(field + " has a coordinate beyond " + number(kMaxLength) + " m" + kLimits);
}

Shape make(ShapeType type, const Eigen::Vector3d& size) {
  Shape s;
  s.type = type;
  s.size = size;
  return s;
}

}  // namespace

Shape Shape::sphere(double radius) {
  require_positive(radius, "radius");
  return make(ShapeType::sphere, {radius, 0, 0});
}

Shape Shape::capsule(double radius, double half_length) {
  require_positive(radius, "radius");
  require_positive(half_length, "half_length");
  return make(ShapeType::capsule, {radius, half_length, 0});
}

Shape Shape::box(double hx, double hy, double hz) {
  require_positive(hx, "half_extents[0]");
  require_positive(hy, "half_extents[1]");
  require_positive(hz, "half_extents[2]");
  return make(ShapeType::box, {hx, hy, hz});
}

Shape Shape::cylinder(double radius, double half_length) {
  require_positive(radius, "radius");
  require_positive(half_length, "half_length");
  return make(ShapeType::cylinder, {radius, half_length, 0});
}

Shape Shape::cone(double radius, double half_length) {
  require_positive(radius, "radius");
  require_positive(half_length, "half_length");
  return make(ShapeType::cone, {radius, half_length, 0});
}

Shape Shape::ellipsoid(double rx, double ry, double rz) {
  require_positive(rx, "radii[0]");
  require_positive(ry, "radii[1]");
  require_positive(rz, "radii[2]");
  return make(ShapeType::ellipsoid, {rx, ry, rz});
}

Shape Shape::convex(const std::vector<Eigen::Vector3d>& points) { return convex(compute_convex_hull(points, "vertices")); }

Shape Shape::convex(std::shared_ptr<const ConvexHull> hull) {
  if (!hull || hull->vertices.size() < 4) throw InputError("vertices: a convex hull needs at least 4 vertices");
  for (const auto& v : hull->vertices) require_finite(v, "vertices");
  Shape probe;
  probe.type = ShapeType::convex;
  probe.hull = hull;
  if (probe.smallest_size() < kMinLength) {
    throw InputError("vertices: the hull is smaller than " + number(kMinLength) + " m along every axis" + kLimits);
  }
  Shape s;
  s.type = ShapeType::convex;
  s.hull = with_search_structures(std::move(hull));
  return s;
}

Shape Shape::triangle_shape(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  require_finite(a, "vertices[0]");
  require_finite(b, "vertices[1]");
  require_finite(c, "vertices[2]");
  // A triangle without area has no normal; reject it rather than let the kernels meet a zero-length cross product.
  const double area2 = (b - a).cross(c - a).norm();
  const double scale = std::max({(b - a).norm(), (c - a).norm(), (c - b).norm()});
  if (scale < kMinLength) throw InputError("vertices: the triangle is smaller than " + number(kMinLength) + " m" + kLimits);
  if (!(area2 > 1e-12 * scale * scale))
    throw InputError("vertices: the triangle is degenerate (its three points are collinear or coincide)");
  Shape s;
  s.type = ShapeType::triangle;
  s.triangle = {a, b, c};
  return s;
}

Shape Shape::halfspace(const Eigen::Vector3d& normal, double offset) {
  if (!normal.allFinite()) throw InputError("normal must be finite");  // a direction: any finite magnitude
  if (!std::isfinite(offset)) throw InputError("offset must be a finite number");
  // Scaled by the largest component first: normal.norm() squares the components, which overflow beyond 1e154 (a
  // [1e200, 0, 0] normal became zero) and lose digits below 1e-154 ([3e-162, 4e-162, 0] got length 1.006).
  const double largest = normal.cwiseAbs().maxCoeff();
  if (!(largest > 0.0)) throw InputError("normal must be non-zero");
  const Eigen::Vector3d scaled = normal / largest;
  const double n = scaled.norm();  // in [1, sqrt 3]
  Shape s = make(ShapeType::halfspace, scaled / n);
  s.offset = offset / largest / n;  // {x : normal.x <= offset} is unchanged by scaling both sides
  if (!(std::abs(s.offset) <= kMaxLength)) {
    throw InputError("offset / |normal| = " + number(s.offset) + " is beyond " + number(kMaxLength) + " m" + kLimits);
  }
  return s;
}

Shape Shape::inflated(double radius) const {
  if (!std::isfinite(radius) || radius < 0.0) throw InputError("inflation must be a finite number >= 0, got " + number(radius));
  if (radius > kMaxLength) throw InputError("inflation = " + number(radius) + " is out of range" + kLimits);
  Shape s = *this;
  s.inflation = radius;
  return s;
}

double Shape::bounding_radius() const {
  double core = 0.0;
  switch (type) {
    case ShapeType::sphere: core = size.x(); break;
    case ShapeType::capsule: core = size.x() + size.y(); break;
    // (x x + y y) + z z without hypot's scaling, which is costly on the per-pair path and not needed: sizes are
    // finite, and hypot takes over only if the squares overflow.
    case ShapeType::box: core = std::sqrt((size.x() * size.x() + size.y() * size.y()) + size.z() * size.z()); break;
    case ShapeType::cylinder:
    case ShapeType::cone: core = std::sqrt(size.x() * size.x() + size.y() * size.y()); break;
    case ShapeType::ellipsoid: core = size.maxCoeff(); break;
    case ShapeType::convex: core = hull->radius; break;
    case ShapeType::triangle:
      for (const auto& v : triangle) core = std::max(core, v.norm());
      break;
    case ShapeType::halfspace: return std::numeric_limits<double>::infinity();
  }
  const bool squares = type == ShapeType::box || type == ShapeType::cylinder || type == ShapeType::cone;
  if (squares && !std::isfinite(core))
    core = std::hypot(std::hypot(size.x(), size.y()), type == ShapeType::box ? size.z() : 0.0);
  return core + inflation;
}

double Shape::smallest_size() const {
  switch (type) {
    case ShapeType::sphere: return size.x();
    case ShapeType::capsule:
    case ShapeType::cylinder:
    case ShapeType::cone: return std::min(size.x(), size.y());
    case ShapeType::box:
    case ShapeType::ellipsoid: return size.minCoeff();
    case ShapeType::convex: {
      Eigen::Vector3d lo = hull->vertices.front(), hi = lo;
      for (const auto& v : hull->vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
      return (hi - lo).maxCoeff() / 2;
    }
    case ShapeType::triangle: {
      const auto& t = triangle;
      return (t[0].cwiseMax(t[1]).cwiseMax(t[2]) - t[0].cwiseMin(t[1]).cwiseMin(t[2])).maxCoeff() / 2;
    }
    case ShapeType::halfspace: break;
  }
  return std::numeric_limits<double>::infinity();
}

std::uint32_t ShapeTable::add(Shape shape) {
  if (shapes_.size() >= std::numeric_limits<std::uint32_t>::max()) throw InputError("shape table is full");
  const ShapeType type = shape.type;
  const double radius = shape.bounding_radius(), smallest = shape.smallest_size();
  // The factories check these; a Shape whose fields were set by hand is checked here.
  const bool in_limits = type == ShapeType::halfspace
                             ? std::abs(shape.offset) <= kMaxLength && std::abs(shape.size.norm() - 1.0) <= 1e-12
                             : smallest >= kMinLength && radius <= 4 * kMaxLength;  // implied by sizes <= kMaxLength
  if (!in_limits || !(shape.inflation >= 0.0 && shape.inflation <= kMaxLength)) {
    throw InputError("shape " + std::to_string(shapes_.size()) + " (" + to_string(type) + "): a size is out of range" +
                     kLimits + " or, for a halfspace, the normal is not unit");
  }
  const HullView hull = type == ShapeType::convex && shape.hull ? hull_view(*shape.hull) : HullView{};
  const double size[3] = {shape.size.x(), shape.size.y(), shape.size.z()}, inflation = shape.inflation;
  const std::size_t before = shapes_.size();
  shapes_.push_back(std::move(shape));
  try {  // the arrays grow together: a failed allocation leaves the table as it was
    types_.push_back(type);
    bounding_radii_.push_back(radius);
    for (int k = 0; k < 3; ++k) size_[k].push_back(size[k]);
    inflation_.push_back(inflation);
    hulls_.push_back(hull);
  } catch (...) {
    types_.resize(std::min(types_.size(), before));  // shrinking never allocates
    bounding_radii_.resize(std::min(bounding_radii_.size(), before));
    for (auto& a : size_) a.resize(std::min(a.size(), before));
    inflation_.resize(std::min(inflation_.size(), before));
    hulls_.resize(std::min(hulls_.size(), before));
    shapes_.pop_back();
    throw;
  }
  mixed_ = shapes_.size() > 1 && (mixed_ || type != types_.front());  // a moved-from table starts afresh
  if (shapes_.size() == 1) smallest_size_ = std::numeric_limits<double>::infinity(), largest_radius_ = 0.0;
  smallest_size_ = std::min(smallest_size_, smallest);
  if (type != ShapeType::halfspace) largest_radius_ = std::max(largest_radius_, radius);
  return static_cast<std::uint32_t>(shapes_.size() - 1);
}

HullView hull_view(const ConvexHull& hull) {
  // Eigen's fixed-size 3-vectors are three packed doubles and std::array<uint32, 3> three packed indices, so the
  // hull's vectors are the flat arrays HullView promises.
  static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "Vector3d must be three packed doubles");
  static_assert(sizeof(std::array<std::uint32_t, 3>) == 3 * sizeof(std::uint32_t), "faces must be packed");
  const auto data = [](const auto& v) { return v.empty() ? nullptr : v.data(); };
  HullView h;
  h.vertices = hull.vertices.empty() ? nullptr : hull.vertices.front().data();
  h.vertex_count = static_cast<std::uint32_t>(hull.vertices.size());
  h.face_count = static_cast<std::uint32_t>(hull.faces.size());
  h.faces = hull.faces.empty() ? nullptr : hull.faces.front().data();
  h.face_normals = hull.face_normals.empty() ? nullptr : hull.face_normals.front().data();
  // The kernels check the optional structures by presence: a table of another size, or blocks that do not cover
  // every vertex, are as good as none (a linear scan, a climb from vertex 0).
  h.start_vertices = hull.start_vertices.size() == kHullStartCells ? hull.start_vertices.data() : nullptr;
  h.cell_candidates = h.start_vertices != nullptr && hull.cell_candidates.size() >= kHullStartCells
                          ? hull.cell_candidates.data() : nullptr;
  h.vertex_floats = h.cell_candidates != nullptr && hull.vertex_floats.size() == 3 * hull.vertices.size()
                        ? hull.vertex_floats.data() : nullptr;
  if (hull.neighbor_block_offsets.size() == hull.vertices.size() + 1) {
    h.neighbor_block_offsets = hull.neighbor_block_offsets.data();
    h.neighbor_block_index = data(hull.neighbor_block_index);
    h.neighbor_block_xyz = data(hull.neighbor_block_xyz);
  }
  for (int k = 0; k < 3; ++k) h.centroid[k] = hull.centroid[k];
  h.radius = hull.radius;
  return h;
}

ShapeView shape_view(const Shape& shape, const HullView* hull) {
  return shape_view(shape, hull, shape.bounding_radius());
}

ShapeView shape_view(const Shape& shape, const HullView* hull, double bounding_radius) {
  ShapeView v;
  v.type = shape.type;
  for (int k = 0; k < 3; ++k) v.size[k] = shape.size[k];
  v.offset = shape.offset;
  v.inflation = shape.inflation;
  v.bounding_radius = bounding_radius;
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) v.triangle[i][k] = shape.triangle[i][k];
  v.hull = shape.type == ShapeType::convex ? hull : nullptr;
  return v;
}

}  // namespace batchcol
