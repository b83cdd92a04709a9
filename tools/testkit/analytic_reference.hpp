// Closed-form references of `batchcol accuracy` and the tests, written from the shape definitions independently
// of the engine's own analytic kernels (kernels/closed_forms.hpp), so that each checks the other:
//   - a point against a sphere, capsule, box, cylinder or cone: the nearest point of the solid, found in the
//     meridian plane for the solids of revolution (the nearest point of a body of revolution lies in the plane
//     through its axis and the query point); inside the solid, the nearest boundary point is the foot on the
//     nearest face (for a convex body, the distance to the boundary is the smallest distance to a face plane);
//   - sphere against any of those (the point's result shifted by the radius), and capsule against capsule (closest
//     points of two segments, the minimum of a convex quadratic over the unit square).
// Inflation is included: the signed distance to X + ball(r) is the signed distance to X minus r.
#pragma once

#include "testkit/reference_set.hpp"

#include <batchcol/pose.hpp>
#include <batchcol/shapes.hpp>

#include <optional>

namespace batchcol::testkit {

/// Signed distance from a point to a solid, the nearest boundary point and the outward unit normal there.
struct BoundaryPoint {
  double signed_distance = 0;  // negative inside
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};

/// `p` in the shape's local frame. Empty for shape types without a closed form here, or when the point is within
/// 1e-9 m of a sphere's centre or a capsule's axis (the normal is undefined there).
std::optional<BoundaryPoint> point_to_shape(const Shape& shape, const Eigen::Vector3d& p);

/// Closest points of the segments [p0, p1] and [q0, q1].
void closest_points_of_segments(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& q0,
                                 const Eigen::Vector3d& q1, Eigen::Vector3d& on_p, Eigen::Vector3d& on_q);

/// The analytic reference of a pair (world frame), or empty when the pair has no closed form here.
std::optional<ReferencePair> analytic_reference(const Shape& a, const Pose& pose_a, const Shape& b,
                                                const Pose& pose_b);

/// True when analytic_reference covers this type pair (in either order).
bool has_closed_form(ShapeType a, ShapeType b);

}  // namespace batchcol::testkit
