// Shape factories validate their sizes; AABBs are tight (they equal the extent formula along each world axis);
// bounding radii contain the shape; hulls keep only their vertices, with consistent faces and adjacency.
#include "shape_table_access.hpp"  // engine/src: the table's per-shape arrays
#include "support/generators.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <memory>

namespace batchcol {
namespace {

void expect_rejected(const std::function<void()>& make, const std::string& field) {
  try {
    make();
    ADD_FAILURE() << "accepted bad " << field;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

TEST(Shapes, FactoriesRejectNonPositiveAndNonFiniteSizes) {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::nan("");
  for (double bad : {0.0, -1.0, inf, nan}) {
    expect_rejected([&] { Shape::sphere(bad); }, "radius");
    expect_rejected([&] { Shape::capsule(0.1, bad); }, "half_length");
    expect_rejected([&] { Shape::box(0.1, bad, 0.1); }, "half_extents[1]");
    expect_rejected([&] { Shape::cylinder(bad, 0.1); }, "radius");
    expect_rejected([&] { Shape::cone(0.1, bad); }, "half_length");
    expect_rejected([&] { Shape::ellipsoid(0.1, 0.1, bad); }, "radii[2]");
  }
  expect_rejected([] { Shape::sphere(0.1).inflated(-0.01); }, "inflation");
  expect_rejected([] { Shape::halfspace({0, 0, 0}, 0); }, "normal");
  expect_rejected([] { Shape::halfspace({0, 0, 1}, std::nan("")); }, "offset");
  expect_rejected([] { Shape::triangle_shape({0, 0, 0}, {1, 1, 1}, {2, 2, 2}); }, "vertices");
}

TEST(Shapes, AabbIsTightAndBoundingRadiusContainsTheShape) {
  testing::Rng rng(21);
  for (ShapeType t : testing::bounded_shape_types())
    for (int trial = 0; trial < 50; ++trial) {
      Shape s = testing::random_shape(rng, t);
      if (trial % 2) s = s.inflated(0.01);
      const Eigen::Quaterniond q = testing::random_rotation(rng);
      const Eigen::Vector3d p = testing::random_vector(rng);
      const Aabb box = compute_aabb(s, q, p);
      for (int axis = 0; axis < 3; ++axis) {
        const Eigen::Vector3d e = Eigen::Vector3d::Unit(axis);
        EXPECT_NEAR(box.max[axis], p[axis] + testing::extent(s, q.inverse() * e), 1e-12) << to_string(t);
        EXPECT_NEAR(box.min[axis], p[axis] - testing::extent(s, q.inverse() * -e), 1e-12) << to_string(t);
        // The shape's extent in any direction is within its bounding radius.
        const Eigen::Vector3d u = testing::random_unit_vector(rng);
        EXPECT_LE(testing::extent(s, u), s.bounding_radius() + 1e-12) << to_string(t);
      }
    }
  const Aabb h = compute_aabb(Shape::halfspace({0, 0, 1}, 0), Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero());
  EXPECT_TRUE(std::isinf(h.max.x()) && std::isinf(h.min.z()));
}

TEST(Shapes, HullKeepsVerticesFacesAndAdjacency) {
  testing::Rng rng(22);
  const auto pts = testing::random_hull_points(rng, 500, 0.1, 0.3);
  const Shape s = Shape::convex(pts);
  const ConvexHull& h = *s.hull;
  EXPECT_EQ(h.vertices.size(), 500u);  // points on an ellipsoid are all extreme
  EXPECT_EQ(h.faces.size(), 2 * h.vertices.size() - 4);  // Euler: triangulated sphere
  EXPECT_EQ(h.neighbor_offsets.size(), h.vertices.size() + 1);
  EXPECT_EQ(h.neighbors.size(), 3 * h.faces.size());     // each edge seen from both ends
  for (std::size_t f = 0; f < h.faces.size(); ++f) {
    const auto& v = h.vertices;
    const auto& tri = h.faces[f];
    const Eigen::Vector3d n = (v[tri[1]] - v[tri[0]]).cross(v[tri[2]] - v[tri[0]]).normalized();
    EXPECT_GT(n.dot(h.face_normals[f]), 1 - 1e-9);               // counter-clockwise from outside
    EXPECT_LT((h.centroid - v[tri[0]]).dot(n), 0.0);            // centroid behind every face
  }
}

TEST(Shapes, TableStoresEachShapeOnceAndHullsAreShared) {
  ShapeTable table;
  const Shape hull = Shape::convex({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}});
  const auto a = table.add(hull), b = table.add(hull.inflated(0.1));
  EXPECT_EQ(table.size(), 2u);
  EXPECT_EQ(table[a].hull.get(), table[b].hull.get());
}

// The per-shape arrays the kernels read (engine/src/shape_table_access.hpp) hold each shape's fields, in step with
// the Shape records, and a convex shape's hull view covers its hull's arrays; a copy of the table stays valid after
// the original is gone (the views point into the shared hulls, not into the table).
TEST(Shapes, TableKeepsItsPerShapeArraysInStep) {
  using Access = detail::ShapeTableAccess;
  auto table = std::make_unique<ShapeTable>();
  testing::Rng rng(5);
  const Shape shapes[] = {Shape::sphere(0.5), Shape::box(0.1, 0.2, 0.3).inflated(0.05), Shape::cylinder(0.2, 0.4),
                          Shape::halfspace({0, 0, 1}, 0.0),
                          Shape::convex(testing::random_hull_points(rng, 200, 0.05, 0.4)).inflated(0.01)};
  for (const Shape& s : shapes) table->add(s);
  const ShapeTable copy = *table;
  table.reset();
  ASSERT_EQ(Access::types(copy).size(), copy.size());
  ASSERT_EQ(Access::bounding_radii(copy).size(), copy.size());
  ASSERT_EQ(Access::inflations(copy).size(), copy.size());
  ASSERT_EQ(Access::hulls(copy).size(), copy.size());
  for (std::size_t i = 0; i < copy.size(); ++i) {
    EXPECT_EQ(Access::types(copy)[i], shapes[i].type) << i;
    EXPECT_EQ(Access::bounding_radii(copy)[i], shapes[i].bounding_radius()) << i;  // the same function, bits
    for (int k = 0; k < 3; ++k) EXPECT_EQ(Access::sizes(copy, k)[i], shapes[i].size[k]) << i;
    EXPECT_EQ(Access::inflations(copy)[i], shapes[i].inflation) << i;
    const ShapeView v = Access::view(copy, i);
    EXPECT_EQ(v.type, shapes[i].type);
    EXPECT_EQ(v.bounding_radius, Access::bounding_radii(copy)[i]);
    EXPECT_EQ(v.hull != nullptr, shapes[i].type == ShapeType::convex) << i;
  }
  EXPECT_DOUBLE_EQ(Access::bounding_radii(copy)[1], std::sqrt(0.01 + 0.04 + 0.09) + 0.05);
  EXPECT_EQ(Access::bounding_radii(copy)[3], std::numeric_limits<double>::infinity());
  const ConvexHull& hull = *copy[4].hull;
  const HullView& h = Access::hulls(copy)[4];
  ASSERT_EQ(h.vertex_count, hull.vertices.size());
  ASSERT_EQ(h.face_count, hull.faces.size());
  for (std::uint32_t v = 0; v < h.vertex_count; ++v)
    for (int k = 0; k < 3; ++k) ASSERT_EQ(h.vertices[3 * v + k], hull.vertices[v][k]) << v;
  for (std::uint32_t f = 0; f < h.face_count; ++f)
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(h.faces[3 * f + k], hull.faces[f][k]) << f;
      ASSERT_EQ(h.face_normals[3 * f + k], hull.face_normals[f][k]) << f;
    }
  EXPECT_EQ(h.start_vertices, hull.start_vertices.data());
  EXPECT_EQ(h.neighbor_block_offsets, hull.neighbor_block_offsets.data());
  EXPECT_EQ(h.neighbor_block_xyz, hull.neighbor_block_xyz.data());
  EXPECT_EQ(h.radius, hull.radius);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(h.centroid[k], hull.centroid[k]);
  EXPECT_EQ(Access::hulls(copy)[0].vertices, nullptr);  // not convex: an empty view
}

TEST(Shapes, TableKnowsWhenItHoldsOneType) {
  ShapeTable table;
  const auto one_type = [&] { return detail::ShapeTableAccess::one_type(table); };
  EXPECT_FALSE(one_type());  // empty: no type at all
  table.add(Shape::capsule(0.1, 0.2));
  EXPECT_TRUE(one_type());
  table.add(Shape::capsule(0.3, 0.1).inflated(0.01));  // inflation does not change the type
  EXPECT_TRUE(one_type());
  table.add(Shape::sphere(0.1));
  EXPECT_FALSE(one_type());
  table.add(Shape::capsule(0.1, 0.2));
  EXPECT_FALSE(one_type());  // once mixed, always mixed: shapes are never removed
}

}  // namespace
}  // namespace batchcol

namespace batchcol {
namespace {

TEST(Poses, RotationMatricesAndQuaternionsAreCheckedAtTheBoundary) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Pose p = Pose::from_matrix(R, Eigen::Vector3d(1, 2, 3));
  EXPECT_LT((p.rotation.toRotationMatrix() - R).norm(), 1e-14);
  EXPECT_THROW(Pose::from_matrix(2 * R, Eigen::Vector3d::Zero()), InputError);
  EXPECT_THROW(Pose::from_matrix(-R, Eigen::Vector3d::Zero()), InputError);  // det -1: a reflection
  EXPECT_NEAR(checked_unit_quaternion(Eigen::Quaterniond(1 + 9e-7, 0, 0, 0)).norm(), 1.0, 1e-15);
  EXPECT_THROW(checked_unit_quaternion(Eigen::Quaterniond(1.01, 0, 0, 0)), InputError);
  EXPECT_THROW(checked_unit_quaternion(Eigen::Quaterniond(std::nan(""), 0, 0, 0)), InputError);
}

}  // namespace
}  // namespace batchcol
