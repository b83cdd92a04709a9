// batchcol shapes and poses through Coal (formerly HPP-FCL), built from source by ../shared/peers/build-coal.sh.
// The header is Coal-free so consumers compile without the library.
//
// Two ways into Coal, both on geometries built once per shape (CoalShapeCache):
// - its public queries, coal::collide and coal::distance (signed distance; Coal always computes nearest points);
// - GJK called directly, as coal::GJKSolver::runGJKAndEPA does it but without the request/result/solver objects
//   and the collide/distance function tables: a coal::details::MinkowskiDiff set from the two shapes and poses,
//   then coal::details::GJK::evaluate from Coal's default guess (1, 0, 0). For booleans GJK stops as soon as a
//   support point proves separation (setDistanceEarlyBreak(0)); for distances early break is disabled and the
//   witness points are read from the final simplex. That is what a user after Coal's best speed calls.
//
// Shapes: every bounded type maps to a Coal shape of the same conventions (Box takes full sides, Capsule, Cylinder
// and Cone full lengths, the cone's apex at +lz/2 as batchcol's; convex hulls become coal::Convex<Triangle> from the
// hull's vertices and faces, so Coal builds its vertex adjacency and hill-climbs on large hulls). Triangles become
// coal::TriangleP, halfspaces coal::Halfspace (coal::collide / coal::distance only: a halfspace has no bounded
// support, so the direct GJK answers ok = false). Inflation maps to Coal's swept-sphere radius
// (ShapeBase::setSweptSphereRadius), the same Minkowski sum with a ball, on every type including halfspaces.
#pragma once

#include "batchcol/batchcol.hpp"
#include "peers/peer_answer.hpp"

#include <cstdint>
#include <memory>

namespace batchcol::peers {

enum class CoalGjkVariant { plain, nesterov };
const char* to_string(CoalGjkVariant variant);

/// coal::collide with a boolean CollisionRequest(NO_REQUEST, 1) and distance_upper_bound = 0, Coal's documented
/// early stop (GJK tolerance 1e-6, no security margin); geometries built per call.
PeerAnswer coal_collide(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb);

/// coal::distance with enable_signed_distance, gjk_tolerance = `tolerance` and epa_tolerance = max(`tolerance`, 1e-6)
/// (Coal's EPA_MINIMUM_TOLERANCE: below it Coal's EPA gives centimetre errors on curved shapes); geometries built per
/// call. Overlapping pairs get Coal's EPA depth as a negative distance. Pairs with a triangle, which coal::distance
/// does not accept, go through GJKSolver::shapeDistance (the same GJK + EPA).
PeerAnswer coal_distance(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double tolerance);

/// The direct GJK of CoalShapeCache::gjk_collide / gjk_distance on geometries built per call.
PeerAnswer coal_gjk_collide(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, CoalGjkVariant variant);
PeerAnswer coal_gjk_distance(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, CoalGjkVariant variant,
                             double tolerance, bool want_depth);

/// max <x, d> over the Coal shape built for s (swept-sphere radius included), in s's local frame: checks that the
/// adapter's shapes are batchcol's shapes.
double coal_extent(const Shape& s, const Eigen::Vector3d& d);

/// Coal geometries built once per shape of a table, so that timing loops measure the queries and not geometry
/// construction. The queries are const and may run concurrently: Coal only reads the shapes, and each call owns
/// its request, solver (or GJK/EPA) and Minkowski difference.
class CoalShapeCache {
 public:
  explicit CoalShapeCache(const ShapeTable& shapes);
  ~CoalShapeCache();
  CoalShapeCache(const CoalShapeCache&) = delete;
  CoalShapeCache& operator=(const CoalShapeCache&) = delete;

  /// Same answers as coal_collide / coal_distance.
  PeerAnswer collide(std::uint32_t a, const Pose& pa, std::uint32_t b, const Pose& pb) const;
  PeerAnswer distance(std::uint32_t a, const Pose& pa, std::uint32_t b, const Pose& pb, double tolerance) const;

  /// Direct GJK, boolean: early break at 0, Coal's default tolerance (1e-6) and iteration cap (128).
  /// collide is GJK's Collision / CollisionWithPenetrationInformation status; a run out of iterations is ok = false.
  PeerAnswer gjk_collide(std::uint32_t a, const Pose& pa, std::uint32_t b, const Pose& pb,
                         CoalGjkVariant variant) const;

  /// Direct GJK, distance: no early break, GJK tolerance `tolerance`, witness points from the final simplex (moved
  /// out by the swept-sphere radii and re-centred on their midpoint as Coal's GJKSolver does). When GJK finds the
  /// origin inside the Minkowski difference: with `want_depth`, coal::details::EPA (tolerance max(`tolerance`, 1e-6),
  /// Coal's default iteration cap) gives the depth as coal::distance would; without it the answer is the boolean only
  /// (collide = true, distance NaN), as batchcol answers below the penetration level.
  PeerAnswer gjk_distance(std::uint32_t a, const Pose& pa, std::uint32_t b, const Pose& pb, CoalGjkVariant variant,
                          double tolerance, bool want_depth) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace batchcol::peers
