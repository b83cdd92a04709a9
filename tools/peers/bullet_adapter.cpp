#include "peers/bullet_adapter.hpp"

#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletCollision/CollisionShapes/btCapsuleShape.h>
#include <BulletCollision/CollisionShapes/btConeShape.h>
#include <BulletCollision/CollisionShapes/btConvexHullShape.h>
#include <BulletCollision/CollisionShapes/btCylinderShape.h>
#include <BulletCollision/CollisionShapes/btSphereShape.h>
#include <BulletCollision/CollisionShapes/btTriangleShape.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpa2.h>

#include <memory>
#include <stdexcept>
#include <vector>

namespace batchcol::peers {
namespace {

btVector3 to_bt(const Eigen::Vector3d& v) { return {btScalar(v.x()), btScalar(v.y()), btScalar(v.z())}; }
Eigen::Vector3d from_bt(const btVector3& v) { return {double(v.x()), double(v.y()), double(v.z())}; }

btTransform to_bt(const Pose& p) {
  const Eigen::Quaterniond& q = p.rotation;  // btQuaternion takes (x, y, z, w)
  return btTransform(btQuaternion(btScalar(q.x()), btScalar(q.y()), btScalar(q.z()), btScalar(q.w())),
                     to_bt(p.translation));
}

std::unique_ptr<btConvexShape> make_core(const Shape& s) {
  const Eigen::Vector3d& z = s.size;
  switch (s.type) {
    case ShapeType::sphere: return std::make_unique<btSphereShape>(btScalar(z.x()));
    case ShapeType::capsule: return std::make_unique<btCapsuleShapeZ>(btScalar(z.x()), btScalar(2 * z.y()));
    case ShapeType::box: return std::make_unique<btBoxShape>(to_bt(z));
    case ShapeType::cylinder: return std::make_unique<btCylinderShapeZ>(to_bt({z.x(), z.x(), z.y()}));
    case ShapeType::cone: return std::make_unique<btConeShapeZ>(btScalar(z.x()), btScalar(2 * z.y()));
    case ShapeType::convex: {
      auto hull = std::make_unique<btConvexHullShape>();
      for (const auto& v : s.hull->vertices) hull->addPoint(to_bt(v), false);
      hull->recalcLocalAabb();
      return hull;
    }
    case ShapeType::triangle:
      return std::make_unique<btTriangleShape>(to_bt(s.triangle[0]), to_bt(s.triangle[1]), to_bt(s.triangle[2]));
    case ShapeType::ellipsoid:
    case ShapeType::halfspace: break;
  }
  throw std::invalid_argument("Bullet adapter: unsupported shape type");
}

std::unique_ptr<btConvexShape> make_shape(const Shape& s) {
  if (s.inflation != 0.0) throw std::invalid_argument("Bullet adapter: inflated shapes are not supported");
  auto shape = make_core(s);
  shape->setMargin(0);  // no-op for spheres and capsules, whose margin is their radius
  return shape;
}

PeerAnswer signed_distance(const btConvexShape* sa, const Pose& pa, const btConvexShape* sb, const Pose& pb) {
  PeerAnswer out;
  btGjkEpaSolver2::sResults r;
  const btVector3 guess = to_bt(pa.translation - pb.translation);
  if (!btGjkEpaSolver2::SignedDistance(sa, to_bt(pa), sb, to_bt(pb), guess, r)) return out;
  // Core result: witnesses[1] - witnesses[0] = core_distance * n (n from a to b) in both outcomes.
  const double core = double(r.distance);  // > 0 from Distance, -depth from Penetration
  Eigen::Vector3d wa = from_bt(r.witnesses[0]), wb = from_bt(r.witnesses[1]);
  const Eigen::Vector3d delta = wb - wa;
  if (delta.norm() == 0.0) return out;  // touching cores: no direction to add the margins along
  const Eigen::Vector3d n = core < 0 ? Eigen::Vector3d(-delta.normalized()) : Eigen::Vector3d(delta.normalized());
  const double ma = double(sa->getMargin()), mb = double(sb->getMargin());
  out.point_a = wa + ma * n;
  out.point_b = wb - mb * n;
  out.distance = core - ma - mb;
  out.collide = out.distance <= 0;
  out.ok = true;
  return out;
}

}  // namespace

bool bullet_supports(ShapeType type) { return type != ShapeType::ellipsoid && type != ShapeType::halfspace; }

bool bullet_double_precision() { return sizeof(btScalar) == sizeof(double); }

double bullet_extent(const Shape& s, const Eigen::Vector3d& d) {
  const auto shape = make_shape(s);
  const btVector3 dir = to_bt(d);
  return double(shape->localGetSupportingVertexWithoutMargin(dir).dot(dir)) +
         double(shape->getMargin()) * d.norm();
}

PeerAnswer bullet_signed_distance(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
  if (!bullet_supports(a.type) || !bullet_supports(b.type)) return {};
  const auto sa = make_shape(a), sb = make_shape(b);
  return signed_distance(sa.get(), pa, sb.get(), pb);
}

struct BulletShapeCache::Impl {
  std::vector<std::unique_ptr<btConvexShape>> shapes;  // null for unsupported types
};

BulletShapeCache::BulletShapeCache(const ShapeTable& shapes) : impl_(std::make_unique<Impl>()) {
  for (const Shape& s : shapes.shapes()) {
    impl_->shapes.push_back(bullet_supports(s.type) && s.inflation == 0.0 ? make_shape(s) : nullptr);
  }
}

BulletShapeCache::~BulletShapeCache() = default;

PeerAnswer BulletShapeCache::signed_distance(std::uint32_t a, const Pose& pa, std::uint32_t b, const Pose& pb) const {
  const btConvexShape *sa = impl_->shapes.at(a).get(), *sb = impl_->shapes.at(b).get();
  if (!sa || !sb) return {};
  return peers::signed_distance(sa, pa, sb, pb);
}

}  // namespace batchcol::peers
