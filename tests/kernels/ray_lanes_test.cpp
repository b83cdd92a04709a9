// The lane kernels of the shape form (kernels/rays/ray_lanes.*: spheres, boxes, capsules, hulls): every instruction set gives the scalar build's bits
// for every ray, cast_rays gives the same bits whether a ray ran in a full register or alone (next to invalid
// rays), and the answers agree with the general per-shape kernels (ray_local in the shape's frame), which the
// sphere-tracing tests check against the shape definitions.
#include "shape_table_access.hpp"  // engine/src: hull_view, OwnedShapeView
#include "support/generators.hpp"

#include "batchcol/rays.hpp"
#include "kernels/rays/ray_lanes.hpp"
#include "kernels/rays/ray_shape.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

namespace batchcol {
namespace {

using testing::Rng;
using testing::uniform;
namespace kr = kernels::rays;

struct World {
  ShapeTable table;
  ShapeRayBatch batch;
  std::vector<kr::HullPlanes<double>> planes_d;  // per shape (empty for non-hulls)
  std::vector<kr::HullPlanes<float>> planes_f;
  void prepare() {
    for (std::size_t s = 0; s < table.size(); ++s) {
      const bool hull = table[s].type == ShapeType::convex;
      planes_d.push_back(hull ? kr::make_hull_planes<double>(hull_view(*table[s].hull)) : kr::HullPlanes<double>{});
      planes_f.push_back(hull ? kr::make_hull_planes<float>(hull_view(*table[s].hull)) : kr::HullPlanes<float>{});
    }
  }
};

// Spheres, boxes and capsules (plain and inflated spheres / capsules), posed at random, with rays from all around:
// through the shape, grazing, starting inside, axis-parallel (zero direction components), finite and infinite t_max;
// quaternions off unit by up to 2e-7 (inside the tolerance).
World make_world(Rng& rng, int n) {
  World w;
  for (int k = 0; k < 3; ++k) {
    w.table.add(Shape::sphere(uniform(rng, 0.1, 1.0)));
    w.table.add(Shape::sphere(uniform(rng, 0.1, 1.0)).inflated(0.1));
    w.table.add(Shape::box(uniform(rng, 0.1, 1.0), uniform(rng, 0.1, 1.0), uniform(rng, 0.1, 1.0)));
    w.table.add(Shape::capsule(uniform(rng, 0.1, 0.6), uniform(rng, 0.1, 1.0)));
    w.table.add(Shape::capsule(uniform(rng, 0.1, 0.6), uniform(rng, 0.1, 1.0)).inflated(0.05));
    w.table.add(Shape::convex(testing::random_hull_points(rng, k == 0 ? 12 : 250, 0.3, 1.0)));  // clip / walk
  }
  for (int i = 0; i < n; ++i) {
    // Runs of 8 rays on one shape so that full registers form; the shape changes between runs.
    const std::uint32_t s = static_cast<std::uint32_t>((i / 8) % w.table.size());
    Eigen::Quaterniond q = testing::random_rotation(rng);
    if (i % 3 == 0) q.coeffs() *= 1.0 + uniform(rng, -2e-7, 2e-7);
    if (i % 11 == 0) q = Eigen::Quaterniond::Identity();
    const Pose pose{Eigen::Vector3d(uniform(rng, -3, 3), uniform(rng, -3, 3), uniform(rng, -3, 3)), q};
    const double reach = w.table[s].bounding_radius();
    Eigen::Vector3d o = pose.translation + uniform(rng, 0.0, 3.0 * reach) * testing::random_unit_vector(rng);
    Eigen::Vector3d target = pose.translation + uniform(rng, 0.0, 1.2 * reach) * testing::random_unit_vector(rng);
    Eigen::Vector3d d = (target - o) * uniform(rng, 0.5, 2.0);
    if (i % 7 == 0) d = q * Eigen::Vector3d(d.norm(), 0, 0);   // along a local axis: zero local components
    if (i % 13 == 0) d = Eigen::Vector3d(0, 0, d.z() == 0 ? 1 : d.z());  // zero world components
    if (d.squaredNorm() == 0) d = Eigen::Vector3d::UnitX();
    const double t_max = i % 4 == 0 ? uniform(rng, 0.2, 1.5) : std::numeric_limits<double>::infinity();
    w.batch.add(s, pose, o, d, t_max);
  }
  w.prepare();
  return w;
}

kr::LaneShapeTable lane_table(const World& w) {
  kr::LaneShapeTable t;
  for (std::size_t s = 0; s < w.table.size(); ++s) {
    const Shape& shape = w.table[s];
    const double r = shape.size.x() + shape.inflation;
    t.hull_d.push_back(nullptr), t.hull_f.push_back(nullptr);
    if (shape.type == ShapeType::sphere) {
      t.kind.push_back(kr::LaneKind::sphere), t.a.push_back(r), t.b.push_back(0);
    } else if (shape.type == ShapeType::capsule) {
      t.kind.push_back(kr::LaneKind::capsule), t.a.push_back(r), t.b.push_back(shape.size.y());
    } else if (shape.type == ShapeType::convex) {
      t.kind.push_back(kr::LaneKind::hull), t.a.push_back(shape.bounding_radius()), t.b.push_back(0);
      t.hull_d.back() = &w.planes_d[s], t.hull_f.back() = &w.planes_f[s];
    } else {
      t.kind.push_back(kr::LaneKind::box), t.a.push_back(shape.size.x()), t.b.push_back(shape.size.y());
    }
    t.c.push_back(shape.type == ShapeType::box ? shape.size.z() : 0.0);
  }
  return t;
}

struct Out {
  std::vector<std::uint8_t> status, hit;
  std::vector<double> t, nx, ny, nz;
  explicit Out(std::size_t n) : status(n, 9), hit(n, 9), t(n, -1), nx(n, -1), ny(n, -1), nz(n, -1) {}
  kr::LaneOut view() { return {status.data(), hit.data(), t.data(), nx.data(), ny.data(), nz.data()}; }
};

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

TEST(RayLanes, EveryInstructionSetGivesTheScalarBits) {
  Rng rng(3);
  const World w = make_world(rng, 4096);
  const ShapeRayBatch& b = w.batch;
  const kr::LaneShapeTable table = lane_table(w);
  const kr::LaneRays rays{b.rays.origin.x.data(), b.rays.origin.y.data(), b.rays.origin.z.data(),
                          b.rays.direction.x.data(), b.rays.direction.y.data(), b.rays.direction.z.data(),
                          b.rays.t_max.data(), b.translation.x.data(), b.translation.y.data(),
                          b.translation.z.data(), b.rotation.w.data(), b.rotation.x.data(), b.rotation.y.data(),
                          b.rotation.z.data(), b.shape.data()};
  const std::size_t n = b.size();
  int sets = 0;
  for (bool dbl : {true, false}) {
    SCOPED_TRACE(dbl ? "double" : "float");
    const kr::LaneCasts scalar = kr::lane_casts_for(0);
    Out ref(n);
    kr::LaneOut ref_view = ref.view();
    std::size_t hits = 0;
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_TRUE((dbl ? scalar.cast_double : scalar.cast_float)(table, rays, i, ref_view)) << "ray " << i;
      hits += ref.hit[i];
    }
    EXPECT_GT(hits, n / 4);
    EXPECT_LT(hits, n - n / 8);
    for (int isa = 1; isa <= 2; ++isa) {
      const kr::LaneCasts c = kr::lane_casts_for(isa);
      if (c.width == 0) continue;
      ++sets;
      Out out(n);
      kr::LaneOut view = out.view();
      for (std::size_t i = 0; i + c.width <= n; i += c.width)
        EXPECT_TRUE((dbl ? c.cast_double : c.cast_float)(table, rays, i, view)) << "group at " << i;
      EXPECT_EQ(out.hit, ref.hit) << "isa " << isa;
      EXPECT_EQ(out.status, ref.status) << "isa " << isa;
      EXPECT_TRUE(same_bits(out.t, ref.t)) << "isa " << isa;
      EXPECT_TRUE(same_bits(out.nx, ref.nx) && same_bits(out.ny, ref.ny) && same_bits(out.nz, ref.nz)) << "isa " << isa;
    }
  }
  if (__builtin_cpu_supports("avx2")) {
    EXPECT_GT(sets, 0);
  }
}

TEST(RayLanes, CastRaysIsTheSameAloneOrInARegisterAndMatchesTheGeneralKernels) {
  Rng rng(8);
  const World w = make_world(rng, 3000);
  const ShapeRayBatch& b = w.batch;
  // The same rays with an invalid ray after each one: no register of two or more lanes can form.
  ShapeRayBatch lonely;
  for (std::size_t i = 0; i < b.size(); ++i) {
    const Pose pose{b.translation[i], Eigen::Quaterniond(b.rotation.w[i], b.rotation.x[i], b.rotation.y[i],
                                                         b.rotation.z[i])};
    lonely.add(b.shape[i], pose, b.rays.origin[i], b.rays.direction[i], b.rays.t_max[i]);
    lonely.add(b.shape[i], pose, b.rays.origin[i], Eigen::Vector3d::Zero(), 1.0);
  }
  for (Precision p : {Precision::float64, Precision::float32}) {
    SCOPED_TRACE(to_string(p));
    RayOptions o;
    o.precision = p;
    RayResults full, alone;
    cast_rays(w.table, b, o, full);
    cast_rays(w.table, lonely, o, alone);
    for (std::size_t i = 0; i < b.size(); ++i) {
      ASSERT_EQ(full.status[i], RayStatus::ok);
      ASSERT_EQ(alone.status[2 * i + 1], RayStatus::invalid_input);
      ASSERT_EQ(full.hit[i], alone.hit[2 * i]);
      const double a[4] = {full.t[i], full.normal.x[i], full.normal.y[i], full.normal.z[i]};
      const double c[4] = {alone.t[2 * i], alone.normal.x[2 * i], alone.normal.y[2 * i], alone.normal.z[2 * i]};
      ASSERT_EQ(std::memcmp(a, c, sizeof a), 0) << "ray " << i;
    }
    // Against the general kernels in double (the pose applied in double): hit or miss alike except tangent rays,
    // t within 1e-12 of the scale (double) or 1e-5 (float: the ray and pose rounded to float first).
    const double tol = p == Precision::float64 ? 1e-12 : 1e-5;
    int compared = 0, hits = 0;
    for (std::size_t i = 0; i < b.size(); ++i) {
      const Shape& shape = w.table[b.shape[i]];
      const Eigen::Quaterniond q = Eigen::Quaterniond(b.rotation.w[i], b.rotation.x[i], b.rotation.y[i],
                                                      b.rotation.z[i]).normalized();
      const Eigen::Matrix3d R = q.toRotationMatrix();
      const Eigen::Vector3d ol = R.transpose() * (b.rays.origin[i] - b.translation[i]);
      const Eigen::Vector3d dl = R.transpose() * b.rays.direction[i];
      const OwnedShapeView view(shape);
      const kr::RayShape<double> rs = kr::make_ray_shape<double>(view.view, &w.planes_d[b.shape[i]]);
      const kr::LocalHit<double> h = kr::ray_local(rs, ol, dl, b.rays.t_max[i], kr::RayGjkSettings{1e-9, 64});
      const double scale = 1.0 + (b.rays.origin[i] - b.translation[i]).norm() / b.rays.direction[i].norm();
      if (h.hit != bool(full.hit[i])) {
        // Only a tangent ray or one ending at the surface (t = t_max within the tolerance) may disagree.
        const double t_any = h.hit ? h.t : full.t[i];
        const Eigen::Vector3d n = h.hit ? Eigen::Vector3d(R * h.normal) : full.normal[i];
        ASSERT_TRUE(std::isfinite(t_any)) << "ray " << i;
        ASSERT_NEAR(n.norm(), 1.0, 1e-5) << "ray " << i;
        const bool tangent = std::abs(n.dot(b.rays.direction[i].normalized())) < 1e-3;
        EXPECT_TRUE(tangent || std::abs(t_any - b.rays.t_max[i]) <= tol * scale) << "ray " << i;
        continue;
      }
      ++compared;
      if (!h.hit) continue;
      ++hits;
      EXPECT_NEAR(full.t[i], h.t, tol * scale) << "ray " << i;
      const Eigen::Vector3d n = R * h.normal;
      // Box and hull edges and corners have a cone of normals (the kernels may pick different faces at a tie):
      // not compared.
      if (shape.type != ShapeType::box && shape.type != ShapeType::convex) {
        EXPECT_LT((full.normal[i] - n).norm(), 1e3 * tol) << "ray " << i;
      }
      EXPECT_NEAR(full.normal[i].norm(), 1.0, 10 * tol);
    }
    EXPECT_GT(compared, 2900);
    EXPECT_GT(hits, 800);
  }
}

}  // namespace
}  // namespace batchcol
