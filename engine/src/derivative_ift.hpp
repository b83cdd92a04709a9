// Derivatives of one pair's distance, witness points and normal by the envelope and implicit function theorems.
//
// With z = witness_b - witness_a = sd n, the witness points are support points, x_a = S_A(n), x_b = S_B(-n) (world
// frame; for separated and penetrating pairs alike). For separated pairs z is the fixed point
//   f(z, T) = z + S_A(z; T_a) - S_B(-z; T_b) = 0,
// and for penetrating pairs the same with n = -z/|z|. Under the twist convention of derivatives.hpp,
//   d S(u; T) / d xi = [I, -[x]x + H(u) [u]x]   (x = S(u), H = the support map's Jacobian in the world frame),
// so with H_a = H_A(n), H_b = H_B(-n) at unit directions (S is homogeneous of degree 0, H of degree -1):
//   F_a = df/dxi_a = [ I, -[x_a]x + H_a [n]x ],   F_b = df/dxi_b = [-I, [x_b]x + H_b [n]x ],
//   K = (sd I + H_a + H_b)^-1,   dz/dxi = -sd K F   (the implicit function theorem, multiplied through by sd),
//   dx_a/dxi = -H_a K F (+ F_a for xi_a),   dx_b/dxi = H_b K F (- F_b for xi_b),   dn/dxi = -(I - n n^T) K F,
// none of which divides by sd, so they stay finite as the pair approaches contact when H_a + H_b is definite.
// The distance gradient is the envelope theorem's: dsd/dxi_a = -(n, x_a x n), dsd/dxi_b = (n, x_b x n) (it equals
// n^T dz/dxi because H n = 0).
//
// Faces and edges. Where n is normal to a face or edge of a core (a "flat" of its support map), S jumps along it:
// its Jacobian is H' + lambda A A^T with lambda -> infinity (A: orthonormal flat directions, H': the finite part).
// The limit exists whenever the flats of the two shapes are independent: writing mu_a = lambda A^T y for
// y = K F, the system M y = F becomes the saddle-point system
//   [ sd I + H'_a + H'_b   A   B ] [ y   ]   [ F'  ]
//   [ A^T                  0   0 ] [ mu_a] = [ c_a ]      (c_a = A^T [0, [n]x] for xi_a, 0 for xi_b; c_b alike)
//   [ B^T                  0   0 ] [ mu_b]   [ c_b ]
// (F' is F without its infinite part lambda A A^T [n]x, which reappears as the constraint's right-hand side), and
// H_a K F = H'_a y + A mu_a + lambda A c_a, whose last term cancels against F's in every witness Jacobian. That
// is the vertex-face and edge-edge derivative of two polytopes: a witness on a face slides with the other witness.
// Dependent flats (face-face, parallel edges, an edge on a face) make the witness points non-unique: no derivative.
#pragma once

#include "batchcol/types.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross() in distance_gradients()

#include <cstddef>
#include <cstdint>

namespace batchcol::detail {

using Mat36 = Eigen::Matrix<double, 3, 6>;
using Row6 = Eigen::Matrix<double, 1, 6>;

struct PairGeometry {
  Eigen::Vector3d witness_a, witness_b, normal;
  double distance = 0.0;  // signed
  Eigen::Matrix3d H_a, H_b;  // support-map Jacobians (finite parts), world frame, at the unit directions n, -n
  Eigen::Matrix<double, 3, 2> flat_a = Eigen::Matrix<double, 3, 2>::Zero(), flat_b = flat_a;  // world, orthonormal
  int flats_a = 0, flats_b = 0;
  double scale = 1.0;        // a length of the problem (sum of bounding radii) for the singularity test
};

struct PairJacobians {
  Row6 distance_a, distance_b;
  Mat36 witness_a_a, witness_a_b, witness_b_a, witness_b_b, normal_a, normal_b;
  bool singular = false;   // the system is singular (touching without curvature, some penetrations)
  bool dependent = false;  // the flats of a and b are dependent: non-unique witness points
};

/// [x]x, the cross-product matrix: [x]x y = x x y.
inline Eigen::Matrix3d skew(const Eigen::Vector3d& x) {
  Eigen::Matrix3d m;
  m << 0, -x.z(), x.y(), x.z(), 0, -x.x(), -x.y(), x.x(), 0;
  return m;
}

/// The rigid motion of a point x fixed on a body: [I, -[x]x] (v + w x x = v - [x]x w).
inline Mat36 rigid_motion(const Eigen::Vector3d& x) {
  Mat36 m;
  m << Eigen::Matrix3d::Identity(), -skew(x);
  return m;
}

/// Distance gradients by the envelope theorem.
inline void distance_gradients(const PairGeometry& g, Row6& grad_a, Row6& grad_b) {
  grad_a << -g.normal.transpose(), g.normal.cross(g.witness_a).transpose();
  grad_b << g.normal.transpose(), g.witness_b.cross(g.normal).transpose();
}

/// Where each output starts among a pair's entries (StoreBlock's slots, write_jacobians(), the smoothed0 mapping):
/// the distance gradients of a and b (6 each), then the six 3x6 Jacobians (18 each, row-major) in
/// DerivativeResults' order. The one spelling of that layout.
namespace store_at {
constexpr int distance_a = 0, distance_b = 6, witness_a_a = 12, witness_a_b = 30, witness_b_a = 48, witness_b_b = 66,
              normal_a = 84, normal_b = 102;
}
/// Entries per pair of the derivative outputs (2 x 6 + 6 x 18).
constexpr int StoreEntries = store_at::normal_b + 18;
// The blocks follow each other in this order: StoreBlock::flush() walks the output arrays in it, and the gradients'
// writers index entries 0-11 directly.
static_assert(store_at::distance_a == 0 && store_at::distance_b == 6 && store_at::witness_a_a == 12 &&
              store_at::witness_a_b == store_at::witness_a_a + 18 &&
              store_at::witness_b_a == store_at::witness_a_b + 18 &&
              store_at::witness_b_b == store_at::witness_b_a + 18 && store_at::normal_a == store_at::witness_b_b + 18 &&
              store_at::normal_b == store_at::normal_a + 18);

/// How AVX-512 writes whole blocks of a large output (StoreBlock): every row in whole 64-byte lines with
/// non-temporal stores, which write a line without first reading it and keep the output from evicting the cache.
/// A block starts a line of the rows whose bit is set in `whole` (8 pairs: one aligned store). Another row's line
/// starts shift[e] pairs before the block (1..7: the arrays are separate allocations, and rows of one array start n
/// entries apart): the block completes that
/// line with the last shift[e] entries of the previous block, kept in carry[e], and keeps its own in carry[e]
/// for the next line; `carried` says that carry holds the block just before (contiguous, this task range's),
/// otherwise only the block's own part of the line is stored (a masked, regular store). The last block's carried
/// entries are stored by flush_stream_carry().
struct StreamRows {
  std::uint64_t whole[2] = {0, 0};
  std::int64_t shift[StoreEntries] = {};
  alignas(64) double carry[StoreEntries][8];
  bool carried = false;
};

/// Stores the carried entries of the whole block that started at pair `at` (masked regular stores) and clears
/// `carried`.
void flush_stream_carry(StreamRows& rows, double* const* out, std::size_t at);

/// A sphere's or an ellipsoid's support-map Jacobian left to SmoothLanes to compute (world_support_jacobian()'s
/// formula): the shape's rotation as the pose's quaternion (x, y, z, w, not normalised: the lanes normalise it and
/// build the matrix as Eigen's normalized().toRotationMatrix() does, eight poses per register instead of one), its
/// squared radii (zero for a sphere) and its round radius (sphere radius plus inflation, or the ellipsoid's
/// inflation).
struct CurvedSide {
  double q[4] = {0.0, 0.0, 0.0, 1.0};
  Eigen::Vector3d radii2 = Eigen::Vector3d::Zero();
  double round = 0.0;
};

/// The separated pairs without flats (the smooth common case) of a block of up to kLanes pairs, in
/// structure-of-arrays order (lane l of every array), so that their implicit-function Jacobians are computed
/// across the lanes in SIMD registers. Lanes are filled in order (lane l goes to output column column[l]); a
/// register half past `count` is computed on whatever it holds and not written.
struct SmoothLanes {
  static constexpr std::size_t kLanes = 8;
  // Per side (a, b): H = H0 + B / m - (B n)(B n)^T / m^3 + round (I - n n^T) with B = R diag(radii2) R^T, R the
  // rotation of the quaternion q (x, y, z, w) and m = sqrt(n^T B n) (0 / 0 taken as 0): a sphere or ellipsoid
  // (H0 = 0), or the given H0 (q = radii2 = round = 0: R = I, B = +0).
  struct Side {
    alignas(64) double H0[9][kLanes], q[4][kLanes], radii2[3][kLanes], round[kLanes];
  };
  alignas(64) double n[3][kLanes], xa[3][kLanes], xb[3][kLanes], sd[kLanes];
  Side a, b;
  std::size_t column[kLanes];
  std::size_t count = 0;
  /// Some lane has a sphere or ellipsoid side (curvature() needed); false when every lane's H is its given H0 (all
  /// smoothed1 pairs, analytic pairs with features): solve() then takes H = H0 + 0.0, the same bits as the full
  /// formula with R = radii2 = round = 0 (each of its terms is +0 or -0, and x + 0 - 0 + (-0) is x, +0 for -0).
  bool curved = false;
  /// Some lane has a side with a given H0 (not a sphere or ellipsoid). Until one does, add() writes no H0 and the
  /// lanes take H0 = +0, what it held for curved sides (no H0 stores and loads for ellipsoid pairs); the first
  /// given side zeroes the H0 of the lanes before it.
  bool given = false;
  void clear() { count = 0, curved = false, given = false; }
  /// The next lane takes pair g, for output column `column`; a null side uses g.H_a / g.H_b.
  void add(std::size_t column, const PairGeometry& g, const CurvedSide* curved_a = nullptr,
           const CurvedSide* curved_b = nullptr);
  /// The next lane takes pair g with H0 of both sides left to the caller (written before solve(): smoothed1's
  /// Smoothed1Lanes), for output column `column`: add(column, g) without g.H_a, g.H_b.
  void add_given(std::size_t column, const PairGeometry& g);
  /// Writes the 120 entries of every lane l < count to out[e][column[l]] (write_jacobians()'s order; out[e] points
  /// to column 0 of entry e: a block buffer's row or the output array itself). Whole registers are stored when
  /// the columns are 0, 1, 2, ... (a block of smooth pairs only), single lanes otherwise.
  /// normal_b_only: only normal_wrt_b's 18 entries (the other rows of `out` are left as they were).
  /// isa: a whole block (count == kLanes, columns 0, 1, 2, ...) runs in one 8-lane register of that set (AVX-512,
  /// AVX2); the same bits on every set.
  /// AVX-512 also runs a block of fewer lanes in one register when its columns are 0 .. count - 1 (masked stores).
  /// at: added to every out[e] (out[e] + at is column 0): StoreBlock passes the output arrays' rows of pair 0 once
  /// computed and the block's first pair, instead of building 120 row pointers per flush.
  /// stream (null: none): AVX-512 writes a whole block in whole 64-byte lines with non-temporal stores
  /// (StreamRows).
  void solve(double* const* out, bool normal_b_only = false, InstructionSet isa = InstructionSet::scalar,
             std::size_t at = 0, StreamRows* stream = nullptr) const;

 private:
  template <bool kNormalB, bool kCurved, bool kGiven>
  void solve_lanes(double* const* out, InstructionSet isa, std::size_t at, StreamRows* stream) const;
  /// add() and add_given()'s common steps: the next lane's column and geometry (returns the lane); +0 in every
  /// lane's H0 (the lanes added before the first given side); a side with a given H0 (R = radii2 = round = 0).
  std::size_t take_lane(std::size_t column, const PairGeometry& g);
  void zero_given();
  static void flat_side(Side& s, std::size_t l);
};

/// The separated pairs of polytopes without inflation (H_a = H_b = 0: hulls, boxes, triangles) with at most two
/// independent flats in all (vertex-vertex, vertex-edge, vertex-face, edge-edge) of a block of up to kLanes pairs,
/// solved across the lanes as SmoothLanes solves the smooth ones. Their saddle-point system has M0 = sd I, so the
/// solution for the twist of a (derivative_ift.cpp, polytope_jacobians()) is, with F = [I, -[x_a]x] and P the
/// projector on the flats' span,
///   y = [(I - P) / sd, -(I - P) [x_a]x / sd + G],   dx_b/dxi_a = W (F - sd y),   dx_a/dxi_a = dx_b/dxi_a + sd y,
///   dn/dxi_a = -(I - n n^T) y,
/// where only the 3x3 blocks P, G (the constraint part) and W (the part of the multipliers on b's flats) depend on
/// the case: add() computes them per pair in scalars, solve() does the 3x6 products and the 120 outputs in lanes.
struct PolytopeLanes {
  static constexpr std::size_t kLanes = 8;
  alignas(64) double n[3][kLanes], xa[3][kLanes], xb[3][kLanes], sd[kLanes];
  alignas(64) double P[9][kLanes], G[9][kLanes], W[9][kLanes];
  std::size_t column[kLanes];
  std::size_t count = 0;
  void clear() { count = 0; }
  /// The next lane takes pair g (g.H_a = g.H_b = 0, separated beyond the singularity threshold, flats_a + flats_b
  /// <= 2), for output column `column`. Returns false, taking no lane, when two flats are dependent (parallel
  /// edges): the general path decides. Defined in derivative_polytope_add.hpp, inlined into its caller.
  inline bool add(std::size_t column, const PairGeometry& g);
  /// As SmoothLanes::solve().
  void solve(double* const* out, InstructionSet isa = InstructionSet::scalar, std::size_t at = 0,
             StreamRows* stream = nullptr) const;
};

/// True when the pair can take PolytopeLanes (no curvature, separated, at most two flats).
inline bool polytope_pair(const PairGeometry& g) {
  return g.flats_a + g.flats_b <= 2 && g.distance > 1e-9 * g.scale && g.H_a.isZero(0.0) && g.H_b.isZero(0.0);
}

/// True when the pair takes SmoothLanes: no flats and separated beyond the singularity threshold.
inline bool smooth_pair(const PairGeometry& g) {
  return g.flats_a + g.flats_b == 0 && g.distance > 1e-9 * g.scale;
}

/// Writes J's 120 entries to `slot` (entry e at slot[e * stride], in StoreBlock's order: the distance gradients
/// of a and b, then witness_a_a, witness_a_b, witness_b_a, witness_b_b, normal_a, normal_b, row-major).
void write_jacobians(const PairJacobians& J, double* slot, std::size_t stride);

struct IftFlags {
  bool singular = false;   // see PairJacobians
  bool dependent = false;
};

/// Everything above for one pair, written to `slot` as by write_jacobians(); `singular` (Jacobians left NaN) when
/// the system (its constraint rows scaled to lengths) has an eigenvalue within 1e-9 of the problem's length scale:
/// its inverse would magnify the witness points' own error (~1e-8 of that scale at the default GJK tolerance)
/// beyond any meaning.
IftFlags implicit_jacobians(const PairGeometry& g, double* slot, std::size_t stride);

}  // namespace batchcol::detail
