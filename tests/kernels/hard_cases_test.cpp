// Numerically hard configurations: exact touching, tiny gaps, far from the origin, extreme aspect and size
// ratios, identical poses, degenerate hulls. Answers come from the extent-gap closed form (symmetric layouts).
#include "support/hard_cases.hpp"

#include <gtest/gtest.h>

namespace batchcol {
namespace {

using testing::Rng;

QueryOptions opts(QueryLevel level = QueryLevel::penetration, double tol = 1e-12) {
  QueryOptions o = testing::hard_case_options(Precision::float64, level, tol);
  o.epa_max_iterations = 1000;
  return o;
}

/// Places b beside a along world x (both axis-aligned, symmetric) at the given gap, then moves both by T.
testing::SingleResult beside(const Shape& a, const Shape& b, double gap, const Eigen::Vector3d& T,
                             const QueryOptions& o, Eigen::Vector3d lateral = Eigen::Vector3d::Zero()) {
  return testing::beside(a, testing::kIdentity, b, testing::kIdentity, gap, T, testing::kIdentity, o, lateral);
}

TEST(HardCases, TinyGapsDownTo1e9) {
  const std::vector<std::pair<Shape, Shape>> pairs = {
      {Shape::box(0.1, 0.2, 0.3), Shape::box(0.3, 0.1, 0.05)},          // face-face
      {Shape::sphere(0.1), Shape::box(0.1, 0.1, 0.1)},                   // vertex(point)-face
      {Shape::cylinder(0.1, 0.2), Shape::ellipsoid(0.1, 0.2, 0.05)},     // curved-curved
      {Shape::capsule(0.05, 0.2), Shape::cone(0.1, 0.2)},
  };
  for (const auto& [a, b] : pairs)
    for (double gap : {1e-3, 1e-5, 1e-7, 1e-9})
      for (double sign : {1.0, -1.0}) {
        const auto r = beside(a, b, sign * gap, Eigen::Vector3d(0.3, -0.2, 0.1), opts());
        SCOPED_TRACE(std::string(to_string(a.type)) + "-" + to_string(b.type) + " gap " + std::to_string(sign * gap));
        EXPECT_EQ(r.status, Status::converged);
        // Polytope-like contacts are exact to rounding. Curved-curved contacts at gaps ~1e-9 are limited by the
        // direction of x (~eps |w| / |x| ~ 1e-7 rad at 1e-9 m), measured at 1.2e-10: bound 2e-10 (README).
        const bool curved = a.type == ShapeType::cylinder;
        EXPECT_NEAR(r.distance, sign * gap, (curved ? 2e-10 : 1e-12) + (sign < 0 ? 1e-9 : 0.0));
        EXPECT_EQ(r.collide, sign < 0);
        EXPECT_GT(r.normal.x(), 1 - 1e-6);
      }
}

TEST(HardCases, ExactTouchingFaceFaceEdgeEdgeVertexFace) {
  const Eigen::Quaterniond edge_up(Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitZ()));
  const Eigen::Quaterniond edge_side(Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitY()));
  const Shape cube = Shape::box(0.1, 0.1, 0.1);
  const double diag = 0.1 * std::sqrt(2.0);
  struct Case { const char* name; Pose pa, pb; };
  const std::vector<Case> cases = {
      {"face-face", Pose{}, Pose::from_translation({0.2, 0.03, -0.04})},
      {"edge-edge", Pose{{0, 0, 0}, edge_up}, Pose{{2 * diag, 0, 0}, edge_side}},
      {"vertex-face", Pose{}, Pose{{0.1 + 0.1 * std::sqrt(3.0), 0, 0},
                                   Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d(-1, -1, -1).normalized(),
                                                                       -Eigen::Vector3d::UnitX())}},
  };
  for (const auto& c : cases)
    for (QueryLevel level : {QueryLevel::boolean, QueryLevel::distance, QueryLevel::penetration}) {
      const auto r = testing::run_pair(cube, c.pa, cube, c.pb, opts(level));
      SCOPED_TRACE(std::string(c.name) + " " + to_string(level));
      EXPECT_EQ(r.status, Status::converged);
      // Touching is decided within rounding: either a tiny gap, or an overlap of depth ~0.
      if (level == QueryLevel::penetration || (level == QueryLevel::distance && !r.collide)) {
        EXPECT_NEAR(r.distance, 0.0, 1e-13);
      }
    }
}

TEST(HardCases, FarFromTheOriginInDoubleAndFloat) {
  const Shape a = Shape::box(0.1, 0.2, 0.3), b = Shape::ellipsoid(0.1, 0.05, 0.2);
  for (double far : {1e4, 1e6}) {
    const Eigen::Vector3d T(far, -far, far);
    for (double gap : {1e-2, 1e-4}) {
      const auto d = beside(a, b, gap, T, opts(QueryLevel::witness, 1e-10));
      EXPECT_EQ(d.status, Status::converged);
      EXPECT_NEAR(d.distance, gap, 1e-9) << far;
      // Float works on the relative pose, computed in double: it keeps its accuracy far from the origin.
      QueryOptions f = opts(QueryLevel::witness, 1e-6);
      f.precision = Precision::float32;
      const auto s = beside(a, b, gap, T, f);
      EXPECT_NE(s.status, Status::invalid_input);
      EXPECT_NEAR(s.distance, gap, 1e-5 * 0.5) << far;
    }
  }
}

TEST(HardCases, AspectRatio1e4NeedlesAndPlates) {
  const Shape needle = Shape::capsule(1e-5, 0.1);      // 2e-5 thick, 0.2 long
  const Shape plate = Shape::box(0.2, 0.2, 2e-5);        // 1e4 : 1
  const Shape rod = Shape::cylinder(1e-5, 0.1);
  const Eigen::Quaterniond lay(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()));  // z axis -> x axis
  for (double gap : {1e-3, 1e-6, 1e-9}) {
    // Needle lying flat above the plate, parallel to it.
    const auto r = testing::run_pair(plate, Pose{}, needle, Pose{{0.05, 0.01, 2e-5 + 1e-5 + gap}, lay}, opts());
    EXPECT_NEAR(r.distance, gap, 1e-12) << gap;
    const auto c = testing::run_pair(plate, Pose{}, rod, Pose{{0.05, 0.01, 2e-5 + 1e-5 + gap}, lay}, opts());
    EXPECT_NEAR(c.distance, gap, 1e-12) << gap;
    const auto p = testing::run_pair(plate, Pose{}, plate, Pose{{0.1, 0.05, 4e-5 + gap}, Eigen::Quaterniond::Identity()}, opts());
    EXPECT_NEAR(p.distance, gap, 1e-12) << gap;
  }
}

TEST(HardCases, SizeRatio1e6) {
  const Shape big = Shape::box(100, 100, 100), tiny = Shape::sphere(1e-4);
  const Shape tiny_box = Shape::box(1e-4, 1e-4, 1e-4);
  for (double gap : {1e-3, 1e-6}) {
    QueryOptions o = opts(QueryLevel::witness, 1e-12);
    const auto r = beside(big, tiny, gap, Eigen::Vector3d::Zero(), o);
    EXPECT_NEAR(r.distance, gap, 1e-12 * 100 * 16);  // the precision floor grows with the 100 m box
    const auto b = beside(big, tiny_box, gap, Eigen::Vector3d::Zero(), o, Eigen::Vector3d(0, 3, -7));
    EXPECT_NEAR(b.distance, gap, 1e-12 * 100 * 16);
    EXPECT_EQ(b.status, Status::converged);
  }
}

TEST(HardCases, IdenticalPosesOfIdenticalShapes) {
  Rng rng(4);
  for (ShapeType t : testing::bounded_shape_types()) {
    const Shape s = testing::random_shape(rng, t);
    const Pose p{testing::random_vector(rng), testing::random_rotation(rng)};
    const auto r = testing::run_pair(s, p, s, p, opts());
    SCOPED_TRACE(to_string(t));
    EXPECT_TRUE(r.collide);
    EXPECT_TRUE(std::isfinite(r.distance));
    EXPECT_LE(r.distance, 0.0);
    EXPECT_NE(r.status, Status::invalid_input);
    EXPECT_TRUE(r.normal.allFinite());
    if (t == ShapeType::sphere) { EXPECT_NEAR(r.distance, -2 * s.size.x(), 1e-12); }
    if (t == ShapeType::box) { EXPECT_NEAR(r.distance, -2 * s.size.minCoeff(), 1e-9); }
  }
}

TEST(HardCases, HullsWithDuplicateAndNearlyCoplanarPoints) {
  std::vector<Eigen::Vector3d> cube;
  for (int i = 0; i < 8; ++i) cube.emplace_back(i & 1 ? 0.1 : -0.1, i & 2 ? 0.1 : -0.1, i & 4 ? 0.1 : -0.1);
  std::vector<Eigen::Vector3d> messy = cube;
  messy.insert(messy.end(), cube.begin(), cube.end());                   // duplicates
  messy.emplace_back(0.1, 0.0, 0.0);                                       // on a face
  messy.emplace_back(0.1 - 1e-13, 0.05, 0.02);                             // almost on a face
  messy.emplace_back(0.0, 0.0, 0.0);                                       // interior
  const Shape hull = Shape::convex(messy);
  EXPECT_EQ(hull.hull->vertices.size(), 8u);
  const auto r = beside(hull, Shape::box(0.1, 0.1, 0.1), 1e-6, Eigen::Vector3d::Zero(), opts());
  EXPECT_NEAR(r.distance, 1e-6, 1e-12);
  // A sliver: four points with a tiny but nonzero height still makes a valid hull.
  const Shape sliver = Shape::convex({{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}, {0.03, 0.03, 1e-7}});
  const auto s = testing::run_pair(sliver, Pose{}, Shape::sphere(0.01), Pose::from_translation({0.03, 0.03, 0.02}), opts());
  EXPECT_NEAR(s.distance, 0.02 - 1e-7 - 0.01, 1e-9);
}

TEST(HardCases, FlatOrTooFewHullPointsAreRejectedWithAMessage) {
  const std::vector<std::vector<Eigen::Vector3d>> bad = {
      {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}},                       // three points
      {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 3, 0}},  // coplanar
      {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}},             // collinear
      {{1, 1, 1}, {1, 1, 1}, {1, 1, 1}, {1, 1, 1}},             // one point
      {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, std::nan("")}},  // not finite
  };
  for (const auto& pts : bad) {
    try {
      Shape::convex(pts);
      ADD_FAILURE() << "accepted a degenerate hull of " << pts.size() << " points";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("vertices"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace batchcol
