// What the executor, the kernels' callers and the tests read of shapes beyond the public API: a ShapeTable's
// per-shape arrays (kept at add()) and the plain views of shapes and hulls the kernels take (batchcol/types.hpp:
// HullView, ShapeView). The kernels never see Shape, ConvexHull or ShapeTable; the engine hands them these.
#pragma once

#include "batchcol/shapes.hpp"
#include "batchcol/types.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace batchcol {

/// The raw view of a hull's arrays (pointers into `hull`, which must outlive the view).
HullView hull_view(const ConvexHull& hull);
/// The plain record of `shape`; `hull` is the view of shape.hull for convex shapes (else ignored: null).
ShapeView shape_view(const Shape& shape, const HullView* hull);
/// The same with Shape::bounding_radius() given (a table keeps it).
ShapeView shape_view(const Shape& shape, const HullView* hull, double bounding_radius);

/// A lone shape's plain record together with the hull view it points to and a share of the hull, for callers that
/// have a Shape and no table (compute_aabb, kernel_for, tests). Neither copied nor moved: `view.hull` points into
/// the object itself.
struct OwnedShapeView {
  std::shared_ptr<const ConvexHull> owner;  // keeps the arrays `hull` points into alive
  HullView hull;
  ShapeView view;
  explicit OwnedShapeView(const Shape& shape)
      : owner(shape.type == ShapeType::convex ? shape.hull : nullptr),
        hull(owner ? hull_view(*owner) : HullView{}),
        view(shape_view(shape, &hull)) {}
  OwnedShapeView(const OwnedShapeView&) = delete;
  OwnedShapeView& operator=(const OwnedShapeView&) = delete;
};

namespace detail {

/// A ShapeTable's per-shape arrays (ShapeTable's private members; the table is the only writer).
struct ShapeTableAccess {
  /// Each shape's type and Shape::bounding_radius().
  static const std::vector<ShapeType>& types(const ShapeTable& t) { return t.types_; }
  static const std::vector<double>& bounding_radii(const ShapeTable& t) { return t.bounding_radii_; }
  /// Shape::size[k] and Shape::inflation of each shape; the hull view of each (zeros for non-convex shapes).
  static const std::vector<double>& sizes(const ShapeTable& t, int k) { return t.size_[k]; }
  static const std::vector<double>& inflations(const ShapeTable& t) { return t.inflation_; }
  static const std::vector<HullView>& hulls(const ShapeTable& t) { return t.hulls_; }
  /// True when the table is not empty and all its shapes have one type: every valid pair is then of one type pair,
  /// and the executor skips reading the two types of each pair.
  static bool one_type(const ShapeTable& t) { return !t.shapes_.empty() && !t.mixed_; }
  /// The smallest Shape::smallest_size() and the largest finite bounding_radius() of the table's shapes (the
  /// float32 limits apply to them); +inf and 0 for an empty table.
  static double smallest_size(const ShapeTable& t) { return t.smallest_size_; }
  static double largest_radius(const ShapeTable& t) { return t.largest_radius_; }
  /// Shape i's plain record, its hull view pointing into the table (valid while the table is not changed).
  static ShapeView view(const ShapeTable& t, std::size_t i) {
    return shape_view(t.shapes_[i], &t.hulls_[i], t.bounding_radii_[i]);
  }
};

}  // namespace detail
}  // namespace batchcol
