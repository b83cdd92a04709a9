#include "support/generators.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace batchcol::testing {

double uniform(Rng& rng, double lo, double hi) { return rng.uniform(lo, hi); }

Eigen::Vector3d random_vector(Rng& rng, double scale) {
  // One draw per statement: the evaluation order of constructor arguments is unspecified.
  const double x = rng.uniform(-scale, scale);
  const double y = rng.uniform(-scale, scale);
  const double z = rng.uniform(-scale, scale);
  return {x, y, z};
}

Eigen::Vector3d random_unit_vector(Rng& rng) { return rng.unit_vector(); }

Eigen::Quaterniond random_rotation(Rng& rng) { return rng.rotation(); }

std::vector<ShapeType> bounded_shape_types() {
  return {ShapeType::sphere,    ShapeType::capsule,  ShapeType::box,     ShapeType::cylinder,
          ShapeType::cone,      ShapeType::ellipsoid, ShapeType::convex, ShapeType::triangle};
}

std::vector<Eigen::Vector3d> random_hull_points(Rng& rng, int n, double min_size, double max_size) {
  const Eigen::Vector3d radii(uniform(rng, min_size, max_size), uniform(rng, min_size, max_size),
                              uniform(rng, min_size, max_size));
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < n; ++i) pts.push_back(random_unit_vector(rng).cwiseProduct(radii));
  return pts;
}

Shape random_shape(Rng& rng, ShapeType type, double lo, double hi) {
  const auto u = [&] { return uniform(rng, lo, hi) / 2; };  // sizes are diameters in [lo, hi]
  switch (type) {
    case ShapeType::sphere: return Shape::sphere(u());
    case ShapeType::capsule: return Shape::capsule(u(), u());
    case ShapeType::box: return Shape::box(u(), u(), u());
    case ShapeType::cylinder: return Shape::cylinder(u(), u());
    case ShapeType::cone: return Shape::cone(u(), u());
    case ShapeType::ellipsoid: return Shape::ellipsoid(u(), u(), u());
    case ShapeType::convex: return Shape::convex(random_hull_points(rng, 24, lo / 2, hi / 2));
    case ShapeType::triangle: {
      const double s = u();
      return Shape::triangle_shape(s * random_unit_vector(rng), s * random_unit_vector(rng),
                                   s * random_unit_vector(rng));
    }
    case ShapeType::halfspace: return Shape::halfspace(random_unit_vector(rng), 0.0);
  }
  return Shape::sphere(u());
}

Shape symmetric_shape(Rng& rng, ShapeType type, int seeds) {
  if (type != ShapeType::convex) return random_shape(rng, type);
  std::vector<Eigen::Vector3d> pts;
  for (const auto& p : random_hull_points(rng, seeds, 0.02, 0.2))
    for (int s = 0; s < 8; ++s)
      pts.emplace_back(s & 1 ? -p.x() : p.x(), s & 2 ? -p.y() : p.y(), s & 4 ? -p.z() : p.z());
  return Shape::convex(pts);
}

double extent(const Shape& s, const Eigen::Vector3d& d) {
  const double n = d.norm();
  const double rho = std::hypot(d.x(), d.y());
  double core = 0;
  switch (s.type) {
    case ShapeType::sphere: core = s.size.x() * n; break;
    case ShapeType::capsule: core = s.size.y() * std::abs(d.z()) + s.size.x() * n; break;
    case ShapeType::box: core = s.size.cwiseProduct(d.cwiseAbs()).sum(); break;
    case ShapeType::cylinder: core = s.size.x() * rho + s.size.y() * std::abs(d.z()); break;
    case ShapeType::cone: core = std::max(s.size.y() * d.z(), -s.size.y() * d.z() + s.size.x() * rho); break;
    case ShapeType::ellipsoid: core = s.size.cwiseProduct(d).norm(); break;
    case ShapeType::convex:
      core = -1e300;
      for (const auto& v : s.hull->vertices) core = std::max(core, v.dot(d));
      break;
    case ShapeType::triangle:
      core = std::max({s.triangle[0].dot(d), s.triangle[1].dot(d), s.triangle[2].dot(d)});
      break;
    case ShapeType::halfspace: core = 1e300; break;
  }
  return core + s.inflation * n;
}

SingleResult run_pair(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, const QueryOptions& options) {
  ShapeTable table;
  const auto ia = table.add(a), ib = table.add(b);
  PairBatch batch;
  batch.add(ia, pa, ib, pb);
  PairResults r;
  collide(table, batch, options, r);
  // Arrays the level does not compute are empty: their values read as NaN here.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Eigen::Vector3d none = Eigen::Vector3d::Constant(nan);
  return {r.status[0], r.collide[0] != 0, r.distance.empty() ? nan : r.distance[0],
          r.witness_a.x.empty() ? none : Eigen::Vector3d(r.witness_a[0]),
          r.witness_b.x.empty() ? none : Eigen::Vector3d(r.witness_b[0]),
          r.normal.x.empty() ? none : Eigen::Vector3d(r.normal[0]), r.iterations[0]};
}

}  // namespace batchcol::testing
