// World AABBs of the scene's objects, computed over the structure-of-arrays poses.
//
// The loop over primitives is branch-free (quaternion -> rotation matrix, |R| times the box, the ellipsoid term, the
// ball) so that the compiler vectorises it. g++ 12 -O3 reports "loop vectorized using 16 byte vectors" for
// world_boxes() (-fopt-info-vec; the project's default x86-64 target is SSE2, two doubles per vector) and "32 byte
// vectors" with -mavx2. Two things were needed: `#pragma GCC ivdep` (see the loop) and -fno-math-errno for this file
// (engine/CMakeLists.txt), since errno handling puts a branch around sqrt; it changes no result. Cones and triangles
// (no closed form of the Minkowski-sum kind, see LocalBound) are redone afterwards with compute_aabb().
//
// Rounding: each box is widened by pad = 2^-22 (|centre| + half extent) + 2^-126 before the cast to float. The double
// computation errs by a few 1e-16 of |centre| + half extent and the cast to nearest float by at most 2^-24 of the
// value, so the float box always contains the exact box (the outward rounding the broad phase relies on), at a cost
// of about two float ulps. 2^-126 (the smallest normal float) covers values that round to subnormals.
#include "scene_state.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

namespace batchcol {

LocalBound local_bound(const Shape& s) {
  LocalBound b;
  b.ball = s.inflation;
  switch (s.type) {
    case ShapeType::sphere: b.ball += s.size.x(); break;
    case ShapeType::capsule: b.ball += s.size.x(); b.box.z() = s.size.y(); break;
    case ShapeType::box: b.box = s.size; break;
    case ShapeType::cylinder:
      b.box.z() = s.size.y();
      b.ellipse = Eigen::Vector3d(s.size.x(), s.size.x(), 0.0);
      break;
    case ShapeType::ellipsoid: b.ellipse = s.size; break;
    case ShapeType::convex: {
      Eigen::Vector3d lo = s.hull->vertices.front(), hi = lo;
      for (const Eigen::Vector3d& v : s.hull->vertices) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
      b.centre = 0.5 * (lo + hi);
      b.box = 0.5 * (hi - lo);
      // centre + box may round below hi: add the rounding of the half sum (a few ulps of the coordinates).
      b.box += Eigen::Vector3d::Constant(4e-16 * (lo.cwiseAbs().maxCoeff() + hi.cwiseAbs().maxCoeff()));
      break;
    }
    case ShapeType::cone:
    case ShapeType::triangle:
    case ShapeType::halfspace: b.exact_path = true; break;
  }
  return b;
}

namespace {

constexpr double kPad = 0x1p-22;
constexpr double kTiny = 0x1p-126;

// One axis of one box: row (r0, r1, r2) of R. Inlined into the vectorised loop.
inline void axis_bounds(double r0, double r1, double r2, double t, double cx, double cy, double cz, double bx,
                        double by, double bz, double ex, double ey, double ez, double ball, float& lo, float& hi) {
  const double centre = t + (r0 * cx + r1 * cy + r2 * cz);
  const double e0 = r0 * ex, e1 = r1 * ey, e2 = r2 * ez;
  const double half = std::fabs(r0) * bx + std::fabs(r1) * by + std::fabs(r2) * bz +
                      std::sqrt(e0 * e0 + e1 * e1 + e2 * e2) + ball;
  const double pad = kPad * (std::fabs(centre) + half) + kTiny;
  lo = static_cast<float>(centre - half - pad);
  hi = static_cast<float>(centre + half + pad);
}

// The vectorised loop: objects [begin, end), ball already includes the margin through `margin`.
void world_boxes(const FiniteObjects& o, double margin, std::size_t begin, std::size_t end,
                 broadphase::AabbSoa& out) {
  const double *__restrict tx = o.tx.data(), *__restrict ty = o.ty.data(), *__restrict tz = o.tz.data();
  const double *__restrict qw = o.qw.data(), *__restrict qx = o.qx.data(), *__restrict qy = o.qy.data(),
               *__restrict qz = o.qz.data();
  const double *__restrict cx = o.cx.data(), *__restrict cy = o.cy.data(), *__restrict cz = o.cz.data();
  const double *__restrict bx = o.bx.data(), *__restrict by = o.by.data(), *__restrict bz = o.bz.data();
  const double *__restrict ex = o.ex.data(), *__restrict ey = o.ey.data(), *__restrict ez = o.ez.data();
  const double* __restrict ball = o.ball.data();
  float *__restrict lx = out.min_x.data(), *__restrict ly = out.min_y.data(), *__restrict lz = out.min_z.data();
  float *__restrict hx = out.max_x.data(), *__restrict hy = out.max_y.data(), *__restrict hz = out.max_z.data();
  // GCC ignores __restrict on local pointers and gives up on the ~23 runtime alias checks; the arrays are distinct
  // vectors, so no iteration depends on another.
#pragma GCC ivdep
  for (std::size_t i = begin; i < end; ++i) {
    const double w = qw[i], x = qx[i], y = qy[i], z = qz[i];
    const double xx = x * x, yy = y * y, zz = z * z, xy = x * y, xz = x * z, yz = y * z;
    const double wx = w * x, wy = w * y, wz = w * z;
    const double r = ball[i] + margin;
    axis_bounds(1.0 - 2.0 * (yy + zz), 2.0 * (xy - wz), 2.0 * (xz + wy), tx[i], cx[i], cy[i], cz[i], bx[i], by[i],
                bz[i], ex[i], ey[i], ez[i], r, lx[i], hx[i]);
    axis_bounds(2.0 * (xy + wz), 1.0 - 2.0 * (xx + zz), 2.0 * (yz - wx), ty[i], cx[i], cy[i], cz[i], bx[i], by[i],
                bz[i], ex[i], ey[i], ez[i], r, ly[i], hy[i]);
    axis_bounds(2.0 * (xz - wy), 2.0 * (yz + wx), 1.0 - 2.0 * (xx + yy), tz[i], cx[i], cy[i], cz[i], bx[i], by[i],
                bz[i], ex[i], ey[i], ez[i], r, lz[i], hz[i]);
  }
}

// Cones and triangles: the support-function box of compute_aabb(), with the same margin and padding.
void exact_box(const ShapeTable& shapes, const FiniteObjects& o, double margin, std::size_t i,
               broadphase::AabbSoa& out) {
  const Aabb box = compute_aabb(shapes[o.shape[i]], Eigen::Quaterniond(o.qw[i], o.qx[i], o.qy[i], o.qz[i]),
                                Eigen::Vector3d(o.tx[i], o.ty[i], o.tz[i]));
  float* lo[3] = {out.min_x.data(), out.min_y.data(), out.min_z.data()};
  float* hi[3] = {out.max_x.data(), out.max_y.data(), out.max_z.data()};
  for (int a = 0; a < 3; ++a) {
    const double l = box.min[a] - margin, h = box.max[a] + margin;
    const double pad = kPad * std::fmax(std::fabs(l), std::fabs(h)) + kTiny;
    lo[a][i] = static_cast<float>(l - pad);
    hi[a][i] = static_cast<float>(h + pad);
  }
}

}  // namespace

void compute_world_boxes(const ShapeTable& shapes, const FiniteObjects& objects, double margin,
                         broadphase::AabbSoa& boxes, std::vector<PoseRecord>& poses) {
  const std::size_t n = objects.size();
  boxes.resize(n);
  poses.resize(n);
  const FiniteObjects& o = objects;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    world_boxes(o, margin, r.begin(), r.end(), boxes);
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      if (o.exact_path[i]) exact_box(shapes, o, margin, i, boxes);
      poses[i] = {o.tx[i], o.ty[i], o.tz[i], o.qw[i], o.qx[i], o.qy[i], o.qz[i]};  // still in cache
    }
  });
}

}  // namespace batchcol
