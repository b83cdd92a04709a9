// Real meshes in every supported format (OBJ, ASCII and binary STL, PLY, COLLADA) through load_mesh_points and the
// qhull hull. Expected vertex counts and volumes are computed independently: from the fixture's own text, or in
// closed form for the simple solids. The bunny's hull is checked against its input points along 2000 directions.
#include "batchcol/batchcol.hpp"
#include "batchcol/io.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <tuple>

namespace batchcol {
namespace {

const std::string kDataDir = BATCHCOL_TEST_DATA_DIR;

/// Volume of a closed hull from its outward triangles (divergence theorem).
double hull_volume(const ConvexHull& hull) {
  double six_v = 0.0;
  for (const auto& f : hull.faces)
    six_v += hull.vertices[f[0]].dot(hull.vertices[f[1]].cross(hull.vertices[f[2]]));
  return six_v / 6.0;
}

/// Distinct points, compared exactly (the fixtures write every coordinate the same way each time).
std::set<std::tuple<double, double, double>> distinct(const std::vector<Eigen::Vector3d>& points) {
  std::set<std::tuple<double, double, double>> out;
  for (const auto& p : points) out.emplace(p.x(), p.y(), p.z());
  return out;
}

/// The "v x y z" lines of an OBJ file, read with a stream (not assimp).
std::vector<Eigen::Vector3d> obj_vertices(const std::string& path) {
  std::ifstream in(path);
  std::vector<Eigen::Vector3d> out;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream row(line);
    std::string tag;
    double x, y, z;
    if (row >> tag && tag == "v" && row >> x >> y >> z) out.emplace_back(x, y, z);
  }
  return out;
}

/// Checks a hull against the points it was built from: its vertices are input points, every input point lies inside
/// every face plane, and along random directions the hull's support equals the points' support.
void expect_hull_of(const ConvexHull& hull, const std::vector<Eigen::Vector3d>& points) {
  const auto input = distinct(points);
  for (const auto& v : hull.vertices) EXPECT_TRUE(input.count({v.x(), v.y(), v.z()})) << v.transpose();
  double scale = 0.0;
  for (const auto& p : points) scale = std::max(scale, p.norm());
  // qhull merges facets whose points are within its own rounding (~1e-15 relative): allow 1e-12 of the size.
  const double slack = 1e-12 * scale;
  for (std::size_t f = 0; f < hull.faces.size(); ++f) {
    const Eigen::Vector3d& n = hull.face_normals[f];
    const double offset = n.dot(hull.vertices[hull.faces[f][0]]);
    double worst = -1e300;
    for (const auto& p : points) worst = std::max(worst, n.dot(p) - offset);
    EXPECT_LE(worst, slack) << "face " << f;
  }
  std::mt19937_64 rng(11);
  std::normal_distribution<double> gauss;
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector3d d = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
    double from_points = -1e300, from_hull = -1e300;
    for (const auto& p : points) from_points = std::max(from_points, d.dot(p));
    for (const auto& v : hull.vertices) from_hull = std::max(from_hull, d.dot(v));
    EXPECT_EQ(from_hull, from_points) << d.transpose();
  }
}

std::shared_ptr<const ConvexHull> hull_of(const std::string& path, std::vector<Eigen::Vector3d>& points) {
  points = load_mesh_points(path);
  return compute_convex_hull(points, path);
}

TEST(MeshFormats, ObjBunnyKeepsEveryVertexAndItsHullIsTight) {
  const std::string path = kDataDir + "/bunny.obj";
  const auto expected = obj_vertices(path);
  ASSERT_EQ(expected.size(), 1839u);  // "v" lines in the file
  std::vector<Eigen::Vector3d> points;
  const auto hull = hull_of(path, points);
  // Assimp parses into floats (not always correctly rounded): every point within 2e-6 m (4 float ulps at 7 m) of a
  // point of the file, and the other way round.
  ASSERT_EQ(points.size(), expected.size());
  const auto covered = [](const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& by) {
    for (const auto& p : from) {
      double nearest = 1e300;
      for (const auto& q : by) nearest = std::min(nearest, (p - q).norm());
      if (nearest > 2e-6) return false;
    }
    return true;
  };
  EXPECT_TRUE(covered(points, expected));
  EXPECT_TRUE(covered(expected, points));
  expect_hull_of(*hull, points);
  EXPECT_GT(hull_volume(*hull), 0.0);
}

TEST(MeshFormats, AsciiStlIrregularTetrahedron) {
  std::vector<Eigen::Vector3d> points;
  const auto hull = hull_of(kDataDir + "/tetrahedronIrregular.ascii.stl", points);
  const std::set<std::tuple<double, double, double>> corners = {{0, 0, 0}, {3, 0, 0}, {0, 2, 0}, {0, 0, 1}};
  EXPECT_EQ(distinct(points), corners);
  EXPECT_EQ(hull->vertices.size(), 4u);
  EXPECT_NEAR(hull_volume(*hull), 3.0 * 2.0 * 1.0 / 6.0, 1e-14);  // right-corner tetrahedron: abc / 6
  expect_hull_of(*hull, points);
}

TEST(MeshFormats, BinaryStlCube) {
  std::vector<Eigen::Vector3d> points;
  const auto hull = hull_of(kDataDir + "/cube.bin.stl", points);
  EXPECT_EQ(distinct(points).size(), 8u);
  EXPECT_EQ(hull->vertices.size(), 8u);
  EXPECT_NEAR(hull_volume(*hull), 8.0, 1e-13);  // side 2
  expect_hull_of(*hull, points);
}

TEST(MeshFormats, PlyOctahedron) {
  std::vector<Eigen::Vector3d> points;
  const auto hull = hull_of(kDataDir + "/octahedron.ascii.ply", points);
  EXPECT_EQ(distinct(points).size(), 6u);
  EXPECT_EQ(hull->vertices.size(), 6u);
  EXPECT_NEAR(hull_volume(*hull), 4.0 / 3.0 * 0.125, 1e-15);  // (4/3) r^3 with r = 0.5
  expect_hull_of(*hull, points);
}

TEST(MeshFormats, ColladaBoxIsPlacedByItsNode) {
  std::vector<Eigen::Vector3d> points;
  const auto hull = hull_of(kDataDir + "/box_translated.dae", points);
  ASSERT_EQ(distinct(points).size(), 8u);
  for (const auto& p : points) {
    const Eigen::Vector3d local = (p - Eigen::Vector3d(1, 2, 3)).cwiseAbs();
    // The file stores floats: 1e-6 covers their rounding at coordinates ~3.
    EXPECT_NEAR(local.x(), 0.1, 1e-6);
    EXPECT_NEAR(local.y(), 0.2, 1e-6);
    EXPECT_NEAR(local.z(), 0.3, 1e-6);
  }
  EXPECT_NEAR(hull_volume(*hull), 0.2 * 0.4 * 0.6, 1e-6);
}

TEST(MeshFormats, MeshShapesInABatchFileGiveClosedFormDistances) {
  // Binary-STL cube (half side 1) against each mesh solid, placed along x; the gap follows from the extents.
  const std::string batch = R"({"shapes":[
      {"type":"mesh","file":"cube.bin.stl"},
      {"type":"mesh","file":"octahedron.ascii.ply"},
      {"type":"mesh","file":"tetrahedronIrregular.ascii.stl"},
      {"type":"mesh","file":"bunny.obj"}],
    "pairs":[
      {"a":0,"b":1,"pose_b":{"translation":[1.75,0,0]}},
      {"a":0,"b":2,"pose_b":{"translation":[1.25,0.1,0.2]}},
      {"a":0,"b":0,"pose_b":{"translation":[0,0,2.5]}}],
    "query":"witness","tolerance":1e-12})";
  const BatchFile file = parse_batch_json(batch, "meshes.json", kDataDir);
  ASSERT_EQ(file.shapes.size(), 4u);
  EXPECT_GE(file.shapes[3].hull->vertices.size(), 4u);
  QueryOptions options;
  file.apply_to(options);
  PairResults results;
  collide(file.shapes, file.pairs, options, results);
  const double expected[] = {1.75 - 1 - 0.5, 1.25 - 1, 2.5 - 2};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(results.status[i], Status::converged) << i;
    EXPECT_NEAR(results.distance[i], expected[i], 1e-12) << i;
  }
}

}  // namespace
}  // namespace batchcol
