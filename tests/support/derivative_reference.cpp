#include "support/derivative_reference.hpp"

#include "kernels/shape_core.hpp"
#include "kernels/support.hpp"
#include "shape_table_access.hpp"  // engine/src: OwnedShapeView, ShapeTableAccess

#include <algorithm>
#include <cmath>

namespace batchcol::testing {
namespace {

Eigen::Vector3d world_support(const Shape& shape, const Pose& pose, const Eigen::Vector3d& u) {
  const OwnedShapeView view(shape);
  const auto core = kernels::make_core<double>(view.view);
  kernels::SupportHint hint;
  const Eigen::Matrix3d R = pose.rotation.toRotationMatrix();
  const Eigen::Vector3d d = R.transpose() * u;
  Eigen::Vector3d p = kernels::support(core, d, hint);
  if (core.radius > 0.0) p += core.radius * d.normalized();
  return R * p + pose.translation;
}

bool strictly_convex(const Shape& s) {
  return s.type == ShapeType::ellipsoid || s.type == ShapeType::sphere;
}

// Newton on f(z) = z + S_a(z) - S_b(-z) from GJK's z, with a forward-difference Jacobian (step 1e-7 |z|: the
// Jacobian's own error only slows convergence, the fixed point is f's).
void polish(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Eigen::Vector3d& xa, Eigen::Vector3d& xb) {
  Eigen::Vector3d z = xb - xa;
  const auto f = [&](const Eigen::Vector3d& v) {
    return Eigen::Vector3d(v + world_support(a, pa, v) - world_support(b, pb, -v));
  };
  for (int it = 0; it < 40; ++it) {
    const Eigen::Vector3d r = f(z);
    if (r.norm() <= 1e-17 * (1.0 + z.norm())) break;
    Eigen::Matrix3d J;
    const double step = 1e-7 * z.norm();
    for (int k = 0; k < 3; ++k) J.col(k) = (f(z + step * Eigen::Vector3d::Unit(k)) - r) / step;
    z -= J.lu().solve(r);
  }
  xa = world_support(a, pa, z);
  xb = world_support(b, pb, -z);
}

// The closest point of a (non-inflated) cylinder or box to a point q, in closed form (local frame: clamp the
// radial distance or each coordinate; a point inside is not handled, the tests' pairs are separated).
bool closest_on_solid(const Shape& s, const Pose& pose, const Eigen::Vector3d& q, Eigen::Vector3d& out) {
  if (s.inflation != 0.0 || (s.type != ShapeType::cylinder && s.type != ShapeType::box)) return false;
  const Eigen::Matrix3d R = pose.rotation.toRotationMatrix();
  Eigen::Vector3d p = R.transpose() * (q - pose.translation);
  if (s.type == ShapeType::box) {
    p = p.cwiseMax(-s.size).cwiseMin(s.size);
  } else {
    const double rho = std::hypot(p.x(), p.y());
    if (rho > s.size.x()) p.head<2>() *= s.size.x() / rho;
    p.z() = std::clamp(p.z(), -s.size.y(), s.size.y());
  }
  out = R * p + pose.translation;
  return true;
}

// Spheres against cylinders and boxes: the closest point to the sphere's centre, then the sphere's witness on the
// segment to it.
bool sphere_against_solid(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Eigen::Vector3d& xa,
                          Eigen::Vector3d& xb) {
  if (a.type == ShapeType::sphere && closest_on_solid(b, pb, pa.translation, xb)) {
    xa = pa.translation + (a.size.x() + a.inflation) * (xb - pa.translation).normalized();
    return true;
  }
  if (b.type == ShapeType::sphere && closest_on_solid(a, pa, pb.translation, xa)) {
    xb = pb.translation + (b.size.x() + b.inflation) * (xa - pb.translation).normalized();
    return true;
  }
  return false;
}

}  // namespace

Pose twisted(const Pose& pose, const Eigen::Matrix<double, 6, 1>& xi, double h) {
  const Eigen::Vector3d w = h * xi.tail<3>();
  const double angle = w.norm();
  const Eigen::Quaterniond q =
      angle > 0 ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, w / angle)) : Eigen::Quaterniond::Identity();
  return {q * pose.translation + h * xi.head<3>(), (q * pose.rotation).normalized()};
}

QueryOptions tight_query() {
  QueryOptions q;
  q.level = QueryLevel::witness;
  q.tolerance = 1e-15;  // raised to the precision floor by collide()
  q.max_iterations = 1000;
  return q;
}

PairResults exact_witness(const ShapeTable& shapes, const PairBatch& batch) {
  PairResults r;
  collide(shapes, batch, tight_query(), r);
  for (std::size_t i = 0; i < batch.size(); ++i) {
    const Shape& a = shapes[batch.shape_a[i]];
    const Shape& b = shapes[batch.shape_b[i]];
    if (r.status[i] != Status::converged) continue;
    Eigen::Vector3d xa = r.witness_a[i], xb = r.witness_b[i];
    if (!sphere_against_solid(a, batch.pose_a(i), b, batch.pose_b(i), xa, xb)) {
      if (!strictly_convex(a) || !strictly_convex(b)) continue;
      polish(a, batch.pose_a(i), b, batch.pose_b(i), xa, xb);
    }
    const double d = (xb - xa).norm();
    r.witness_a.set(i, xa);
    r.witness_b.set(i, xb);
    r.normal.set(i, (xb - xa) / d);
    r.distance[i] = d;
  }
  return r;
}

FiniteDifferences finite_differences(const ShapeTable& shapes, const PairBatch& batch, const std::vector<double>& h) {
  const std::vector<double>& radii = detail::ShapeTableAccess::bounding_radii(shapes);
  const std::size_t n = batch.size();
  PairBatch perturbed;
  for (std::size_t i = 0; i < n; ++i) {
    const double scale = radii[batch.shape_a[i]] + radii[batch.shape_b[i]];
    for (int body = 0; body < 2; ++body)
      for (int k = 0; k < 6; ++k)
        for (int sign = -1; sign <= 1; sign += 2) {
          Eigen::Matrix<double, 6, 1> xi = Eigen::Matrix<double, 6, 1>::Zero();
          xi(k) = k < 3 ? 1.0 : 1.0 / scale;
          Pose pa = batch.pose_a(i), pb = batch.pose_b(i);
          (body == 0 ? pa : pb) = twisted(body == 0 ? pa : pb, xi, sign * h[i]);
          perturbed.add(batch.shape_a[i], pa, batch.shape_b[i], pb);
        }
  }
  const PairResults r = exact_witness(shapes, perturbed);
  FiniteDifferences fd;
  for (auto* v : {&fd.distance_a, &fd.distance_b}) v->resize(n);
  for (auto* m : {&fd.witness_a_a, &fd.witness_a_b, &fd.witness_b_a, &fd.witness_b_b, &fd.normal_a, &fd.normal_b})
    m->resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double scale = radii[batch.shape_a[i]] + radii[batch.shape_b[i]];
    for (int body = 0; body < 2; ++body)
      for (int k = 0; k < 6; ++k) {
        const std::size_t minus = 24 * i + 12 * body + 2 * k, plus = minus + 1;
        const double step = 2.0 * h[i] * (k < 3 ? 1.0 : 1.0 / scale);
        const double dd = (r.distance[plus] - r.distance[minus]) / step;
        const Eigen::Vector3d da = (r.witness_a[plus] - r.witness_a[minus]) / step;
        const Eigen::Vector3d db = (r.witness_b[plus] - r.witness_b[minus]) / step;
        const Eigen::Vector3d dn = (r.normal[plus] - r.normal[minus]) / step;
        (body == 0 ? fd.distance_a : fd.distance_b)[i](k) = dd;
        (body == 0 ? fd.witness_a_a : fd.witness_a_b)[i].col(k) = da;
        (body == 0 ? fd.witness_b_a : fd.witness_b_b)[i].col(k) = db;
        (body == 0 ? fd.normal_a : fd.normal_b)[i].col(k) = dn;
      }
  }
  return fd;
}

PairBatch random_separated_pairs(Rng& rng, ShapeTable& shapes, const std::vector<ShapeType>& types, int count) {
  const std::vector<double>& radii = detail::ShapeTableAccess::bounding_radii(shapes);  // grows with the table
  PairBatch batch;
  while (static_cast<int>(batch.size()) < count) {
    PairBatch trial;
    for (int k = 0; k < count; ++k) {
      const ShapeType ta = types[static_cast<std::size_t>(uniform(rng, 0, types.size())) % types.size()];
      const ShapeType tb = types[static_cast<std::size_t>(uniform(rng, 0, types.size())) % types.size()];
      Shape sa = random_shape(rng, ta, 0.05, 0.4), sb = random_shape(rng, tb, 0.05, 0.4);
      if (uniform(rng, 0, 1) < 0.25) sa = sa.inflated(uniform(rng, 0.01, 0.05));
      const std::uint32_t a = shapes.add(sa), b = shapes.add(sb);
      const double sum = radii[a] + radii[b];
      const Pose pa{random_unit_vector(rng) * uniform(rng, 0.0, 1.0), random_rotation(rng)};
      const Pose pb{pa.translation + random_unit_vector(rng) * sum * uniform(rng, 0.8, 2.0), random_rotation(rng)};
      trial.add(a, pa, b, pb);
    }
    PairResults r;
    collide(shapes, trial, tight_query(), r);
    for (std::size_t i = 0; i < trial.size() && static_cast<int>(batch.size()) < count; ++i) {
      const double sum = radii[trial.shape_a[i]] + radii[trial.shape_b[i]];
      if (r.status[i] == Status::converged && r.distance[i] > 0.02 * sum)
        batch.add(trial.shape_a[i], trial.pose_a(i), trial.shape_b[i], trial.pose_b(i));
    }
  }
  return batch;
}

}  // namespace batchcol::testing
