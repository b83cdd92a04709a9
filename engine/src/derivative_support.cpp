#include "derivative_support.hpp"

#include "counter_rng.hpp"
#include "kernels/shape_core.hpp"
#include "kernels/simd/wide_gjk.hpp"
#include "kernels/support.hpp"
#include "shape_table_access.hpp"

#include <immintrin.h>  // SSE2: the x86-64 baseline this file is compiled for; AVX2 under its target pragma

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

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
  if (J.flats < 2 && d.norm() > 1e-6 * length) J.flat.col(J.flats++) = d.normalized();
}

// A hull: the witness lies on the planes of the faces containing it (to kExactFeature): one plane, a face (two
// flats); two, an edge (one flat, along both normals' cross product); three or more, a vertex.
void hull_feature(SupportJacobian& J, const ConvexHull& hull, const Eigen::Vector3d& u, const Eigen::Vector3d& p,
                  double tolerance) {
  Eigen::Vector3d planes[3];
  int count = 0;
  for (std::size_t f = 0; f < hull.faces.size() && count < 3; ++f) {
    const Eigen::Vector3d& n = hull.face_normals[f];
    if (n.dot(p - hull.vertices[hull.faces[f][0]]) < -tolerance) continue;
    bool seen = false;  // triangulated faces repeat their plane
    for (int k = 0; k < count; ++k) seen = seen || planes[k].dot(n) > 1.0 - 1e-9;
    if (!seen) planes[count++] = n;
  }
  if (count == 1) {
    const Eigen::Vector3d t = planes[0].unitOrthogonal();
    add_flat(J, u, t, 1.0);
    add_flat(J, u, planes[0].cross(t), 1.0);
  } else if (count == 2) {
    add_flat(J, u, planes[0].cross(planes[1]), 1.0);
  }
}

// A triangle: the witness's barycentric coordinates; the vertices with a positive weight span its feature.
void triangle_feature(SupportJacobian& J, const std::array<Eigen::Vector3d, 3>& v, const Eigen::Vector3d& u,
                      const Eigen::Vector3d& p) {
  const Eigen::Vector3d e1 = v[1] - v[0], e2 = v[2] - v[0], q = p - v[0];
  Eigen::Matrix2d G;
  G << e1.dot(e1), e1.dot(e2), e1.dot(e2), e2.dot(e2);
  const Eigen::Vector2d l = G.inverse() * Eigen::Vector2d(e1.dot(q), e2.dot(q));
  const double weights[3] = {1.0 - l.x() - l.y(), l.x(), l.y()};
  const Eigen::Vector3d* first = nullptr;
  for (int k = 0; k < 3; ++k) {
    if (!(weights[k] > kExactFeature)) continue;
    if (!first) first = &v[k];
    else add_flat(J, u, v[k] - *first, std::sqrt(G.trace()));
  }
}

/// Zeroes a_pq of a symmetric 3x3 by a Jacobi rotation in the (p, q) plane; r is the third index (a_rp, a_rq the
/// entries it mixes). The smaller root t = tan(angle) of t^2 + 2 theta t - 1 = 0 (|angle| <= pi/4), overflow-safe
/// for large theta.
inline void jacobi_rotate(double& app, double& aqq, double& apq, double& arp, double& arq) {
  if (apq == 0.0) return;
  const double theta = (aqq - app) / (2.0 * apq), at = std::abs(theta);
  const double t = std::copysign(at > 1e150 ? 0.5 / at : 1.0 / (at + std::sqrt(at * at + 1.0)), theta);
  const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
  app -= t * apq;
  aqq += t * apq;
  apq = 0.0;
  const double rp = arp, rq = arq;
  arp = c * rp - s * rq;
  arq = s * rp + c * rq;
}

/// The eigenvalues of symmetric A by cyclic Jacobi rotations (no eigenvectors: psd_projection() needs only the
/// values), until the off-diagonal entries are below 1e-18 of the diagonal's (the eigenvalues then to rounding;
/// 3x3 converges quadratically: ~3 sweeps). Only + - * / and sqrt, so the bits are the same on every machine and
/// instruction set (libm's acos / cos of the closed-form cubic may differ by ISA variant).
Eigen::Vector3d symmetric_eigenvalues(const Eigen::Matrix3d& A) {
  double a00 = A(0, 0), a11 = A(1, 1), a22 = A(2, 2), a01 = A(0, 1), a02 = A(0, 2), a12 = A(1, 2);
  for (int sweep = 0; sweep < 32; ++sweep) {
    const double off = std::max(std::max(std::abs(a01), std::abs(a02)), std::abs(a12));
    const double diagonal = std::max(std::max(std::abs(a00), std::abs(a11)), std::abs(a22));
    if (!(off > 1e-18 * diagonal)) break;
    jacobi_rotate(a00, a11, a01, a02, a12);  // (p, q, r) = (0, 1, 2)
    jacobi_rotate(a00, a22, a02, a01, a12);  // (0, 2, 1)
    jacobi_rotate(a11, a22, a12, a01, a02);  // (1, 2, 0)
  }
  return {a00, a11, a22};
}

// Two doubles in an SSE2 register: project() computes columns 0 and 1 of each row together.
using V2 = double __attribute__((vector_size(16)));

}  // namespace

namespace {

/// False when psd_projection(H) is H without eigenvalues: positive definite by Sylvester's criterion (the leading
/// minors), the common case on curved shapes at larger M, or not finite (NaN in, NaN out, as the
/// eigendecomposition did; no rotations on NaN). Each minor must clear 1e-12 of the sum of its terms' magnitudes,
/// far above their rounding (~4e-16 of it): a nearly singular H whose computed minors are positive by rounding
/// alone (an eigenvalue of -1e-12 |H| passed) takes the eigenvalues instead.
bool needs_eigenvalues(const Eigen::Matrix3d& H) {
  const double a00 = H(0, 0), a11 = H(1, 1), a22 = H(2, 2), a01 = H(0, 1), a02 = H(0, 2), a12 = H(1, 2);
  const double m2 = a00 * a11 - a01 * a01, m2_size = std::abs(a00 * a11) + a01 * a01;
  const double c0 = a11 * a22 - a12 * a12, c1 = a01 * a22 - a12 * a02, c2 = a01 * a12 - a11 * a02;
  const double det = a00 * c0 - a01 * c1 + a02 * c2;
  const double det_size = std::abs(a00) * (std::abs(a11 * a22) + a12 * a12) +
                          std::abs(a01) * (std::abs(a01 * a22) + std::abs(a12 * a02)) +
                          std::abs(a02) * (std::abs(a01 * a12) + std::abs(a11 * a02));
  if (a00 > 0.0 && m2 > 1e-12 * m2_size && det > 1e-12 * det_size) return false;
  return H.allFinite();
}

/// The projection of H given its eigenvalues l (any order).
Eigen::Matrix3d project(const Eigen::Matrix3d& H, Eigen::Vector3d l) {
  // l0 >= l1 >= l2
  if (l[1] > l[0]) std::swap(l[0], l[1]);
  if (l[2] > l[1]) std::swap(l[1], l[2]);
  if (l[1] > l[0]) std::swap(l[0], l[1]);
  if (l[2] >= 0.0) return H;
  if (l[0] <= 0.0) return Eigen::Matrix3d::Zero();
  // With eigenvalues l_i and spectral projectors Q_i, Q_i = prod_{j != i} (H - l_j) / (l_i - l_j). One negative
  // value: H - l2 Q2; two: l0 Q0. Both denominators are at least |the negative value| and the positive one, so an
  // eigenvalue's rounding moves the result by about that rounding (no eigenvector, which would be ill-conditioned
  // for close eigenvalues).
  // Plain loops in the operation order of the Eigen expressions they replaced (Q = (H - x I) (H - y I) / den,
  // P = H - l2 Q or l0 Q, 0.5 (P + P^T); Eigen sums row 2 of the 3x3 product, after its 2-row packet, as
  // a0 + (a1 + a2); found by a bitwise comparison against Eigen on 200000 random matrices): the same bits without
  // Eigen's temporaries (~250 instructions a matrix, callgrind).
  const bool one = l[1] >= 0.0;
  const double x = one ? l[0] : l[1], y = one ? l[1] : l[2];
  const double den = one ? (l[2] - l[0]) * (l[2] - l[1]) : (l[0] - l[1]) * (l[0] - l[2]);
  // Columns 0 and 1 in an SSE2 register, column 2 scalar (the same operations per entry).
  double A[3][3], B01[3][2], B2[3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double d = i == j ? 1.0 : 0.0;  // x I's entries are x * 1 and x * 0 (a signed zero)
      A[i][j] = H(i, j) - x * d;
      if (j < 2) B01[i][j] = H(i, j) - y * d;
      else B2[i] = H(i, j) - y * d;
    }
  const V2 b[3] = {{B01[0][0], B01[0][1]}, {B01[1][0], B01[1][1]}, {B01[2][0], B01[2][1]}};
  const V2 vden = V2{} + den, l2 = V2{} + l[2], l0 = V2{} + l[0];
  double P[3][3];
  for (int i = 0; i < 3; ++i) {
    const V2 p0 = A[i][0] * b[0], p1 = A[i][1] * b[1], p2 = A[i][2] * b[2];
    const V2 q = (i < 2 ? (p0 + p1) + p2 : p0 + (p1 + p2)) / vden;
    const V2 h = {H(i, 0), H(i, 1)};
    const V2 p = one ? h - l2 * q : l0 * q;
    const double s0 = A[i][0] * B2[0], s1 = A[i][1] * B2[1], s2 = A[i][2] * B2[2];
    const double q2 = (i < 2 ? (s0 + s1) + s2 : s0 + (s1 + s2)) / den;
    P[i][0] = p[0], P[i][1] = p[1], P[i][2] = one ? H(i, 2) - l[2] * q2 : l[0] * q2;
  }
  Eigen::Matrix3d S;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) S(i, j) = 0.5 * (P[i][j] + P[j][i]);
  return S;
}

}  // namespace

Eigen::Matrix3d psd_projection(const Eigen::Matrix3d& H) {
  return needs_eigenvalues(H) ? project(H, symmetric_eigenvalues(H)) : H;
}

SupportJacobian support_jacobian(const Shape& s, const Eigen::Vector3d& u, const Eigen::Vector3d& witness) {
  SupportJacobian J;
  const double r = round_radius(s);
  const Eigen::Vector3d p = witness - r * u;  // the witness on the core
  // Computed only for the types that test features (spheres and ellipsoids, the smooth common case, skip them).
  const bool features = s.type != ShapeType::sphere && s.type != ShapeType::ellipsoid;
  const double radius_b = features ? s.bounding_radius() : 0.0;
  const double tol = kExactFeature * radius_b, curved_tol = kCurvedFeature * radius_b;
  // Only the solids of revolution look at the radial coordinates (hypot is ~100 instructions per call).
  const bool round = s.type == ShapeType::cylinder || s.type == ShapeType::cone;
  const double rho = round ? std::hypot(u.x(), u.y()) : 0.0, rho_p = round ? std::hypot(p.x(), p.y()) : 0.0;
  const Eigen::Vector3d ex = Eigen::Vector3d::UnitX(), ey = Eigen::Vector3d::UnitY(), ez = Eigen::Vector3d::UnitZ();
  switch (s.type) {
    case ShapeType::sphere: break;
    case ShapeType::capsule:
      if (std::abs(p.z()) < s.size.y() - tol) add_flat(J, u, ez, 1.0);  // inside the segment
      break;
    case ShapeType::box:
      J.zero = true;
      for (int k = 0; k < 3; ++k)
        if (std::abs(p(k)) < s.size(k) - tol) add_flat(J, u, Eigen::Vector3d::Unit(k), 1.0);
      break;
    case ShapeType::cylinder:
      if (rho_p < s.size.x() - curved_tol) {  // inside a cap
        add_flat(J, u, ex, 1.0);
        add_flat(J, u, ey, 1.0);
        break;
      }
      if (rho > 0.0) add_rim(J.H, s.size.x(), u, rho);
      if (std::abs(p.z()) < s.size.y() - tol) add_flat(J, u, ez, 1.0);  // on the side line
      break;
    case ShapeType::cone: {
      const double h = s.size.y(), radius = s.size.x();
      if (p.z() < -h + tol && rho_p < radius - curved_tol) {  // inside the base
        add_flat(J, u, ex, 1.0);
        add_flat(J, u, ey, 1.0);
      } else if ((p - h * ez).norm() <= tol) {  // the apex
        J.zero = true;
      } else if (rho > 0.0) {
        if (rho_p < radius - curved_tol) {  // on a generator line, between apex and rim
          // The side's normals form one circle of directions; turning u about the axis by dphi (|du| = rho dphi)
          // turns the generator with it, and the witness, at radius rho_p from the axis, moves by rho_p dphi: the
          // curvature term of a circle of radius rho_p (the rim's at the rim, none at the apex); along the
          // generator the support map jumps (the flat). Measured against witness points solved exactly on the side
          // (derivatives_exact_features_test.cpp): 0.58 relative error with the rim's radius, ~1e-6 with this.
          add_rim(J.H, rho_p, u, rho);
          add_flat(J, u, Eigen::Vector3d(radius * u.x() / rho, radius * u.y() / rho, -2.0 * h), h + radius);
        } else {
          add_rim(J.H, radius, u, rho);
        }
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
      hull_feature(J, *s.hull, u, p, tol);
      break;
    case ShapeType::triangle:
      J.zero = true;
      triangle_feature(J, s.triangle, u, p);
      break;
    case ShapeType::halfspace: J.unsupported = true; return J;
  }
  if (r > 0.0) J.H += r * (Eigen::Matrix3d::Identity() - u * u.transpose());
  J.zero = J.zero && r == 0.0 && J.flats == 0;
  return J;
}

namespace {
// The feature of the exposed vertices `mask` (bits in index order, as exposed_feature()'s scans visit them): one
// vertex, or two (an edge: second - first), need no test; from the third on, a vertex off the line of the first two
// makes a face (exposed_feature()'s collinearity test, the same expression). On distant convex8 pairs 72% of the
// sides expose one vertex, 26% two and 2% more (callgrind's branch counts), so the one- and two-bit cases skip the
// walk's per-bit bookkeeping.
inline __attribute__((always_inline)) int feature_of_mask(const double* vertices, std::uint32_t mask,
                                                          Eigen::Vector3d& edge) {
  const auto vertex = [&](std::size_t k) {
    return Eigen::Vector3d(vertices[3 * k], vertices[3 * k + 1], vertices[3 * k + 2]);
  };
  if ((mask & (mask - 1)) == 0) return 0;  // none (all heights NaN) or one vertex
  const std::size_t first = std::size_t(__builtin_ctz(mask));
  mask &= mask - 1;
  const std::size_t second = std::size_t(__builtin_ctz(mask));
  mask &= mask - 1;
  for (; mask != 0; mask &= mask - 1) {
    const std::size_t k = std::size_t(__builtin_ctz(mask));
    const Eigen::Vector3d e1 = vertex(second) - vertex(first), e2 = vertex(k) - vertex(first);
    if (e1.cross(e2).squaredNorm() > 1e-12 * e1.squaredNorm() * e2.squaredNorm()) return 2;
  }
  edge = vertex(second) - vertex(first);
  return 1;
}
}  // namespace

#pragma GCC push_options
#pragma GCC target("avx2")
namespace {
// exposed_feature()'s height pass and mask for a hull of 4..16 vertices, four vertices per AVX2 register: each
// lane computes (x ux + y uy) + z uz, the scalar expression's operations in its order (no FMA: only AVX2 is
// enabled here), so every height, the maximum and the mask have the SSE2 pass's bits. The coordinates of four
// vertices (x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3) become x, y, z rows with three 128-bit loads, three
// 128-bit inserts and three shuffles. Returns the bit mask of the vertices whose height is >= max - tolerance
// (ordered compares: a NaN height is never exposed nor the maximum). Why: the SSE2 pass was two thirds of
// exposed_feature(), 330 instructions per analytic hull pair for both sides (callgrind, AVX2); with this 197.
inline __attribute__((always_inline)) std::uint32_t exposed_mask_avx2_body(const double* vertices, std::size_t count,
                                                                           const Eigen::Vector3d& u,
                                                                           double tolerance) {
  const __m256d ux = _mm256_set1_pd(u.x()), uy = _mm256_set1_pd(u.y()), uz = _mm256_set1_pd(u.z());
  const auto heights = [&](const double* p) {
    const __m256d xy = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p)), _mm_loadu_pd(p + 6), 1);
    const __m256d zx = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p + 2)), _mm_loadu_pd(p + 8), 1);
    const __m256d yz = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(p + 4)), _mm_loadu_pd(p + 10), 1);
    const __m256d x = _mm256_shuffle_pd(xy, zx, 0b1010), y = _mm256_shuffle_pd(xy, yz, 0b0101),
                  z = _mm256_shuffle_pd(zx, yz, 0b1010);
    return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(x, ux), _mm256_mul_pd(y, uy)), _mm256_mul_pd(z, uz));
  };
  // The largest of a register's lanes (NaN lanes never taken; -inf when all are NaN).
  const auto largest = [](__m256d top) {
    const __m128d half = _mm256_extractf128_pd(top, 1), low = _mm256_castpd256_pd128(top);
    const __m128d top2 = _mm_blendv_pd(low, half, _mm_cmpgt_pd(half, low));
    return std::max(_mm_cvtsd_f64(top2), _mm_cvtsd_f64(_mm_unpackhi_pd(top2, top2)));
  };
  const __m256d none = _mm256_set1_pd(-std::numeric_limits<double>::infinity());
  if (count == 8) {  // the common 8-vertex hull: two registers, no loop
    const __m256d h0 = heights(vertices), h1 = heights(vertices + 12);
    __m256d top = _mm256_blendv_pd(none, h0, _mm256_cmp_pd(h0, none, _CMP_GT_OQ));
    top = _mm256_blendv_pd(top, h1, _mm256_cmp_pd(h1, top, _CMP_GT_OQ));
    const __m256d f = _mm256_set1_pd(largest(top) - tolerance);
    return std::uint32_t(_mm256_movemask_pd(_mm256_cmp_pd(h0, f, _CMP_GE_OQ))) |
           std::uint32_t(_mm256_movemask_pd(_mm256_cmp_pd(h1, f, _CMP_GE_OQ))) << 4;
  }
  __m256d kept[4];
  __m256d top = none;
  const std::size_t groups = count / 4;
  for (std::size_t g = 0; g < groups; ++g) {
    const __m256d h = heights(vertices + 12 * g);
    kept[g] = h;
    top = _mm256_blendv_pd(top, h, _mm256_cmp_pd(h, top, _CMP_GT_OQ));
  }
  // The maximum of the lanes (any order gives the same value: NaN never enters top, and +0 / -0 give the same
  // floor), then the vertices past the last whole group as the scalar pass computes them.
  double tail[3];
  double h = largest(top);
  for (std::size_t k = 4 * groups; k < count; ++k) {
    const double* p = vertices + 3 * k;
    const double d = u.x() * p[0] + u.y() * p[1] + u.z() * p[2];
    tail[k - 4 * groups] = d;
    h = std::max(h, d);
  }
  const double floor = h - tolerance;
  const __m256d f = _mm256_set1_pd(floor);
  std::uint32_t mask = 0;
  for (std::size_t g = 0; g < groups; ++g)
    mask |= std::uint32_t(_mm256_movemask_pd(_mm256_cmp_pd(kept[g], f, _CMP_GE_OQ))) << (4 * g);
  for (std::size_t k = 4 * groups; k < count; ++k)
    if (tail[k - 4 * groups] >= floor) mask |= std::uint32_t{1} << k;
  return mask;
}
__attribute__((noinline)) std::uint32_t exposed_mask_avx2(const double* vertices, std::size_t count,
                                                          const Eigen::Vector3d& u, double tolerance) {
  return exposed_mask_avx2_body(vertices, count, u, tolerance);
}
}  // namespace
namespace {
// hull_pair_flats_avx2()'s steps after the directions.
inline __attribute__((always_inline)) void hull_pair_features(const Eigen::Quaterniond* unit, const Eigen::Vector3d* u,
                                                              const Eigen::Vector3d& n, const HullView& a,
                                                              const HullView& b, const double* tolerance, int* flats,
                                                              Eigen::Vector3d* flat) {
  Eigen::Vector3d edge[2];
  const std::uint32_t mask_a = exposed_mask_avx2_body(a.vertices, a.vertex_count, u[0], tolerance[0]);
  const std::uint32_t mask_b = exposed_mask_avx2_body(b.vertices, b.vertex_count, u[1], tolerance[1]);
  flats[0] = feature_of_mask(a.vertices, mask_a, edge[0]);
  flats[1] = feature_of_mask(b.vertices, mask_b, edge[1]);
  for (int s = 0; s < 2; ++s)
    if (flats[s] == 1 && !edge_flat(unit[s], edge[s], n, flat[s])) flats[s] = 0;
}
}  // namespace

// hull_pair_directions(), feature_of_mask() and edge_flat() are inlined here (baseline code into an AVX2 function,
// no FMA enabled), so their SSE2 operations take the VEX three-operand forms with the bits of the baseline code.
void hull_pair_flats_avx2(const QuatArray& ra, const QuatArray& rb, std::size_t i, const Eigen::Vector3d& n,
                          const HullView& a, const HullView& b, const double* tolerance, int* flats,
                          Eigen::Vector3d* flat) {
  Eigen::Quaterniond unit[2];
  Eigen::Vector3d u[2];
  hull_pair_directions(Lanes2{ra.x[i], rb.x[i]}, Lanes2{ra.y[i], rb.y[i]}, Lanes2{ra.z[i], rb.z[i]},
                       Lanes2{ra.w[i], rb.w[i]}, n, unit[0], unit[1], u[0], u[1]);
  hull_pair_features(unit, u, n, a, b, tolerance, flats, flat);
}

int hull_pair_flats_given_avx2(const HullDirections& d, std::size_t j, const Eigen::Vector3d& n, const HullView& a,
                               const HullView& b, const double* tolerance, Eigen::Vector3d* flat) {
  int flats[2];
  Eigen::Quaterniond unit[2];
  Eigen::Vector3d u[2];
  for (int s = 0; s < 2; ++s) {
    unit[s] = Eigen::Quaterniond(d.unit[s][3][j], d.unit[s][0][j], d.unit[s][1][j], d.unit[s][2][j]);
    u[s] = Eigen::Vector3d(d.u[s][0][j], d.u[s][1][j], d.u[s][2][j]);
  }
  hull_pair_features(unit, u, n, a, b, tolerance, flats, flat);
  return flats[0] + 4 * flats[1];
}

// hull_pair_directions() with pair j of the block in lane j % 4 of the (j / 4)-th pair of AVX2 registers, side a and
// side b in separate registers: the same operations per lane in the same order (the sign a product by +1 or -1).
// (4-lane vectors, not 8-lane ones: GCC split 64-byte vector-extension code into halves through the stack, 121
// instructions per pair, callgrind AVX2.)
void hull_directions_block(const QuatArray& ra, const QuatArray& rb, const Vec3Array& normal, std::size_t first,
                           std::size_t count, HullDirections& d) {
  using V = double __attribute__((vector_size(32)));
  using M = long long __attribute__((vector_size(32)));
  constexpr std::size_t kHalf = HullDirections::kPairs / 2;
  d.first = first;
  for (std::size_t h = 0; h < HullDirections::kPairs; h += kHalf) {
    // Lane j reads pair first + h + j, or the block's last pair past `count` (copies in a short tail only).
    const auto load = [&](const std::vector<double>& c) {
      V v;
      if (h + kHalf <= count) {
        std::memcpy(&v, c.data() + first + h, sizeof v);
      } else {
        for (std::size_t j = 0; j < kHalf; ++j) v[j] = c[first + std::min(h + j, count - 1)];
      }
      return v;
    };
    const V n0 = load(normal.x), n1 = load(normal.y), n2 = load(normal.z);
    const auto side = [&](const QuatArray& r, double sign_value, int s) {
      V x = load(r.x), y = load(r.y), z = load(r.z), w = load(r.w);
      const V sum = (x * x + z * z) + (y * y + w * w);
      const V root = (V)_mm256_sqrt_pd((__m256d)sum);  // IEEE: std::sqrt()'s and _mm_sqrt_pd()'s bits
      const M positive = sum > 0.0;
      const auto scale = [&](V c) { return (V)(((M)(c / root) & positive) | ((M)c & ~positive)); };
      x = scale(x), y = scale(y), z = scale(z), w = scale(w);
      std::memcpy(&d.unit[s][0][h], &x, sizeof x), std::memcpy(&d.unit[s][1][h], &y, sizeof y);
      std::memcpy(&d.unit[s][2][h], &z, sizeof z), std::memcpy(&d.unit[s][3][h], &w, sizeof w);
      const V cx = -x, cy = -y, cz = -z;
      V uv0 = cy * n2 - cz * n1, uv1 = cz * n0 - cx * n2, uv2 = cx * n1 - cy * n0;
      uv0 += uv0, uv1 += uv1, uv2 += uv2;
      const V sign = V{} + sign_value;
      const V r0 = sign * ((n0 + w * uv0) + (cy * uv2 - cz * uv1));
      const V r1 = sign * ((n1 + w * uv1) + (cz * uv0 - cx * uv2));
      const V r2 = sign * ((n2 + w * uv2) + (cx * uv1 - cy * uv0));
      std::memcpy(&d.u[s][0][h], &r0, sizeof r0), std::memcpy(&d.u[s][1][h], &r1, sizeof r1);
      std::memcpy(&d.u[s][2][h], &r2, sizeof r2);
    };
    side(ra, 1.0, 0);
    side(rb, -1.0, 1);
    if (h + kHalf >= count) break;  // the second half holds no pair of the block
  }
}
#pragma GCC pop_options

int exposed_feature(const double* vertices, std::size_t count, const Eigen::Vector3d& u, double tolerance,
                    Eigen::Vector3d& edge, InstructionSet isa) {
  const auto vertex = [&](std::size_t k) { return Eigen::Vector3d(vertices[3 * k], vertices[3 * k + 1], vertices[3 * k + 2]); };
  // The same expression in both passes, so that the maximum's own vertex compares equal to it; small hulls keep
  // the heights of the first pass.
  const auto height = [&](std::size_t k) {
    return u.x() * vertices[3 * k] + u.y() * vertices[3 * k + 1] + u.z() * vertices[3 * k + 2];
  };
  std::size_t first = count, second = count;
  // Returns true at a face: a third exposed vertex off the line of the first two.
  const auto exposed = [&](std::size_t k) {
    if (first == count) {
      first = k;
    } else if (second == count) {
      second = k;
    } else {
      const Eigen::Vector3d e1 = vertex(second) - vertex(first), e2 = vertex(k) - vertex(first);
      return e1.cross(e2).squaredNorm() > 1e-12 * e1.squaredNorm() * e2.squaredNorm();
    }
    return false;
  };
  const auto feature = [&] {
    if (second == count) return 0;
    edge = vertex(second) - vertex(first);
    return 1;
  };
  constexpr std::size_t kKept = 16;
  if ((isa == InstructionSet::avx2 || isa == InstructionSet::avx512) && count >= 4 && count <= kKept)
    return feature_of_mask(vertices, exposed_mask_avx2(vertices, count, u, tolerance), edge);
  double kept[kKept];
  // Two vertices per SSE2 register (vector extensions, the scalar expression's operations and order: the same
  // bits): the 6 coordinates of vertices k, k + 1 are three unaligned pairs (x y, z x', y' z').
  using V = double __attribute__((vector_size(16)));
  const auto load = [](const double* p) {
    V v;
    std::memcpy(&v, p, sizeof v);
    return v;
  };
  const double inf = std::numeric_limits<double>::infinity();
  const V uxy = {u.x(), u.y()}, uzx = {u.z(), u.x()}, uyz = {u.y(), u.z()};
  V top = {-inf, -inf};
  std::size_t k = 0;
  for (const std::size_t paired = std::min(count, kKept) & ~std::size_t{1}; k < paired; k += 2) {
    const double* p = vertices + 3 * k;
    const V a = load(p) * uxy, b = load(p + 2) * uzx, c = load(p + 4) * uyz;
    const V x = {a[0], b[1]}, y = {a[1], c[0]}, z = {b[0], c[1]};
    const V h2 = (x + y) + z;
    std::memcpy(&kept[k], &h2, sizeof h2);
    top = h2 > top ? h2 : top;
  }
  double h = std::max(top[0], top[1]);
  for (; k < count; ++k) {
    const double d = height(k);
    if (k < kKept) kept[k] = d;
    h = std::max(h, d);
  }
  const double floor = h - tolerance;
  if (count <= kKept) {
    // The kept heights' test two at a time into a bit mask (ordered compares: a NaN height is not exposed, as
    // below), then the exposed vertices in index order: the test and branch per vertex cost ~50 instructions per
    // 8-vertex hull (callgrind, analytic hull pairs), while a hull exposes 1-3 of its vertices.
    const __m128d f = _mm_set1_pd(floor);
    std::uint32_t mask = 0;
    for (k = 0; k + 1 < count; k += 2)
      mask |= std::uint32_t(_mm_movemask_pd(_mm_cmpge_pd(_mm_loadu_pd(&kept[k]), f))) << k;
    if (k < count && kept[k] >= floor) mask |= std::uint32_t{1} << k;
    return feature_of_mask(vertices, mask, edge);
  }
  for (k = 0; k < count; ++k)
    if ((k < kKept ? kept[k] : height(k)) >= floor && exposed(k)) return 2;
  return feature();
}

SupportJacobian exposed_support_jacobian(const Shape& s, const Eigen::Vector3d& u) {
  SupportJacobian J;
  const std::vector<Eigen::Vector3d>& v = s.hull->vertices;
  Eigen::Vector3d e;
  const int feature = exposed_feature(v.front().data(), v.size(), u, kExposedFeature * s.bounding_radius(), e);
  if (feature == 2) {
    const Eigen::Vector3d t = u.unitOrthogonal();
    add_flat(J, u, t, 1.0);
    add_flat(J, u, u.cross(t), 1.0);
  } else if (feature == 1) {
    add_flat(J, u, e, e.norm());
  }
  J.zero = J.flats == 0;
  return J;
}

bool world_support_jacobian(const Shape& s, const Eigen::Matrix3d& R, const Eigen::Vector3d& n, Eigen::Matrix3d& H) {
  if (s.type != ShapeType::sphere && s.type != ShapeType::ellipsoid) return false;
  const double r = round_radius(s);
  if (s.type == ShapeType::sphere) {
    H = r * (Eigen::Matrix3d::Identity() - n * n.transpose());
    return true;
  }
  // B = R diag(radii^2) R^T, the world-frame shape matrix: S(n) = B n / m with m = sqrt(n^T B n), so
  // dS/dn = B / m - (B n)(B n)^T / m^3 (the local formula of support_jacobian() rotated, without the two 3x3
  // products of R H R^T). Even in n, so the same at -n.
  const Eigen::Vector3d r2 = s.size.cwiseProduct(s.size);
  const Eigen::Matrix3d RD = R * r2.asDiagonal();
  Eigen::Matrix3d B;
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) B(i, j) = B(j, i) = RD(i, 0) * R(j, 0) + RD(i, 1) * R(j, 1) + RD(i, 2) * R(j, 2);
  const Eigen::Vector3d Bn = B * n;
  const double m = std::sqrt(n.dot(Bn)), inv_m = 1.0 / m, inv_m3 = inv_m * inv_m * inv_m;
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) H(i, j) = H(j, i) = B(i, j) * inv_m - Bn(i) * Bn(j) * inv_m3;
  if (r > 0.0)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) H(i, j) += r * ((i == j ? 1.0 : 0.0) - n(i) * n(j));
  return true;
}

Eigen::Vector3d full_support(const Shape& shape, const Eigen::Vector3d& u) {
  const OwnedShapeView view(shape);
  const auto core = kernels::make_core<double>(view.view);
  kernels::SupportHint hint;
  Eigen::Vector3d p = kernels::support(core, u, hint);
  add_swept_radius(p, core.radius, u);
  return p;
}

}  // namespace batchcol::detail
