// The acceptance check of the core engine: `batchcol query` on a 3000-pair mixed batch (every shape family,
// random rigid transforms, gaps 1e-6..0.3 m and depths 1e-5..0.1 m) at tolerance 1e-10 in double must match an
// independent reference within 1e-9 on separated pairs and 1e-7 on penetration depth. The reference values are
// closed forms computed here from the shape definitions (extent gaps of symmetric layouts, ball and box depths),
// not by the engine's kernels.
#include "support/generators.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace batchcol {
namespace {

using testing::Rng;
namespace fs = std::filesystem;

struct RefPair {
  std::string shape_a, shape_b;  // JSON objects
  Pose pa, pb;
  double distance;
};

std::string num(double v) {
  std::ostringstream s;
  s << std::setprecision(17) << v;
  return s.str();
}
std::string vec(const Eigen::Vector3d& v) { return "[" + num(v.x()) + "," + num(v.y()) + "," + num(v.z()) + "]"; }

std::string shape_json(const Shape& s) {
  std::string j;
  switch (s.type) {
    case ShapeType::sphere: j = R"({"type":"sphere","radius":)" + num(s.size.x()); break;
    case ShapeType::capsule: j = R"({"type":"capsule","radius":)" + num(s.size.x()) + R"(,"half_length":)" + num(s.size.y()); break;
    case ShapeType::cylinder: j = R"({"type":"cylinder","radius":)" + num(s.size.x()) + R"(,"half_length":)" + num(s.size.y()); break;
    case ShapeType::cone: j = R"({"type":"cone","radius":)" + num(s.size.x()) + R"(,"half_length":)" + num(s.size.y()); break;
    case ShapeType::box: j = R"({"type":"box","half_extents":)" + vec(s.size); break;
    case ShapeType::ellipsoid: j = R"({"type":"ellipsoid","radii":)" + vec(s.size); break;
    case ShapeType::convex: {
      j = R"({"type":"convex","vertices":[)";
      for (std::size_t i = 0; i < s.hull->vertices.size(); ++i) j += (i ? "," : "") + vec(s.hull->vertices[i]);
      j += "]";
      break;
    }
    default: ADD_FAILURE() << "unused type"; break;
  }
  if (s.inflation > 0) j += R"(,"inflation":)" + num(s.inflation);
  return j + "}";
}

std::string pose_json(const Pose& p) {
  const auto& q = p.rotation;
  return R"({"translation":)" + vec(p.translation) + R"(,"quaternion":[)" + num(q.w()) + "," + num(q.x()) + "," +
         num(q.y()) + "," + num(q.z()) + "]}";
}

/// Separated: extent gap along the line of centres; the cone's axis lies on that line.
RefPair separated(Rng& rng) {
  const std::vector<ShapeType> types = {ShapeType::sphere, ShapeType::capsule, ShapeType::box, ShapeType::cylinder,
                                        ShapeType::cone, ShapeType::ellipsoid, ShapeType::convex};
  const ShapeType ta = types[rng() % types.size()], tb = types[rng() % types.size()];
  Shape a = testing::symmetric_shape(rng, ta, 5), b = testing::symmetric_shape(rng, tb, 5);
  if (rng() % 4 == 0) b = b.inflated(testing::uniform(rng, 0.001, 0.03));
  const Eigen::Quaterniond along_x(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()));  // local z -> world x
  const Eigen::Quaterniond ra = ta == ShapeType::cone || rng() % 2 ? along_x : Eigen::Quaterniond::Identity();
  const Eigen::Quaterniond rb = tb == ShapeType::cone || rng() % 2 ? along_x.conjugate() : Eigen::Quaterniond::Identity();
  const double gap = std::pow(10.0, testing::uniform(rng, -6, -0.5));
  const Eigen::Vector3d e = Eigen::Vector3d::UnitX();
  const double L = testing::extent(a, ra.inverse() * e) + testing::extent(b, rb.inverse() * -e) + gap;
  const Eigen::Quaterniond Q = testing::random_rotation(rng);
  const Eigen::Vector3d T = testing::random_vector(rng) * 20;
  return {shape_json(a), shape_json(b), {T, Q * ra}, {T + Q * (L * e), Q * rb}, gap};
}

/// Overlapping with a closed-form depth: balls (as spheres and as round ellipsoids, the latter through EPA on a
/// curved shape), axis-aligned boxes, and a ball against a box.
RefPair overlapping(Rng& rng) {
  const Eigen::Quaterniond Q = testing::random_rotation(rng);
  const Eigen::Vector3d T = testing::random_vector(rng) * 20;
  const int kind = static_cast<int>(rng() % 3);
  if (kind == 0) {
    const double ra = testing::uniform(rng, 0.02, 0.2), rb = testing::uniform(rng, 0.02, 0.2);
    const double depth = std::pow(10.0, testing::uniform(rng, -5, -1.5));
    const bool round = rng() % 2;
    const Shape a = round ? Shape::ellipsoid(ra, ra, ra) : Shape::sphere(ra);
    const Shape b = round ? Shape::ellipsoid(rb, rb, rb) : Shape::sphere(rb);
    return {shape_json(a), shape_json(b), {T, Q}, {T + Q * (testing::random_unit_vector(rng) * (ra + rb - depth)),
            testing::random_rotation(rng)}, -depth};
  }
  const Eigen::Vector3d ha = testing::random_vector(rng).cwiseAbs() * 0.2 + Eigen::Vector3d::Constant(0.02);
  if (kind == 1) {
    const Eigen::Vector3d hb = testing::random_vector(rng).cwiseAbs() * 0.2 + Eigen::Vector3d::Constant(0.02);
    const Eigen::Vector3d c = testing::random_vector(rng).cwiseProduct(ha + hb) * 0.98;
    const Eigen::Vector3d room = (ha + hb) - c.cwiseAbs();
    return {shape_json(Shape::box(ha)), shape_json(Shape::box(hb)), {T, Q}, {T + Q * c, Q}, -room.minCoeff()};
  }
  const double r = testing::uniform(rng, 0.02, 0.2);
  const Eigen::Vector3d c = testing::random_vector(rng).cwiseProduct(ha + Eigen::Vector3d::Constant(r)) * 0.98;
  const Eigen::Vector3d q = c.cwiseMax(-ha).cwiseMin(ha);
  const double depth = q == c ? r + (ha - c.cwiseAbs()).minCoeff() : r - (c - q).norm();
  if (depth <= 1e-5) return overlapping(rng);  // a corner region miss: draw again
  return {shape_json(Shape::box(ha)), shape_json(Shape::sphere(r)), {T, Q}, {T + Q * c, testing::random_rotation(rng)},
          -depth};
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> f;
  std::stringstream s(line);
  for (std::string x; std::getline(s, x, ',');) f.push_back(x);
  return f;
}

TEST(ReferenceBatch, QueryMatchesIndependentReferenceOn3000MixedPairs) {
#ifndef BATCHCOL_CLI_PATH
  GTEST_SKIP() << "the batchcol CLI is not built";
#else
  Rng rng(2024);
  std::vector<RefPair> pairs;
  for (int i = 0; i < 2000; ++i) pairs.push_back(separated(rng));
  for (int i = 0; i < 1000; ++i) pairs.push_back(overlapping(rng));
  std::string shapes, list;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    shapes += (i ? "," : "") + pairs[i].shape_a + "," + pairs[i].shape_b;
    list += std::string(i ? "," : "") + R"({"a":)" + std::to_string(2 * i) + R"(,"b":)" + std::to_string(2 * i + 1) +
            R"(,"pose_a":)" + pose_json(pairs[i].pa) + R"(,"pose_b":)" + pose_json(pairs[i].pb) + "}";
  }
  const fs::path dir = fs::path(::testing::TempDir()) / "batchcol_reference_batch";
  fs::create_directories(dir);
  std::ofstream(dir / "batch.json") << R"({"shapes":[)" << shapes << R"(],"pairs":[)" << list << "]}";
  const std::string cmd = std::string(BATCHCOL_CLI_PATH) + " query " + (dir / "batch.json").string() +
                          " --query penetration --tolerance 1e-10 --precision double --out " + (dir / "out.csv").string();
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;

  std::ifstream csv(dir / "out.csv");
  std::string line;
  std::getline(csv, line);
  double max_sep = 0, max_depth = 0;
  std::size_t rows = 0;
  while (std::getline(csv, line)) {
    const auto f = split(line);
    ASSERT_GE(f.size(), 4u);
    const std::size_t i = std::stoul(f[0]);
    ASSERT_LT(i, pairs.size());
    EXPECT_EQ(f[1], "converged") << "pair " << i;
    const double err = std::abs(std::stod(f[3]) - pairs[i].distance);
    (pairs[i].distance > 0 ? max_sep : max_depth) = std::max(pairs[i].distance > 0 ? max_sep : max_depth, err);
    EXPECT_EQ(f[2], pairs[i].distance > 0 ? "0" : "1") << "pair " << i;
    ++rows;
  }
  EXPECT_EQ(rows, pairs.size());
  EXPECT_LE(max_sep, 1e-9);
  EXPECT_LE(max_depth, 1e-7);
  std::cout << "reference batch: max |error| separated " << max_sep << " m, penetration " << max_depth << " m\n";
  RecordProperty("max_error_separated", num(max_sep));
  RecordProperty("max_error_penetration", num(max_depth));
#endif
}

}  // namespace
}  // namespace batchcol
