// GJK's types: statuses, simplex, parameters and result. The algorithm itself (GJK as fully-corrective
// Frank-Wolfe on the Minkowski difference D = A - B, with optional Nesterov or Polyak momentum on the support
// direction) has one production implementation, the wide kernel kernels/simd/wide_gjk.inl (one pair per SIMD
// lane; the scalar instruction set runs it at width 1). tests/support/reference_gjk.hpp keeps a plain scalar
// transcription that the tests check the wide kernel against, bit for bit.
//   Gilbert, Johnson, Keerthi, "A fast procedure for computing the distance between complex objects", 1988.
//   Montaut, Le Lidec, Petrik, Sivic, Carpentier, "Collision detection accelerated: an optimization
//   perspective", RSS 2022 (Nesterov momentum delta_k = (k+1)/(k+3), normalised directions for shapes that are not
//   strictly convex, fallback to plain GJK when momentum stops helping).
// Distance / witness queries on curved cores (ellipsoid, cylinder, cone) switch to Newton search directions near the
// optimum: Newton on the optimality condition of the direction, with the support functions' Hessians
// (wide_gjk.inl's newton_direction()); the simplex, bounds and termination stay GJK's.
// Minimising f(x) = |x|^2 / 2 over D: the gradient at x is x, a Frank-Wolfe step asks the support of D in
// direction -d, and the support point s gives the certified lower bound <s, d>/|d| on dist(0, D). We stop when
// |x| minus the best lower bound (an upper bound on the distance error) is below the tolerance; with d = x this is
// the duality gap (|x|^2 - <x, s>) / |x|.
#pragma once

#include "batchcol/types.hpp"
#include "kernels/minkowski.hpp"

#include <algorithm>
#include <array>

namespace batchcol::kernels {

enum class GjkStatus : std::uint8_t {
  converged,          // distance certified within tolerance (shapes separated or touching)
  overlap,            // the origin lies in the current simplex (up to touch_tolerance): the cores intersect
  separated_proven,   // boolean query: a separating plane beyond the margin was found
  collision_proven,   // boolean query: a point of D within the margin was found
  max_iterations,
  stalled,            // no progress in working precision before the tolerance was reached
};

template <class T> struct Simplex {
  std::array<SupportPoint<T>, 4> v;
  std::array<T, 4> lambda{};
  int count = 0;
};

template <class T> struct GjkParams {
  Solver solver = Solver::nesterov;
  T tolerance = T(1e-8);           // absolute, on the core distance (already raised to the precision floor)
  T relative_tolerance = T(0);
  int max_iterations = 128;
  bool boolean_only = false;
  T core_margin = T(0);            // boolean: the cores collide when their distance is <= core_margin
  bool normalize_momentum = true;  // normalised Nesterov directions (shapes not strictly convex)
  /// |x| at or below this is indistinguishable from 0 in the working precision: the cores touch or overlap and
  /// the sign of their distance is decided by EPA, not by GJK.
  T touch_tolerance = T(0);
};

template <class T> struct GjkResult {
  GjkStatus status = GjkStatus::max_iterations;
  Vec3<T> x = Vec3<T>::Zero();      // closest point of D found: witness_a - witness_b (A's frame)
  Simplex<T> simplex;
  Vec3<T> direction = Vec3<T>::Zero();  // last search direction (warm start for the next query)
  T lower_bound = T(0);             // best certified lower bound on the core distance (may be <= 0)
  int iterations = 0;
  int newton_steps = 0;             // iterations that searched along a Newton direction (wide_gjk.inl)

  Vec3<T> witness_a() const { return combine(&SupportPoint<T>::a); }
  Vec3<T> witness_b() const { return combine(&SupportPoint<T>::b); }

 private:
  Vec3<T> combine(Vec3<T> SupportPoint<T>::*member) const {
    Vec3<T> p = Vec3<T>::Zero();
    for (int i = 0; i < simplex.count; ++i) p += simplex.lambda[i] * (simplex.v[i].*member);
    return p;
  }
};

/// Momentum steps allowed in a row without closing a tenth of the certified gap before plain GJK takes over.
constexpr int kMaxStaleMomentumSteps = 4;

/// Cores whose support map is piecewise constant with more than one piece (hull, capsule segment; box and triangle
/// too, but see flat_newton_side()): near the optimum their witness lies inside a face or an edge (a feature)
/// spanned by support vertices.
constexpr bool polytope_core(ShapeType t) { return t == ShapeType::convex || t == ShapeType::capsule; }
/// Pairs of a polytope and an ellipsoid take feature Newton directions (wide_gjk.inl's feature_direction()):
/// 1 when A is the polytope, 2 when B is, 0 for the other pair types.
/// Not boxes: with the Hessians formed from the support points, box-ellipsoid went from 18.7 to 12.2 mean iterations
/// and, on AVX2 (4 double lanes), from 8743 to 8085 instructions per pair (callgrind, close witness double) and -8%
/// wall (farm-bench, bench ns/pair medians 2918 -> 2688 on the loaded 2-core Xeon VM); but with 8 lanes per
/// register it lost: AVX-512 double +4% and +7% ns/pair in two A/B runs (2052 -> 2137, 2036 -> 2188), AVX2 float
/// 4035 -> 4530 instructions (14.6 -> 11.6 iterations); distance double 7734 -> 7943 (AVX2). More lanes mix more
/// feature kinds (vertex, edge, face) per call, so feature_direction() runs more of its branches; results must not
/// depend on the instruction set, so the gate is by pair type (branch `flat`: commit 0dff0ff has boxes on in double).
/// Not against cylinders and cones, although their side lines and caps were tried as features as well (a side
/// line as an edge along the axis or the generator, a cap as a face; branch `flat`, commit 58e3fc2): the iterations
/// fell (box-cylinder 13.6 -> 11.5, capsule-cylinder 9.6 -> 7.2, cylinder-cylinder 18.8 -> 15.4, cylinder-convex8
/// 14.6 -> 11.9, box-cone 10.8 -> 10.4, cone-cone 15.8 -> 15.8), but not enough to pay for the step (instructions
/// per pair: box-cylinder 6437 -> 7776, capsule-cylinder 4899 -> 5062, cylinder-cylinder 8709 -> 10434,
/// cylinder-cone 8203 -> 10792, box-cone 5179 -> 7026, cone-cone 7392 -> 10833, capsule-cone 3739 -> 4718), and
/// cylinder-ellipsoid / cone-ellipsoid took more iterations than with newton_direction() (15.0 -> 17.1,
/// 15.4 -> 19.3). (A cone's generator has its rim's curvature scaled by the distance from the apex, which the rim
/// Hessian does not model: likely why cone rows gained least.) Triangles are left out, unmeasured.
/// Feature steps are taken whatever the sign of the support's lower bound lb (the curved pairs need lb > 0 for
/// H + lb I to be definite): on close pairs lb stays negative for the first ~4-6 iterations while the simplex
/// holds the optimum's feature after ~2 (scalar reference, 2000 close ellipsoid-convex8 bench pairs: the final
/// simplex's hull points are all in it from iteration 2.1 on average, of 12.5). A face step needs no curvature;
/// an edge or vertex step uses lb of the feature's own point, and kNewtonSwitch and the shrink / halving tests
/// refuse a step whose linearisation is off, as before. Measured (close witness double ellipsoid-convex8, mean
/// iterations, 20000 bench pairs): 12.55 -> 11.52, err_max 9.88e-9 -> 9.86e-9; distant unchanged (lb > 0 there
/// from the first iterations). Overlapping pairs at the penetration level (lb < 0 until GJK proves the overlap)
/// now take feature steps too: overlap penetration ellipsoid-convex8 (5000 bench pairs) 23.84 -> 24.06 mean
/// iterations, err_max 9.72e-9 -> 9.81e-9 (within the 1e-8 tolerance; keeping the lb > 0 gate for penetration
/// lanes is untried); capsule- and box-ellipsoid unchanged (1.17 / 20.36). Near lb = 0 the vertex step's
/// H + lb I is near singular along n (the ellipsoid's Hessian has n in its kernel): kNewtonSwitch and the
/// halving test refuse the resulting step. A gate lb > -c |x| instead (c = 0.5 / 2, scalar reference, 2000 pairs): 11.64 /
/// 11.48 against 11.41 without.
constexpr int flat_newton_side(ShapeType a, ShapeType b) {
  return polytope_core(a) && b == ShapeType::ellipsoid ? 1 : polytope_core(b) && a == ShapeType::ellipsoid ? 2 : 0;
}

/// Pair types whose distance / witness lanes take Newton search directions (wide_gjk.inl): an ellipsoid (curved in
/// every direction: its Hessian is definite on the tangent plane) against an ellipsoid, a sphere, a cylinder or a
/// cone. Against a flat face, edge or segment (box, hull, triangle, capsule core) the optimal direction is the
/// face's and the other support jumps between vertices, which the Hessians do not see: there the Newton step is
/// mostly refused and only costs its computation. Measured, instructions per pair (callgrind, AVX2, close witness):
/// ellipsoid-ellipsoid 14572 -> 6848, cylinder-ellipsoid 12316 -> 10417, but box-ellipsoid 9764 -> 10397,
/// cylinder-cylinder 9765 -> 11042, box-cylinder 7357 -> 8751 with every curved pair type enabled.
/// A polytope against a curved core (flat_newton_side()) takes them too, with the residual taken from the feature of
/// the polytope that the simplex holds instead of the raw support point (wide_gjk.inl's feature_direction()).
/// Not cylinder / cone against cylinder / cone (measured at 24fd1aa, branch feat): with them on, close witness
/// double mean iterations fell (cylinder-cylinder 18.61 -> 17.03, cylinder-cone 17.41 -> 16.31, cone-cone
/// 15.48 -> 14.80; err_max not worse) but AVX2 instructions per pair rose (8291 -> 8757, 7813 -> 8432,
/// 7044 -> 7688). By the final normal (scalar reference, 2000 pairs), cylinder-cylinder pairs whose optimum is on
/// both rims (13%) went 25.9 -> 13.6 iterations; the rest did not move: a side line (55% of the pairs, 20
/// iterations: the support flips between the rims, which no Hessian sees) or a cap. Treating a side whose simplex
/// points lie on both rims as an edge along the axis (feature_direction()'s edge step, only while |<n, axis>| <
/// 0.05) took cylinder-cylinder to 15.4 and cylinder-ellipsoid 15.8 -> 14.8 in that scalar test, side-line pairs
/// only to ~16-18: the simplex still holds rim points of earlier directions, so GJK needs fresh points on both
/// rims at the final angle. Not built in the wide kernel (estimate only: 3 iterations x ~420 loop instructions is
/// about what the Newton calls cost per pair in the measured build, ~1100, before the side test's own cost).
constexpr bool newton_pair_type(ShapeType a, ShapeType b) {
  const auto round = [](ShapeType t) {
    return t == ShapeType::ellipsoid || t == ShapeType::sphere || t == ShapeType::cylinder || t == ShapeType::cone;
  };
  return (a == ShapeType::ellipsoid && round(b)) || (b == ShapeType::ellipsoid && round(a)) ||
         flat_newton_side(a, b) != 0;
}

/// Newton search directions (distance / witness queries on curved cores, wide_gjk.inl): a Newton step is taken
/// only when it turns the direction by at most this much (|delta|, the tangent of the turn); 0.5 (27 degrees) and
/// 0.25 or 1 gave the same mean iterations on the close ellipsoid pairs (8.99 / 9.01 / 8.99), 0.25 slightly fewer
/// on cylinder-ellipsoid (15.05 vs 15.19).
constexpr double kNewtonSwitch = 0.5;
/// ... and only while the certified gap |x| - lower bound is above this fraction of the tolerance; below it the
/// next step is plain GJK's, along x, whose duality gap certifies the witness. The plain step at x needs x's
/// direction right, not only |x|: |x - x*|^2 <= |x|^2 - dist^2, so its angle error ~ sqrt(2 gap / dist) is
/// amplified by the curvature on close pairs; 0.01 took 8.58 mean iterations on close ellipsoids, 1 took 8.99.
constexpr double kNewtonPlainGap = 0.01;

/// Cylinder / capsule pairs (at least one cylinder; capsule-capsule is a closed form) whose distance / witness lanes
/// start from the closed-form side contact (wide_gjk.inl's side_start()).
constexpr bool side_start_pair(ShapeType a, ShapeType b) {
  const bool axial_a = a == ShapeType::cylinder || a == ShapeType::capsule;
  const bool axial_b = b == ShapeType::cylinder || b == ShapeType::capsule;
  return axial_a && axial_b && (a == ShapeType::cylinder || b == ShapeType::cylinder);
}

/// Cores with a rim (a circle on the boundary: a cylinder's two, a cone's base) and cores with a lateral surface
/// along their axis (a cylinder's side, a cone's slant, a capsule core's segment as a side of radius 0).
constexpr bool rim_core(ShapeType t) { return t == ShapeType::cylinder || t == ShapeType::cone; }
constexpr bool lateral_core(ShapeType t) { return rim_core(t) || t == ShapeType::capsule; }
/// Pair types whose double distance / witness lanes may start from a rim-lateral contact point (wide_gjk.inl's
/// rim_candidate()): a rim of one core against the lateral surface of the other.
constexpr bool rim_start_pair(ShapeType a, ShapeType b) {
  return (rim_core(a) && lateral_core(b)) || (rim_core(b) && lateral_core(a));
}
/// Newton steps on the rim angle per rim-lateral candidate (mean iterations, close witness double cylinder-cylinder,
/// 20000 pairs, without rim starts 17.70: 1 step 11.15, 2 steps 8.96, 3 steps 8.22).
constexpr int kRimNewtonSteps = 3;
/// Newton steps on X's rim angle per rim-rim candidate (wide_gjk_rim_rim.inl's rim_rim(), from the best of
/// kEdgeRimSamples angles). Close witness double (20000 pairs, the scalar reference): 3 -> 4 steps took
/// cylinder-cylinder 1.3018 -> 1.2442 mean iterations, cylinder-cone 1.2277 -> 1.1883 (rim-rim contacts left
/// unfound after 3 steps take 17-25 iterations); distant pairs unchanged (1.047, 1.018).
constexpr int kRimRimNewtonSteps = 4;
/// Pair types whose double distance / witness lanes may start from a box-ellipsoid closed-form point
/// (kernels/simd/wide_gjk_box_ellipsoid.inl): the nearest box face, edge or vertex against the ellipsoid; a
/// capsule's core is a box with two zero extents (its segment), a sphere's a box with three (its centre).
constexpr bool box_ellipsoid_pair(ShapeType a, ShapeType b) {
  const auto flat = [](ShapeType t) { return t == ShapeType::box || t == ShapeType::capsule || t == ShapeType::sphere; };
  return (flat(a) && b == ShapeType::ellipsoid) || (a == ShapeType::ellipsoid && flat(b));
}
/// Pair types whose double distance / witness lanes may start from a box-cylinder or box-cone closed-form point
/// (kernels/simd/wide_gjk_box_round.inl): a box face, edge or vertex against the round core's rim, side or apex.
constexpr bool box_round_pair(ShapeType a, ShapeType b) {
  const auto round = [](ShapeType t) { return t == ShapeType::cylinder || t == ShapeType::cone; };
  return (a == ShapeType::box && round(b)) || (round(a) && b == ShapeType::box);
}
/// Box edge vs rim (wide_gjk_box_round.inl's edge_rim()): the rim angle starts at the best of kEdgeRimSamples
/// angles j pi / 6 (cos, sin of the first half; the second half is their negation), then kEdgeRimNewtonSteps Newton
/// steps. Edge-rim contacts of close box-cylinder pairs (5092 of 20000) found to 1e-8 with 3 steps from
/// rim_lateral()'s start (the line's point nearest to the rim's centre): 2991; from the best of 8 / 12 / 16 samples:
/// 4515 / 4789 / 4928 (the squared distance to the line has two minima on the circle; Newton from a poor start finds
/// the far one).
constexpr int kEdgeRimSamples = 12;
constexpr double kEdgeRimCos[kEdgeRimSamples / 2] = {1.0, 0.8660254037844387, 0.5, 0.0, -0.5, -0.8660254037844387};
constexpr double kEdgeRimSin[kEdgeRimSamples / 2] = {0.0, 0.5, 0.8660254037844387, 1.0, 0.8660254037844387, 0.5};
constexpr int kEdgeRimNewtonSteps = 3;
/// The core box_ellipsoid_point() takes: the box, a capsule's segment, a sphere's point.
constexpr int kBoxCore = 0, kSegmentCore = 1, kPointCore = 2;
/// Pair types whose double distance / witness lanes may start from a cylinder- or cone-ellipsoid Newton point
/// (kernels/simd/wide_gjk_round_ellipsoid.inl): the round core's cap, rim, apex, side or slant against the ellipsoid.
constexpr bool round_ellipsoid_pair(ShapeType a, ShapeType b) {
  const auto round = [](ShapeType t) { return t == ShapeType::cylinder || t == ShapeType::cone; };
  return (round(a) && b == ShapeType::ellipsoid) || (a == ShapeType::ellipsoid && round(b));
}
/// Newton steps on the contact normal against a rim or the cone's apex (disk_ellipsoid()) and on the normal's angle
/// against a cylinder's side or a cone's slant (side_ellipsoid()).
constexpr int kRoundEllipsoidNewtonSteps = 3;
constexpr int kRoundEllipsoidSideSteps = 3;
/// Pair types with any closed-form start candidate (start() takes the lane's rim_a / rim_b).
constexpr bool start_candidate_pair(ShapeType a, ShapeType b) {
  return rim_start_pair(a, b) || box_ellipsoid_pair(a, b) || box_round_pair(a, b) || round_ellipsoid_pair(a, b);
}
/// A sphere against a convex hull, either order: double distance and witness lanes start from the sphere centre's
/// nearest point on the hull's most separating face (kernels/simd/wide_gjk_point_hull.inl) where the hull has at
/// most kPointHullMaxFaces faces and the centre is near (kPointHullNearRadii). Each lane's face loop is scalar code
/// over its own hull's rows: the first form gathered them, slow on this Xeon (the Gather Data Sampling microcode, an
/// inference). Close sphere-convex8 witness double (bench, 2 threads, AVX-512) ~134 -> ~105 ns per pair, distant ~87
/// -> ~92. Boolean lanes keep the first support point (gathered form: double 983 -> 868 callgrind instructions but
/// 54.4 -> 61.1 ns; not re-measured with the scalar loop). Not float: 779 -> 947 instructions (boolean, gathered).
constexpr bool point_hull_pair(ShapeType a, ShapeType b) {
  return (a == ShapeType::sphere && b == ShapeType::convex) || (a == ShapeType::convex && b == ShapeType::sphere);
}
/// The face loop reads one plane per face and lane: bounded to hulls of up to 10 vertices (2 V - 4 triangles), which
/// is what was measured (convex8, 12 faces); larger hulls keep GJK's first support point.
constexpr std::uint32_t kPointHullMaxFaces = 16;
/// Sphere centres farther than this many hull radii from the hull's centroid keep GJK's first support point: far
/// away it is nearly as good (distant sphere-convex8 pairs: 1.31 GJK iterations without the candidate, 1.03 with
/// it), and the candidate's face loop cost more wall time than that saves.
constexpr double kPointHullNearRadii = 2.0;
/// Newton steps on the edge angle and on the vertex's Lagrange multiplier (box_ellipsoid_point()).
constexpr int kBoxEdgeNewtonSteps = 3;
constexpr int kBoxVertexNewtonSteps = 3;
/// A sphere's or capsule's start is the vertex alone (or nearly): more steps there, where they are the whole cost.
constexpr int kPointVertexNewtonSteps = 6;
constexpr int vertex_newton_steps(int core) { return core == kBoxCore ? kBoxVertexNewtonSteps : kPointVertexNewtonSteps; }

}  // namespace batchcol::kernels
