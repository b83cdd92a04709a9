// Extreme scales (issue #16, items 7, 8, 9): sizes and pose translations from 1e-300 to 1e300 in both precisions.
// Every input is either refused with a clear error (InputError from a shape factory, Status::invalid_input for a
// pose) or answered like the same problem at scale 1, scaled: the answers are scale-invariant in exact arithmetic,
// so the result at scale s divided by s must match the one at scale 1 (to the relative tolerance asked for plus
// the precision floor). Never a wrong `collide`.
#include <batchcol/batchcol.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace batchcol {
namespace {

struct Answer {
  bool rejected = false;  // InputError or Status::invalid_input
  Status status = Status::invalid_input;
  bool collide = false;
  double distance = 0.0;
  std::string note;
};

std::optional<Shape> make_shape(const std::function<Shape()>& make, std::string& note) {
  try {
    return make();
  } catch (const InputError& e) {
    note = e.what();
    return std::nullopt;
  }
}

QueryOptions options(Precision p) {
  QueryOptions o;
  o.level = QueryLevel::penetration;
  o.precision = p;
  o.tolerance = 0.0;  // scale-invariant: relative tolerance only
  o.relative_tolerance = 1e-10;
  return o;
}

Answer solve(const std::function<Shape(double)>& make_a, const std::function<Shape(double)>& make_b, double s,
             const Eigen::Vector3d& offset, double translation_scale, Precision p) {
  Answer r;
  const auto a = make_shape([&] { return make_a(s); }, r.note);
  const auto b = make_shape([&] { return make_b(s); }, r.note);
  if (!a || !b) {
    r.rejected = true;
    return r;
  }
  ShapeTable table;
  try {
    table.add(*a);
    table.add(*b);
  } catch (const InputError& e) {
    r.rejected = true;
    r.note = e.what();
    return r;
  }
  PairBatch batch;
  const Eigen::Quaterniond rb(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()));
  batch.add(0, Pose::identity(), 1, Pose{offset * translation_scale, rb});
  PairResults out;
  try {
    collide(table, batch, options(p), out);
  } catch (const InputError& e) {
    r.rejected = true;
    r.note = e.what();
    return r;
  }
  r.status = out.status[0];
  r.rejected = r.status == Status::invalid_input;
  r.collide = out.collide[0] != 0;
  r.distance = out.distance[0];
  return r;
}

struct NamedShape {
  const char* name;
  std::function<Shape(double)> make;
};

std::vector<NamedShape> shapes() {
  return {
      {"sphere", [](double s) { return Shape::sphere(s); }},
      {"box", [](double s) { return Shape::box(s, 0.8 * s, 0.6 * s); }},
      {"ellipsoid", [](double s) { return Shape::ellipsoid(s, 0.7 * s, 0.5 * s); }},
      {"cylinder", [](double s) { return Shape::cylinder(0.6 * s, s); }},
      {"cone", [](double s) { return Shape::cone(0.8 * s, s); }},
      {"capsule", [](double s) { return Shape::capsule(0.5 * s, 0.5 * s); }},
      {"convex", [](double s) {
         return Shape::convex(std::vector<Eigen::Vector3d>{{s, 0, 0}, {-s, 0.1 * s, 0}, {0, s, 0.2 * s}, {0, -0.3 * s, s},
                                                           {0.2 * s, 0.1 * s, -s}});
       }},
  };
}

std::string scale_name(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.0e", s);
  return text;
}

// Relative error allowed at any accepted scale: the relative tolerance (1e-10) and the precision floor
// (16 eps x the problem size, ~5 sizes here), with a factor 100 of room (the hard-case tests measure the
// accuracy itself; this test is about over/underflow, which is off by orders of magnitude).
double relative_bound(Precision p) { return p == Precision::float64 ? 1e-8 : 1e-3; }

TEST(ScaleLimits, SizesFrom1em300To1e300AreRefusedOrAnsweredAsAtScale1) {
  const std::vector<Eigen::Vector3d> offsets = {{2.5, 0.3, 0.2}, {0.5, 0.1, 0.0}, {0.0, 0.0, 0.0}};
  int accepted = 0, refused = 0;
  for (Precision p : {Precision::float64, Precision::float32})
    for (const auto& A : shapes())
      for (const auto& B : shapes())
        for (const Eigen::Vector3d& offset : offsets) {
          const Answer unit = solve(A.make, B.make, 1.0, offset, 1.0, p);
          ASSERT_FALSE(unit.rejected) << unit.note;
          for (int e = -300; e <= 300; e += 10) {
            const double s = std::pow(10.0, e);
            const Answer r = solve(A.make, B.make, s, offset, s, p);
            SCOPED_TRACE(std::string(A.name) + "-" + B.name + " scale " + scale_name(s) + " offset " +
                         std::to_string(offset.x()) + (p == Precision::float64 ? " double" : " float"));
            if (r.rejected) {
              ++refused;
              continue;
            }
            ++accepted;
            EXPECT_EQ(r.collide, unit.collide) << "distance " << r.distance << " at scale 1: " << unit.distance;
            // A converged answer must be right. Where either run ends short of convergence (EPA on a sphere or
            // capsule centred inside a cone or cylinder, item 10; float EPA calling a flat polytope degenerate:
            // rounding differs at every scale that is not a power of 2) only `collide` is comparable.
            if (unit.status != Status::converged || r.status != Status::converged) continue;
            if (std::isfinite(unit.distance)) {
              EXPECT_NEAR(r.distance / s, unit.distance, relative_bound(p) * (1.0 + std::abs(unit.distance)))
                  << "distance " << r.distance;
            }
          }
        }
  std::printf("[measured] %d configurations answered, %d refused\n", accepted, refused);
}

TEST(ScaleLimits, FarApartPosesAreRefusedOrAnsweredCorrectly) {
  for (Precision p : {Precision::float64, Precision::float32})
    for (const auto& A : shapes())
      for (int e = 1; e <= 300; e += e < 10 ? 9 : 10) {
        const double t = std::pow(10.0, e);
        const Answer r = solve(A.make, A.make, 1.0, Eigen::Vector3d(0.6, 0.8, 0.0), t, p);
        SCOPED_TRACE(std::string(A.name) + " at " + scale_name(t) + (p == Precision::float64 ? " double" : " float"));
        if (r.rejected) continue;
        // Two unit-size shapes (bounding radii below 2) |t| apart: the distance is within 4 of |t|.
        EXPECT_FALSE(r.collide);
        EXPECT_EQ(r.status, Status::converged);
        EXPECT_NEAR(r.distance, t, 4.0 + relative_bound(p) * t);
      }
}

// The float path refuses a pair whose translations are more than kMaxLengthFloat apart, whatever its place in the
// batch: the check runs two pairs per register with a scalar tail, so the far pair is put at every index of batches
// of odd and even sizes (a one-pair batch only reaches the tail).
TEST(ScaleLimits, FloatRefusesEachFarPairWhereverItIsInTheBatch) {
  ShapeTable table;
  table.add(Shape::sphere(1.0));
  table.add(Shape::box(Eigen::Vector3d(1, 1, 1)));
  for (std::size_t n : {2, 3, 5, 8}) {
    for (std::size_t far = 0; far < n; ++far) {
      PairBatch batch;
      for (std::size_t i = 0; i < n; ++i) {
        const double x = i == far ? 2.0 * kMaxLengthFloat : 5.0 + double(i);
        batch.add(0, Pose::identity(), 1, Pose{Eigen::Vector3d(x, 0, 0), Eigen::Quaterniond::Identity()});
      }
      PairResults out;
      collide(table, batch, options(Precision::float32), out);
      for (std::size_t i = 0; i < n; ++i) {
        SCOPED_TRACE("batch of " + std::to_string(n) + ", far pair " + std::to_string(far) + ", pair " +
                     std::to_string(i));
        if (i == far) {
          EXPECT_EQ(out.status[i], Status::invalid_input);
        } else {
          EXPECT_EQ(out.status[i], Status::converged);
          EXPECT_NEAR(out.distance[i], 5.0 + double(i) - 2.0, 1e-5);
        }
      }
    }
  }
}

TEST(ScaleLimits, HalfspaceNormalsOfAnyMagnitudeGiveTheUnitNormal) {
  for (int e = -300; e <= 300; e += 10) {
    const double k = std::pow(10.0, e);
    SCOPED_TRACE(scale_name(k));
    std::string note;
    // The solid is {x : n.x <= offset}: scaling n and offset together changes nothing.
    const auto h = make_shape([&] { return Shape::halfspace(Eigen::Vector3d(3 * k, 4 * k, 0), 5 * k); }, note);
    if (!h) continue;
    EXPECT_NEAR(h->size.norm(), 1.0, 1e-15);
    EXPECT_NEAR(h->size.x(), 0.6, 1e-15);
    EXPECT_NEAR(h->offset, 1.0, 1e-15);
  }
  // A sphere 3 m outside a halfspace given with a 1e200 normal: distance 3, no collision.
  ShapeTable table;
  table.add(Shape::halfspace(Eigen::Vector3d(1e200, 0, 0), 0.0));
  table.add(Shape::sphere(1.0));
  PairBatch batch;
  batch.add(0, Pose::identity(), 1, Pose{Eigen::Vector3d(4, 0, 0), Eigen::Quaterniond::Identity()});
  PairResults out;
  collide(table, batch, options(Precision::float64), out);
  EXPECT_EQ(out.collide[0], 0);
  EXPECT_NEAR(out.distance[0], 3.0, 1e-12);
}

}  // namespace
}  // namespace batchcol
