// batchcol shapes and poses through FCL (0.7). The header is FCL-free so the test compiles without the package.
//
// FCL's public fcl::collide / fcl::distance do not accept its TriangleP geometry, so pairs with a triangle go
// through the narrow-phase solver's shapeTriangleIntersect / shapeTriangleDistance (triangle against triangle:
// one of them as a flat fcl::Convex). FCL computes no distance to a halfspace (fcl::distance would call a null
// support function), so fcl_distance reports ok = false for halfspace pairs; fcl_collide handles them with its
// analytic halfspace tests and returns their exact penetration depth.
#pragma once

#include "batchcol/batchcol.hpp"
#include "peers/peer_answer.hpp"

#include <cstdint>
#include <memory>

namespace batchcol::peers {

enum class FclSolver { libccd, indep };
const char* to_string(FclSolver solver);

/// fcl::collide: the boolean, plus (with `want_depth`) the signed distance -penetration_depth of the first contact.
PeerAnswer fcl_collide(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, FclSolver solver,
                       bool want_depth);

/// fcl::distance with enable_signed_distance and enable_nearest_points; `tolerance` is distance_tolerance
/// (the GJK stopping threshold of both solvers). For overlapping pairs libccd returns its EPA depth; the
/// independent solver computes no signed distance.
PeerAnswer fcl_distance(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, FclSolver solver,
                        double tolerance);

/// FCL geometries built once per shape of a table, so that timing loops measure the queries and not the geometry
/// construction of fcl_collide / fcl_distance (which build both geometries on every call). Same answers as those
/// functions; the queries are const and may run concurrently (FCL only reads the geometries).
class FclShapeCache {
 public:
  explicit FclShapeCache(const ShapeTable& shapes);
  ~FclShapeCache();
  FclShapeCache(const FclShapeCache&) = delete;
  FclShapeCache& operator=(const FclShapeCache&) = delete;

  PeerAnswer collide(std::uint32_t a, const Pose& pa, std::uint32_t b, const Pose& pb, FclSolver solver) const;
  PeerAnswer distance(std::uint32_t a, const Pose& pa, std::uint32_t b, const Pose& pb, FclSolver solver,
                      double tolerance) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace batchcol::peers
