// One quaternion-validity rule for the whole library (issue #20): | |q| - 1 | <= kUnitTolerance with the norm summed
// in one fixed order (detail::normalize_unit_quaternion). Quaternions whose norm lies within a few ulps of
// 1 +- kUnitTolerance, where the summation order of the norm decides, must be accepted or refused the same way by
// every kernel family (closed forms scalar and SIMD, box-box, GJK scalar and SIMD in double and float, EPA,
// halfspaces), by is_unit_quaternion / checked_unit_quaternion and by Scene::add.
#include "support/generators.hpp"
#include "validate.hpp"

#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

namespace batchcol {
namespace {

using Quat = std::array<double, 4>;

bool rule(const Quat& q) {
  double c[4] = {q[0], q[1], q[2], q[3]};
  return detail::normalize_unit_quaternion(c);
}

// Rotations scaled to a norm of 1 +- kUnitTolerance (1 +- 4e-10 relative): the target itself is then within ~2 ulps
// of the boundary, and rounding of the four squares decides.
std::vector<Quat> boundary_quaternions(int n, std::uint64_t seed) {
  testing::Rng rng(seed);
  std::vector<Quat> out;
  for (int i = 0; i < n; ++i) {
    const Eigen::Quaterniond q = rng.rotation();
    const double side = i % 2 == 0 ? 1.0 : -1.0;
    const double scale = 1.0 + side * kUnitTolerance * (1.0 + rng.uniform(-4e-10, 4e-10));
    out.push_back({q.w() * scale, q.x() * scale, q.y() * scale, q.z() * scale});
  }
  return out;
}

struct Family {
  std::string name;
  Shape a, b;
  QueryLevel level;
  Precision precision;
  bool closed_forms;
};

std::vector<Family> families() {
  std::vector<Eigen::Vector3d> points;
  testing::Rng rng(5);
  for (int i = 0; i < 12; ++i) points.push_back(0.1 * rng.unit_vector());
  const Shape hull = Shape::convex(points);
  return {
      {"sphere-sphere closed form", Shape::sphere(0.1), Shape::sphere(0.2), QueryLevel::witness, Precision::float64, true},
      {"capsule-capsule closed form", Shape::capsule(0.1, 0.2), Shape::capsule(0.05, 0.1), QueryLevel::witness,
       Precision::float64, true},
      {"sphere-box closed form", Shape::sphere(0.1), Shape::box(0.1, 0.2, 0.3), QueryLevel::witness, Precision::float64,
       true},
      {"box-box boolean closed form", Shape::box(0.1, 0.2, 0.3), Shape::box(0.2, 0.1, 0.1), QueryLevel::boolean,
       Precision::float64, true},
      {"halfspace-box", Shape::halfspace({0, 0, 1}, 0.0), Shape::box(0.1, 0.2, 0.3), QueryLevel::witness,
       Precision::float64, true},
      {"sphere-sphere gjk", Shape::sphere(0.1), Shape::sphere(0.2), QueryLevel::witness, Precision::float64, false},
      {"convex-convex gjk double", hull, hull, QueryLevel::witness, Precision::float64, false},
      {"convex-ellipsoid gjk float", hull, Shape::ellipsoid(0.1, 0.2, 0.15), QueryLevel::witness, Precision::float32,
       false},
      {"cylinder-cone gjk boolean", Shape::cylinder(0.1, 0.2), Shape::cone(0.1, 0.2), QueryLevel::boolean,
       Precision::float64, false},
      {"box-capsule epa", Shape::box(0.1, 0.2, 0.3), Shape::capsule(0.1, 0.2), QueryLevel::penetration,
       Precision::float64, false},
  };
}

std::vector<InstructionSet> available_sets() {
  std::vector<InstructionSet> sets;
  for (InstructionSet isa : {InstructionSet::scalar, InstructionSet::avx2, InstructionSet::avx512}) {
    try {
      resolve_instruction_set(isa);
      sets.push_back(isa);
    } catch (const InputError&) {  // this CPU lacks the set
    }
  }
  return sets;
}

TEST(QuaternionRule, BoundaryCasesOnBothSidesExist) {
  int accepted = 0, refused = 0;
  for (const Quat& q : boundary_quaternions(400, 1)) (rule(q) ? accepted : refused)++;
  // Half are drawn just inside, half just outside, each within ~2 ulps of the boundary: both outcomes occur.
  EXPECT_GT(accepted, 50);
  EXPECT_GT(refused, 50);
}

TEST(QuaternionRule, EveryKernelFamilyAppliesTheSameRule) {
  const std::vector<Quat> quats = boundary_quaternions(64, 2);
  for (const Family& f : families()) {
    ShapeTable shapes;
    const std::uint32_t a = shapes.add(f.a), b = shapes.add(f.b);
    PairBatch batch;
    for (std::size_t i = 0; i < quats.size(); ++i) {
      const Pose near_a{Eigen::Vector3d(0.05 * static_cast<double>(i % 7), 0, 0.5), Eigen::Quaterniond::Identity()};
      batch.add(a, Pose::identity(), b, near_a);
      // Even pairs carry the boundary quaternion on side a, odd pairs on side b.
      QuatArray& r = i % 2 == 0 ? batch.rotation_a : batch.rotation_b;
      r.w[i] = quats[i][0], r.x[i] = quats[i][1], r.y[i] = quats[i][2], r.z[i] = quats[i][3];
    }
    for (InstructionSet isa : available_sets()) {
      QueryOptions o;
      o.level = f.level;
      o.precision = f.precision;
      o.closed_forms = f.closed_forms;
      o.isa = isa;
      o.threads = 1;
      PairResults r;
      collide(shapes, batch, o, r);
      for (std::size_t i = 0; i < quats.size(); ++i) {
        EXPECT_EQ(r.status[i] == Status::invalid_input, !rule(quats[i]))
            << f.name << ", " << to_string(isa) << ", pair " << i << " (quaternion on side " << (i % 2 ? "b" : "a")
            << "): status " << to_string(r.status[i]);
      }
    }
  }
}

TEST(QuaternionRule, PublicChecksAndScenesApplyTheSameRule) {
  auto shapes = std::make_shared<ShapeTable>();
  shapes->add(Shape::sphere(0.1));
  Scene scene(shapes);
  for (const Quat& q : boundary_quaternions(200, 3)) {
    const Eigen::Quaterniond e(q[0], q[1], q[2], q[3]);
    const bool ok = rule(q);
    EXPECT_EQ(is_unit_quaternion(e), ok);
    if (ok) {
      EXPECT_NO_THROW(checked_unit_quaternion(e));
      EXPECT_NO_THROW(scene.add(0, Pose{Eigen::Vector3d::Zero(), e}));
    } else {
      EXPECT_THROW(checked_unit_quaternion(e), InputError);
      EXPECT_THROW(scene.add(0, Pose{Eigen::Vector3d::Zero(), e}), InputError);
    }
  }
}

}  // namespace
}  // namespace batchcol
