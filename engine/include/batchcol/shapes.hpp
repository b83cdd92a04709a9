// Convex shapes and the shape table that stores each shape once.
//
// Conventions: metres; every shape lives in its own local frame; capsule, cylinder and cone axes are the local z
// axis and the cone apex is at +half_length. Any shape may carry an `inflation` radius: the shape becomes its
// Minkowski sum with a ball of that radius (a "swept sphere"). Spheres and capsules are stored the same way, as a
// point and a segment inflated by their radius, so GJK iterates on the core and the radius is added afterwards.
#pragma once

#include "batchcol/export.hpp"

#include "batchcol/errors.hpp"
#include "batchcol/types.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace batchcol {

// The input limits (kMaxLength, kMinLength, their float32 versions), ShapeType and the hull constants are plain
// types shared with the kernels: batchcol/types.hpp.

BATCHCOL_API const char* to_string(ShapeType type);

/// A convex polytope computed by qhull: only the hull vertices are kept, with triangulated faces (outward normals)
/// and vertex adjacency (compressed rows) for hill-climbing support queries on large hulls.
struct ConvexHull {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<std::uint32_t, 3>> faces;  // counter-clockwise seen from outside
  std::vector<Eigen::Vector3d> face_normals;        // unit, outward
  std::vector<std::uint32_t> neighbor_offsets;      // size vertices+1
  std::vector<std::uint32_t> neighbors;             // vertex indices adjacent through a hull edge
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // mean of the hull vertices (inside the hull)
  double radius = 0.0;  // largest vertex norm: the hull's bounding radius about the local origin
  /// Where a support query without a previous vertex starts climbing: per cube-map cell of directions, the support
  /// vertex of the cell's centre direction (kHullStartCells entries; empty: start at vertex 0).
  std::vector<std::uint32_t> start_vertices;
  /// Per cube-map cell, the support vertex of every direction of the cell or the few vertices it is among, so such a
  /// support is a lookup or a first maximum over 2-15 vertices instead of a climb: kHullStartCells entries
  /// (e & 15 = 1: vertex e >> 4; 2 to kHullCellCandidatesMax: a list of that many ascending vertex indices at
  /// index e >> 4 of this same array; 0: none, the support climbs), then the lists. Built with the direction table
  /// (engine/src/convex_hull.cpp, build_cell_candidates(), which has the argument for its exactness) for hulls
  /// that are climbed; empty for small hulls (scanned) and when absent (pure cells and climbs only).
  std::vector<std::uint32_t> cell_candidates;
  /// The vertices rounded to float (x, y, z per vertex; float(v), to nearest, the kernels' own conversion), for the
  /// float kernels' candidate-list supports: the same values without a conversion per coordinate read. Built with
  /// cell_candidates (empty when it is).
  std::vector<float> vertex_floats;
  /// The adjacency again, in blocks of kNeighborBlock neighbours with their coordinates in structure-of-arrays
  /// order, so that one climbing step computes a block's dot products together (kernels/support.hpp). Vertex v's
  /// blocks are [neighbor_block_offsets[v], neighbor_block_offsets[v + 1]); block b's indices are
  /// neighbor_block_index[kNeighborBlock b ...] and its coordinates neighbor_block_xyz[3 kNeighborBlock b ...]
  /// (x of each, then y, then z). A short last block repeats the vertex's first neighbour.
  static constexpr std::uint32_t kNeighborBlock = kHullNeighborBlock;
  std::vector<std::uint32_t> neighbor_block_offsets;
  std::vector<std::uint32_t> neighbor_block_index;
  std::vector<double> neighbor_block_xyz;
};

/// Computes the convex hull of `points` with qhull. Throws InputError (naming `what`) when a point is not finite or
/// when fewer than 4 non-coplanar points remain.
BATCHCOL_API std::shared_ptr<const ConvexHull> compute_convex_hull(const std::vector<Eigen::Vector3d>& points,
                                                      const std::string& what = "convex");

/// One shape. Build it with the factories below: they validate sizes (finite, within [kMinLength, kMaxLength]) and
/// throw InputError naming the offending field; ShapeTable::add() checks the limits again.
struct BATCHCOL_API Shape {
  ShapeType type = ShapeType::sphere;
  /// sphere: (radius, 0, 0); capsule, cylinder, cone: (radius, half_length, 0); box: half extents;
  /// ellipsoid: radii; halfspace: unit outward normal (the solid is {x : normal.x <= offset}).
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  double offset = 0.0;                             // halfspace only
  double inflation = 0.0;                          // extra swept-sphere radius, >= 0
  std::array<Eigen::Vector3d, 3> triangle{};       // triangle only
  std::shared_ptr<const ConvexHull> hull;          // convex only

  static Shape sphere(double radius);
  static Shape capsule(double radius, double half_length);
  static Shape box(double hx, double hy, double hz);
  static Shape box(const Eigen::Vector3d& half_extents) { return box(half_extents.x(), half_extents.y(), half_extents.z()); }
  static Shape cylinder(double radius, double half_length);
  static Shape cone(double radius, double half_length);
  static Shape ellipsoid(double rx, double ry, double rz);
  static Shape convex(const std::vector<Eigen::Vector3d>& points);
  static Shape convex(std::shared_ptr<const ConvexHull> hull);
  static Shape triangle_shape(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);
  static Shape halfspace(const Eigen::Vector3d& normal, double offset);

  /// Returns a copy with the given inflation radius (must be finite and >= 0).
  Shape inflated(double radius) const;

  /// Radius of a ball centred at the local origin that contains the shape (inflation included); infinite for halfspaces.
  double bounding_radius() const;
  /// The smallest size of the shape (smallest radius, half length or half extent; a hull's or triangle's largest
  /// extent along an axis); infinite for halfspaces. What the kMinLength limits apply to.
  double smallest_size() const;
};

/// Axis-aligned bounding box in the world frame.
struct Aabb {
  Eigen::Vector3d min, max;
};

/// Tight world AABB of `shape` under the pose (rotation, translation); infinite extents for halfspaces.
BATCHCOL_API Aabb compute_aabb(const Shape& shape, const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation);

namespace detail {
struct ShapeTableAccess;  // engine/src/shape_table_access.hpp: what the executor and the kernels read of a table
}

/// Stores each shape once; pairs refer to shapes by index, so many instances of one mesh cost one mesh.
class BATCHCOL_API ShapeTable {
 public:
  std::uint32_t add(Shape shape);
  std::size_t size() const { return shapes_.size(); }
  const Shape& operator[](std::size_t i) const { return shapes_[i]; }
  const std::vector<Shape>& shapes() const { return shapes_; }

 private:
  friend struct detail::ShapeTableAccess;
  std::vector<Shape> shapes_;
  // Per shape, kept at add() (shapes never change afterwards), in structure-of-arrays form: what the executor and
  // the batch kernels read per pair instead of the Shape records (one array per field: a lane gathers from one
  // contiguous array, and no kernel depends on Shape's layout). Hull views point into the shapes' hulls, which the
  // table shares (shared_ptr), so copies of the table stay valid.
  std::vector<ShapeType> types_;
  std::vector<double> bounding_radii_;
  std::vector<double> size_[3];
  std::vector<double> inflation_;
  std::vector<HullView> hulls_;  // zeros for shapes other than convex
  bool mixed_ = false;
  double smallest_size_ = std::numeric_limits<double>::infinity(), largest_radius_ = 0.0;
};

}  // namespace batchcol
