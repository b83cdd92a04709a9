// batchcol shapes and poses through Bullet's GJK/EPA (btGjkEpaSolver2). The header is Bullet-free so the test
// compiles without the package.
//
// Margins: every shape gets setMargin(0). Box and cylinder keep their full extents through that call (their
// setMargin moves the margin back into the implicit dimensions). Spheres and capsules ignore it: Bullet stores
// them as a point / segment whose margin is the radius, and btGjkEpaSolver2 works without margins, so the adapter
// subtracts both margins from the core signed distance (the signed distance of Minkowski sums with balls is the
// core signed distance minus the radii, for separated and overlapping cores alike) and moves the witness points
// out by their margin along the normal. btConeShapeZ is centred on its axis midpoint with the apex at +height/2,
// exactly like batchcol's cone (checked by the support test), so no offset is needed.
#pragma once

#include "batchcol/batchcol.hpp"
#include "peers/peer_answer.hpp"

#include <cstdint>
#include <memory>

namespace batchcol::peers {

/// Shape types with a Bullet convex counterpart (no ellipsoid; halfspaces are concave btStaticPlaneShapes).
bool bullet_supports(ShapeType type);

/// btGjkEpaSolver2::SignedDistance: distance by GJK, depth by EPA, witness points and collide.
PeerAnswer bullet_signed_distance(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb);

/// max <x, d> over the Bullet shape built for s (margin included), in s's local frame.
double bullet_extent(const Shape& s, const Eigen::Vector3d& d);

/// true when the library was built with BT_USE_DOUBLE_PRECISION.
bool bullet_double_precision();

/// Bullet shapes built once per shape of a table (unsupported types stay empty and answer ok = false), so that
/// timing loops measure btGjkEpaSolver2 and not shape construction. Same answers as bullet_signed_distance; the
/// query is const and may run concurrently.
class BulletShapeCache {
 public:
  explicit BulletShapeCache(const ShapeTable& shapes);
  ~BulletShapeCache();
  BulletShapeCache(const BulletShapeCache&) = delete;
  BulletShapeCache& operator=(const BulletShapeCache&) = delete;

  PeerAnswer signed_distance(std::uint32_t a, const Pose& pa, std::uint32_t b, const Pose& pb) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace batchcol::peers
