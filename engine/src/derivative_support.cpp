#include "derivative_support.hpp"

#include "counter_rng.hpp"
#include "kernels/shape_core.hpp"
#include "kernels/support.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace batchcol::detail {
namespace {

// Swept-sphere part of a shape: the Jacobian of r u / |u| at unit u is r (I - u u^T).
double round_radius(const Shape& s) {
  double r = s.inflation;
  if (s.type == ShapeType::sphere || s.type == ShapeType::capsule) r += s.size.x();
  return r;
}

// The Jacobian of (r u_xy / rho, .) in the xy block: the curvature of a circle of radius r seen along u_xy.
void add_rim(Eigen::Matrix3d& H, double r, const Eigen::Vector3d& u, double rho) {
  const Eigen::Vector2d t(u.x() / rho, u.y() / rho);
  H.topLeftCorner<2, 2>() += (r / rho) * (Eigen::Matrix2d::Identity() - t * t.transpose());
}

// Adds d (made orthogonal to u and to the flats so far) as a flat direction unless it is (relatively) zero.
void add_flat(SupportJacobian& J, const Eigen::Vector3d& u, Eigen::Vector3d d, double length) {
  d -= u.dot(d) * u;
  for (int k = 0; k < J.flats; ++k) d -= J.flat.col(k).dot(d) * J.flat.col(k);
  if (J.flats < 2 && d.norm() > 1e-9 * length) J.flat.col(J.flats++) = d.normalized();
}

// A polytope given by its vertices: the vertices whose dot product is within the tolerance of the best (scaled by
// the vertices' extent, so the test is independent of units) span the flat directions.
template <class Points> void vertex_ties(SupportJacobian& J, const Points& vertices, const Eigen::Vector3d& u,
                                         double radius) {
  double best = -INFINITY;
  Eigen::Vector3d top = Eigen::Vector3d::Zero();
  for (const auto& v : vertices)
    if (v.dot(u) > best) best = v.dot(u), top = v;
  for (const auto& v : vertices)
    if (v.dot(u) >= best - kTieTolerance * radius) add_flat(J, u, v - top, radius);
}

}  // namespace

SupportJacobian support_jacobian(const Shape& s, const Eigen::Vector3d& u) {
  SupportJacobian J;
  const double rho = std::hypot(u.x(), u.y());
  const Eigen::Vector3d ex = Eigen::Vector3d::UnitX(), ey = Eigen::Vector3d::UnitY(), ez = Eigen::Vector3d::UnitZ();
  switch (s.type) {
    case ShapeType::sphere: break;
    case ShapeType::capsule:
      if (std::abs(u.z()) <= kTieTolerance) add_flat(J, u, ez, 1.0);
      break;
    case ShapeType::box:
      J.zero = true;
      for (int k = 0; k < 3; ++k)
        if (std::abs(u(k)) <= kTieTolerance) add_flat(J, u, Eigen::Vector3d::Unit(k), 1.0);
      break;
    case ShapeType::cylinder:
      if (rho <= kTieTolerance) {  // a cap
        add_flat(J, u, ex, 1.0);
        add_flat(J, u, ey, 1.0);
        break;
      }
      add_rim(J.H, s.size.x(), u, rho);
      if (std::abs(u.z()) <= kTieTolerance) add_flat(J, u, ez, 1.0);  // the side line
      break;
    case ShapeType::cone: {
      const double h = s.size.y(), radius = s.size.x();
      const double apex_minus_rim = 2.0 * h * u.z() - radius * rho;  // support value of the apex minus the rim's
      if (rho <= kTieTolerance && u.z() < 0.0) {  // the base
        add_flat(J, u, ex, 1.0);
        add_flat(J, u, ey, 1.0);
        break;
      }
      if (std::abs(apex_minus_rim) <= kTieTolerance * (h + radius)) {  // a generator line, apex to rim
        add_flat(J, u, Eigen::Vector3d(radius * u.x() / rho, radius * u.y() / rho, -2.0 * h), h + radius);
        add_rim(J.H, radius, u, rho);  // the rim end's curvature; the generator's own direction is flat
        J.approximate = true;
      } else if (apex_minus_rim > 0.0) {
        J.zero = true;
      } else {
        add_rim(J.H, radius, u, rho);
      }
      break;
    }
    case ShapeType::ellipsoid: {
      // S(u) = R^2 u / |R u| with R = diag(radii): dS/du = R^2 / |Ru| - (R^2 u)(R^2 u)^T / |Ru|^3.
      const Eigen::Vector3d r2 = s.size.cwiseProduct(s.size);
      const Eigen::Vector3d r2u = r2.cwiseProduct(u);
      const double m = s.size.cwiseProduct(u).norm();
      J.H = Eigen::Matrix3d(r2.asDiagonal()) / m - r2u * r2u.transpose() / (m * m * m);
      break;
    }
    case ShapeType::convex:
      J.zero = true;
      vertex_ties(J, s.hull->vertices, u, s.hull->radius);
      break;
    case ShapeType::triangle:
      J.zero = true;
      vertex_ties(J, s.triangle, u, std::max({s.triangle[0].norm(), s.triangle[1].norm(), s.triangle[2].norm()}));
      break;
    case ShapeType::halfspace: J.unsupported = true; return J;
  }
  const double r = round_radius(s);
  if (r > 0.0) J.H += r * (Eigen::Matrix3d::Identity() - u * u.transpose());
  J.zero = J.zero && r == 0.0 && J.flats == 0;
  return J;
}

Eigen::Vector3d full_support(const Shape& shape, const Eigen::Vector3d& u) {
  const auto core = kernels::make_core<double>(shape);
  kernels::SupportHint hint;
  Eigen::Vector3d p = kernels::support(core, u, hint);
  const double n = u.norm();
  if (core.radius > 0.0 && n > 0.0) p += core.radius * u / n;
  return p;
}

Eigen::Matrix3d smoothed_support_jacobian(const Shape& shape, const Eigen::Vector3d& u, double e, int samples,
                                          std::uint64_t seed, std::uint64_t pair, std::uint64_t stream) {
  const auto core = kernels::make_core<double>(shape);
  kernels::SupportHint hint;
  const auto support = [&](const Eigen::Vector3d& d) {
    Eigen::Vector3d p = kernels::support(core, d, hint);
    const double n = d.norm();
    if (core.radius > 0.0 && n > 0.0) p += core.radius * d / n;
    return p;
  };
  const Eigen::Vector3d s0 = support(u);
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  double z[4];
  for (int j = 0; j < samples; ++j) {
    if (j % 2 == 0) gaussian_vector<4>(seed, pair, static_cast<std::uint64_t>(j / 2), stream, z);
    const double sign = j % 2 == 0 ? 1.0 : -1.0;
    const Eigen::Vector3d zj(sign * z[0], sign * z[1], sign * z[2]);
    sum += (support(u + e * zj) - s0) * zj.transpose();
  }
  Eigen::Matrix3d H = sum / (static_cast<double>(samples) * e);
  H = (0.5 * (H + H.transpose())).eval();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(H);
  const Eigen::Vector3d clamped = eig.eigenvalues().cwiseMax(0.0);
  return eig.eigenvectors() * clamped.asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace batchcol::detail
