// Independent checks of a pair's signed distance, computed from the shape definitions (testing::extent and the
// membership tests below), never from the kernels. They settle disagreements between batchcol and a peer:
//   lower bound: for any unit direction n, sd >= min_{y in b} <n, y> - max_{x in a} <n, x> (equality at the optimal
//                n; this holds for overlapping pairs too, where -sd is the penetration depth);
//   upper bound: for separated pairs, sd <= |q - p| for any p in a and q in b;
//   overlap:     a point in both shapes proves sd <= 0.
#pragma once

#include "batchcol/batchcol.hpp"

namespace batchcol::crosscheck {

/// max_{x in s} <n, x> for a world direction n (bounded shapes).
double world_extent(const Shape& s, const Pose& p, const Eigen::Vector3d& n);

/// A halfspace solid in the world frame: {x : <normal, x> <= offset}.
struct WorldPlane {
  Eigen::Vector3d normal;
  double offset;
};
WorldPlane world_plane(const Shape& halfspace, const Pose& p);

/// Exact signed distance between a halfspace solid and a bounded shape: min_{x in s} <normal, x> - offset.
double halfspace_signed_distance(const WorldPlane& plane, const Shape& s, const Pose& p);

/// The lower bound above for direction n (any length > 0; normalised here). Exact for pairs with a halfspace.
double certified_lower_bound(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Eigen::Vector3d n);

/// The largest certified_lower_bound found by a compass search over unit directions started at n (step 1e-3
/// down to 1e-13 rad, at most `evaluations` evaluations). Any value it returns is a valid lower bound; it tightens
/// the bound when n is close to, but not exactly, the optimal direction.
double refined_lower_bound(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Eigen::Vector3d n,
                           int evaluations = 600);

/// Signed distance from world point x to the shape's boundary, positive outside. Outside it is exact, except for
/// the ellipsoid, where it is the distance along the ray from the centre (an upper bound, exact on the surface);
/// either way dist(x, shape) <= value. Inside it is a lower bound on the depth (exact for sphere, capsule, box,
/// cylinder, polytope and halfspace), so a negative value -r certifies that the ball of radius r around x is
/// inside the shape. Triangles are flat: never negative. Inflation is ignored (the cross-checks use none).
double signed_outside(const Shape& s, const Pose& p, const Eigen::Vector3d& x);

/// Two triangles whose edges cross each other's interior (by more than rounding): they overlap. Flat shapes have
/// no interior point, so proves_overlap cannot show it.
bool triangles_cross(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb);

/// x proves that the shapes overlap: x is within delta of one shape and deeper than delta inside the other, so the
/// nearest point of the first shape is an interior point of the second.
bool proves_overlap(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, const Eigen::Vector3d& x);

}  // namespace batchcol::crosscheck
