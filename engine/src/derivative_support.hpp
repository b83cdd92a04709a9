// The Jacobian of a shape's support map (the Hessian of its support function sigma(u) = max_{x in A} <x, u>) in the
// shape's local frame, exact where it exists (its randomized-smoothing estimate, Montaut et al. 2023, sec. IV, is in
// derivative_smoothed1.hpp). Used by the implicit-function derivatives (derivative_ift.hpp).
#pragma once

#include "batchcol/pose.hpp"
#include "batchcol/shapes.hpp"
#include "batchcol/types.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <emmintrin.h>

#include <cstddef>
#include <cstdint>

namespace batchcol::detail {

/// Where the witness lies on its core decides which face, edge or vertex the contact is on. Positions, not the
/// normal, are tested: GJK's normal on a curved pair is only accurate to ~sqrt(2 tol / R) (1e-4 rad at the default
/// 1e-8 m tolerance), so a cylinder touching along its side would look like a rim contact, whereas GJK's witness on
/// a polytope, a segment or a cylinder's side is a convex combination of support points of that very feature, on
/// it to rounding. kExactFeature (relative to the shape's bounding radius) is that rounding with a wide margin.
/// kCurvedFeature is for the one boundary that is curved, a cap's or base's rim: a witness combining nearby rim
/// points lies r theta^2 / 2 ~ 1e-8 r inside the rim, far less than this.
constexpr double kExactFeature = 1e-9;
constexpr double kCurvedFeature = 1e-4;

struct SupportJacobian {
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();  // d S(u) / d u at the unit direction u (degree -1 in |u|)
  Eigen::Matrix<double, 3, 2> flat = Eigen::Matrix<double, 3, 2>::Zero();
  int flats = 0;      // 0: no tie; 1: an edge, a capsule's or cylinder's side line, a cone's generator; 2: a face
  bool zero = false;  // S is locally constant at u (a vertex of a non-inflated core)
  bool unsupported = false;  // halfspace: no support map
};

/// Exact support-map Jacobian of `shape` at the unit local direction u, the witness being `witness` (local frame,
/// inflation included).
SupportJacobian support_jacobian(const Shape& shape, const Eigen::Vector3d& u, const Eigen::Vector3d& witness);

/// Where both shapes of a pair are polytopes without inflation (hulls, boxes, triangles), GJK ends on the exact
/// features and the normal n is exact to rounding, so the feature of a hull can be read from the normal instead
/// of the witness: the vertices v with u.v >= max_w u.w - kExposedFeature r (u = the local direction, r the
/// bounding radius) span the face the support map jumps on (one vertex, an edge, a face). Why this tolerance: the
/// exposed vertices' u.v agree to the rounding of the dot products and of n (~1e-16 r and ~1e-16 r / distance
/// rad for GJK's witness points at distance 1e-4..1 r), while the next vertex lies lower by its distance to the
/// feature times the angle between n and the feature's other faces, which is 1e-9 r only within a nano-radian
/// of a face-face or edge-face contact (non-unique witness points either way). Measured on saved batches of hulls
/// against hulls and boxes (convex8 / 250 / 940; distant, close, overlapping): exposed vertices' gaps <= 3.7e-13 r,
/// the next vertex's >= 2.9e-7 r (convex940), >= 2.9e-5 r (convex8). Against ellipsoids and cylinders the exposed
/// gaps reach 2.6e-7 r (GJK's normal is not exact there): those pairs keep support_jacobian()'s witness test.
constexpr double kExposedFeature = 1e-9;

/// The feature of a hull (`count` vertices, x y z each) exposed by the local direction u: 0 a vertex, 1 an edge
/// (`edge` = the difference of its two vertices), 2 a face; a vertex is exposed when u.v is within `tolerance` of
/// the largest (kExposedFeature times the bounding radius). `isa` (resolved): AVX2 and AVX-512 compute the heights
/// four vertices per AVX2 register for hulls of 4..16 vertices, with the same bits as the SSE2 pass.
int exposed_feature(const double* vertices, std::size_t count, const Eigen::Vector3d& u, double tolerance,
                    Eigen::Vector3d& edge, InstructionSet isa = InstructionSet::scalar);

/// support_jacobian() of a hull without inflation (s.type == convex, s.inflation == 0) against a polytope, from
/// the vertices n exposes (kExposedFeature) instead of the face planes through the witness: a scan of the
/// vertices (2 dot products each) instead of every face's plane test.
SupportJacobian exposed_support_jacobian(const Shape& s, const Eigen::Vector3d& u);

/// hull_pair()'s two local directions, u_a = q_a.normalized().conjugate() * n and u_b = -(q_b.normalized().conjugate()
/// * n) (the world normal n in each hull's frame, b's reversed), with the normalised quaternions (an edge's rotation
/// back to the world), side a in lane 0 and side b in lane 1 of SSE2 registers: each lane does Eigen 3.4's
/// operations in their order, so both get the bits of those Eigen expressions at about the instructions of one:
/// normalized() divides each coefficient by sqrt(|q|^2) where |q|^2 > 0 (its SSE2 reduction sums (x^2 + z^2) +
/// (y^2 + w^2)); conjugate() negates x, y, z; q * v is _transformVector(): uv = q.vec() x v, uv += uv,
/// (v + w uv) + q.vec() x uv; the sign is a product by +-1 (exact). Tested bitwise against Eigen
/// (tests/engine/derivatives_lanes_test.cpp).
/// The coefficients (x, y, z, w) come as SSE2 lanes (a in lane 0, b in lane 1) in the first form, as quaternions in
/// the second.
using Lanes2 = double __attribute__((vector_size(16)));
inline __attribute__((always_inline)) void hull_pair_directions(Lanes2 x, Lanes2 y, Lanes2 z, Lanes2 w,
                                                                const Eigen::Vector3d& n, Eigen::Quaterniond& unit_a,
                                                                Eigen::Quaterniond& unit_b, Eigen::Vector3d& u_a,
                                                                Eigen::Vector3d& u_b) {
  using V = Lanes2;
  using M = long long __attribute__((vector_size(16)));
  const V s = (x * x + z * z) + (y * y + w * w);
  const V root = _mm_sqrt_pd(s);
  const M positive = s > 0.0;
  // positive ? c / root : c, without the vector '?:' (GCC may scalarise it)
  const auto scale = [&](V c) { return (V)(((M)(c / root) & positive) | ((M)c & ~positive)); };
  x = scale(x), y = scale(y), z = scale(z), w = scale(w);
  unit_a = Eigen::Quaterniond(w[0], x[0], y[0], z[0]);
  unit_b = Eigen::Quaterniond(w[1], x[1], y[1], z[1]);
  const V cx = -x, cy = -y, cz = -z;  // conjugate()
  const V n0 = {n.x(), n.x()}, n1 = {n.y(), n.y()}, n2 = {n.z(), n.z()};  // not 0 + n: -0 would become +0
  V uv0 = cy * n2 - cz * n1, uv1 = cz * n0 - cx * n2, uv2 = cx * n1 - cy * n0;
  uv0 += uv0, uv1 += uv1, uv2 += uv2;
  const V sign = {1.0, -1.0};
  const V r0 = sign * ((n0 + w * uv0) + (cy * uv2 - cz * uv1));
  const V r1 = sign * ((n1 + w * uv1) + (cz * uv0 - cx * uv2));
  const V r2 = sign * ((n2 + w * uv2) + (cx * uv1 - cy * uv0));
  u_a = {r0[0], r1[0], r2[0]};
  u_b = {r0[1], r1[1], r2[1]};
}
inline void hull_pair_directions(const Eigen::Quaterniond& q_a, const Eigen::Quaterniond& q_b, const Eigen::Vector3d& n,
                                 Eigen::Quaterniond& unit_a, Eigen::Quaterniond& unit_b, Eigen::Vector3d& u_a,
                                 Eigen::Vector3d& u_b) {
  hull_pair_directions(Lanes2{q_a.x(), q_b.x()}, Lanes2{q_a.y(), q_b.y()}, Lanes2{q_a.z(), q_b.z()},
                       Lanes2{q_a.w(), q_b.w()}, n, unit_a, unit_b, u_a, u_b);
}

/// hull_pair()'s flat of an exposed edge (a local vector): e = unit * edge (Eigen 3.4's q * v, _transformVector():
/// uv = q.vec() x v, uv += uv, (v + w uv) + q.vec() x uv), the part of e orthogonal to n, e - (n . e) n, and, where
/// that part's norm is > 1e-6 of e's (add_flat()'s test), flat = its normalized(); returns whether it was. The
/// rotation and the projection are written out with Eigen's operations in its order (the same bits, tested against
/// Eigen in tests/engine/derivatives_lanes_test.cpp): GCC called both out of line from hull_pair(), 27.5 + 11.1
/// instructions per convex8 pair plus the calls' spills (callgrind AVX2).
inline __attribute__((always_inline)) bool edge_flat(const Eigen::Quaterniond& unit, const Eigen::Vector3d& edge,
                                                     const Eigen::Vector3d& n, Eigen::Vector3d& flat) {
  const double x = unit.x(), y = unit.y(), z = unit.z(), w = unit.w();
  double uv0 = y * edge.z() - z * edge.y(), uv1 = z * edge.x() - x * edge.z(), uv2 = x * edge.y() - y * edge.x();
  uv0 += uv0, uv1 += uv1, uv2 += uv2;
  Eigen::Vector3d e((edge.x() + w * uv0) + (y * uv2 - z * uv1), (edge.y() + w * uv1) + (z * uv0 - x * uv2),
                    (edge.z() + w * uv2) + (x * uv1 - y * uv0));
  const double length = e.norm();
  const double along = n.dot(e);
  e.x() -= along * n.x(), e.y() -= along * n.y(), e.z() -= along * n.z();
  if (!(e.norm() > 1e-6 * length)) return false;
  flat = e.normalized();
  return true;
}

/// hull_pair()'s flats of both sides (a, b: [0], [1]): the local directions (hull_pair_directions()), each side's
/// exposed feature (exposed_feature(), tolerance[s]) and, for an edge, edge_flat(): flats[s] = 0 (a vertex, or an
/// edge along n), 1 (an edge; flat[s] its unit direction in the world) or 2 (a face). AVX2 / AVX-512 for hulls of
/// 4..16 vertices: all of it in one call of AVX2 code (both sides' height passes four vertices per register and
/// mask walks, interleaved by GCC; the SSE2 arithmetic of the directions, walks and edges under VEX encoding, the same
/// operations in the same order: the same bits), where the baseline SSE2 code of the directions and edges needed a
/// register copy for most of its two-operand operations: callgrind AVX2, convex8 analytic, 2331.7 -> 2303.3
/// instructions per pair (the features alone: 116 + 81 in four calls, 156 in one).
/// The rotations are pair i's of ra (a) and rb (b), read straight into the lanes (building the two quaternions in
/// memory for the call cost ~15 instructions per pair, callgrind AVX2).
void hull_pair_flats_avx2(const QuatArray& ra, const QuatArray& rb, std::size_t i, const Eigen::Vector3d& n,
                          const HullView& a, const HullView& b, const double* tolerance, int* flats,
                          Eigen::Vector3d* flat);

/// hull_pair_directions() of up to kPairs consecutive pairs at once (pair first + j in lane j), in structure of
/// arrays: unit[s][c][j] is coefficient c (x, y, z, w) of side s's normalised quaternion, u[s][c][j] coordinate c of
/// its local direction. Why: per pair, the square root and the four divisions that normalise the quaternions head a
/// dependency chain through the feature scan, which one pair's ~700 instructions do not leave the out-of-order
/// window room to overlap with the next pair's (perf cpu-clock, AMD EPYC Zen 4: hull_pair_flats_avx2 held 17% of
/// the analytic hull run's samples for 13% of its instructions, a ninth of them on the division); eight pairs'
/// directions in lanes (two 4-lane halves on AVX2) compute the chains side by side.
struct HullDirections {
  static constexpr std::size_t kPairs = 8;
  alignas(64) double unit[2][4][kPairs];
  alignas(64) double u[2][3][kPairs];
  std::size_t first = 0;
  /// The block the caller is in (hull_pair() fills it at its first hull pair: other pairs need no directions).
  std::size_t block_first = 0, block_count = 0;
  bool filled = false;
};

/// Fills `d` for pairs first .. first + count - 1 (count <= kPairs; lanes past count are computed on copies of
/// the last pair and never read) of the rotations ra (side a) and rb (side b) and the world normals `normal`:
/// every lane does hull_pair_directions()'s operations in their order (AVX2 code: the same bits; tested).
void hull_directions_block(const QuatArray& ra, const QuatArray& rb, const Vec3Array& normal, std::size_t first,
                           std::size_t count, HullDirections& d);

/// hull_pair_flats_avx2() with the directions of pair `first + j` of `d` (hull_directions_block()); the flats come
/// back as flats_a + 4 flats_b in a register: written as two ints to memory, the caller's first read of them was one
/// 8-byte load of two 4-byte stores, which the store buffer does not forward (perf cpu-clock, AMD EPYC Zen 4: a
/// tenth of differentiate_pair()'s samples sat on that load).
int hull_pair_flats_given_avx2(const HullDirections& d, std::size_t j, const Eigen::Vector3d& n, const HullView& a,
                               const HullView& b, const double* tolerance, Eigen::Vector3d* flat);


inline __attribute__((always_inline)) void hull_pair_flats(const QuatArray& ra, const QuatArray& rb, std::size_t i,
                                                           const Eigen::Vector3d& n, const HullView& a,
                                                           const HullView& b, const double tolerance[2], int flats[2],
                                                           Eigen::Vector3d flat[2], InstructionSet isa) {
  constexpr std::uint32_t kKept = 16;
  // 4 <= vertex_count <= kKept, each as one unsigned comparison
  if ((isa == InstructionSet::avx2 || isa == InstructionSet::avx512) && a.vertex_count - 4 <= kKept - 4 &&
      b.vertex_count - 4 <= kKept - 4)
    return hull_pair_flats_avx2(ra, rb, i, n, a, b, tolerance, flats, flat);
  Eigen::Quaterniond unit[2];
  Eigen::Vector3d u[2], edge[2];
  hull_pair_directions(ra[i], rb[i], n, unit[0], unit[1], u[0], u[1]);
  flats[0] = exposed_feature(a.vertices, a.vertex_count, u[0], tolerance[0], edge[0], isa);
  flats[1] = exposed_feature(b.vertices, b.vertex_count, u[1], tolerance[1], edge[1], isa);
  for (int s = 0; s < 2; ++s)
    if (flats[s] == 1 && !edge_flat(unit[s], edge[s], n, flat[s])) flats[s] = 0;
}

/// hull_pair_flats() with the directions of `d` (null: computed here), the flats returned as flats_a + 4 flats_b
/// (hull_pair_flats_given_avx2()'s reason): the same bits.
inline __attribute__((always_inline)) int hull_pair_flats_packed(const QuatArray& ra, const QuatArray& rb,
                                                                 std::size_t i, const Eigen::Vector3d& n,
                                                                 const HullView& a, const HullView& b,
                                                                 const double tolerance[2], Eigen::Vector3d flat[2],
                                                                 InstructionSet isa, const HullDirections* d) {
  constexpr std::uint32_t kKept = 16;
  if (d && (isa == InstructionSet::avx2 || isa == InstructionSet::avx512) && a.vertex_count - 4 <= kKept - 4 &&
      b.vertex_count - 4 <= kKept - 4)
    return hull_pair_flats_given_avx2(*d, i - d->first, n, a, b, tolerance, flat);
  int flats[2];
  hull_pair_flats(ra, rb, i, n, a, b, tolerance, flats, flat, isa);
  return flats[0] + 4 * flats[1];
}

/// support_jacobian() of a sphere or an ellipsoid (returns false for the other types, leaving H alone) at the unit
/// WORLD direction n (or -n: the same), in the world frame, R being the shape's rotation: straight from the world
/// shape matrix, without the local direction and the rotation of the local Jacobian.
bool world_support_jacobian(const Shape& shape, const Eigen::Matrix3d& R, const Eigen::Vector3d& n,
                            Eigen::Matrix3d& H);

/// The full support point (core plus inflation radius) of `shape` at local direction u (not necessarily unit).
Eigen::Vector3d full_support(const Shape& shape, const Eigen::Vector3d& u);

/// The nearest symmetric positive semidefinite matrix to symmetric H (Frobenius norm): its eigenvalues clamped at
/// 0. Computed from the eigenvalues alone (Jacobi rotations, then spectral projectors as polynomials in H), within
/// rounding of the eigendecomposition's V max(L, 0) V^T.
Eigen::Matrix3d psd_projection(const Eigen::Matrix3d& H);

/// Adds a swept radius (the inflation of a core) to the core's support point p at direction d (not necessarily unit):
/// radius d / |d|; the norm (a square root) only when there is a radius, nothing at d = 0.
inline void add_swept_radius(Eigen::Vector3d& p, double radius, const Eigen::Vector3d& d) {
  if (!(radius > 0.0)) return;
  const double n = d.norm();
  if (n > 0.0) p += radius * d / n;
}

}  // namespace batchcol::detail
