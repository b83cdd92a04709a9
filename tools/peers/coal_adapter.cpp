#include "peers/coal_adapter.hpp"

#include <coal/collision.h>
#include <coal/distance.h>
#include <coal/narrowphase/narrowphase.h>
#include <coal/narrowphase/gjk.h>
#include <coal/narrowphase/minkowski_difference.h>
#include <coal/narrowphase/narrowphase_defaults.h>
#include <coal/shape/convex.h>
#include <coal/shape/geometric_shapes.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <stdexcept>
#include <vector>

namespace batchcol::peers {
namespace {

coal::Transform3s to_coal(const Pose& p) {
  return coal::Transform3s(p.rotation.toRotationMatrix(), p.translation);
}

std::shared_ptr<coal::ShapeBase> make_core(const Shape& s) {
  const Eigen::Vector3d& z = s.size;
  switch (s.type) {
    case ShapeType::sphere: return std::make_shared<coal::Sphere>(z.x());
    case ShapeType::capsule: return std::make_shared<coal::Capsule>(z.x(), 2 * z.y());
    case ShapeType::box: return std::make_shared<coal::Box>(coal::Vec3s(2 * z));
    case ShapeType::cylinder: return std::make_shared<coal::Cylinder>(z.x(), 2 * z.y());
    case ShapeType::cone: return std::make_shared<coal::Cone>(z.x(), 2 * z.y());
    case ShapeType::ellipsoid: return std::make_shared<coal::Ellipsoid>(z.x(), z.y(), z.z());
    case ShapeType::convex: {
      const ConvexHull& h = *s.hull;
      auto points = std::make_shared<std::vector<coal::Vec3s>>(h.vertices.begin(), h.vertices.end());
      auto faces = std::make_shared<std::vector<coal::Triangle>>();
      faces->reserve(h.faces.size());
      for (const auto& f : h.faces) faces->emplace_back(f[0], f[1], f[2]);
      return std::make_shared<coal::Convex<coal::Triangle>>(points, static_cast<unsigned>(points->size()), faces,
                                                            static_cast<unsigned>(faces->size()));
    }
    case ShapeType::triangle: return std::make_shared<coal::TriangleP>(s.triangle[0], s.triangle[1], s.triangle[2]);
    case ShapeType::halfspace: return std::make_shared<coal::Halfspace>(coal::Vec3s(z), s.offset);
  }
  throw std::invalid_argument("Coal adapter: unknown shape type");
}

std::shared_ptr<coal::ShapeBase> make_shape(const Shape& s) {
  auto shape = make_core(s);
  if (s.inflation > 0.0) shape->setSweptSphereRadius(s.inflation);
  shape->computeLocalAABB();  // as coal::CollisionObject does; only read by Coal's bounding-volume guess
  return shape;
}

/// Coal documents 1e-6 as its EPA's minimum tolerance (EPA_MINIMUM_TOLERANCE). Below it EPA runs out of its 64
/// iterations on curved shapes and returns depths off by centimetres: measured by the cross-check at 1e-10, proven
/// wrong on 1-15% of the overlapping pairs per type, against 0-1.7% at 1e-6 (median error there ~2e-6 m).
double epa_tolerance(double tolerance) { return std::max(tolerance, coal::EPA_MINIMUM_TOLERANCE); }

PeerAnswer geometry_collide(const coal::ShapeBase& ga, const Pose& pa, const coal::ShapeBase& gb, const Pose& pb) {
  PeerAnswer out;
  try {
    // A boolean request: no contact information (so no EPA), one contact, no security margin, GJK tolerance 1e-6,
    // and GJK's early break at 0: the default request (enable_contact, distance_upper_bound = max) runs GJK to
    // convergence and EPA on overlapping pairs, which a boolean does not need.
    coal::CollisionRequest request(coal::NO_REQUEST, 1);
    request.distance_upper_bound = 0;
    coal::CollisionResult result;
    coal::collide(&ga, to_coal(pa), &gb, to_coal(pb), request, result);
    out.collide = result.isCollision();
    out.ok = true;
  } catch (const std::exception&) {
    out.ok = false;
  }
  return out;
}

PeerAnswer geometry_distance(const coal::ShapeBase& ga, const Pose& pa, const coal::ShapeBase& gb, const Pose& pb,
                             double tolerance) {
  PeerAnswer out;
  try {
    coal::DistanceRequest request;  // nearest points and signed distance are on by default
    request.enable_signed_distance = true;
    request.gjk_tolerance = tolerance;
    request.epa_tolerance = epa_tolerance(tolerance);
    if (ga.getNodeType() == coal::GEOM_TRIANGLE || gb.getNodeType() == coal::GEOM_TRIANGLE) {
      // coal::distance has no TriangleP entry (its table throws "not yet supported"): Coal's narrow phase, the
      // GJK + EPA every other GJK pair of coal::distance runs, called through GJKSolver::shapeDistance.
      const coal::GJKSolver solver(request);
      coal::Vec3s normal;
      out.distance = solver.shapeDistance(ga, to_coal(pa), gb, to_coal(pb), true, out.point_a, out.point_b, normal);
    } else {
      coal::DistanceResult result;
      out.distance = coal::distance(&ga, to_coal(pa), &gb, to_coal(pb), request, result);
      out.point_a = result.nearest_points[0];
      out.point_b = result.nearest_points[1];
    }
    out.collide = out.distance <= 0;
    // A failed EPA (statuses DidNotRun / FallBack) reports -max(): no answer.
    out.ok = std::isfinite(out.distance) && out.distance > -std::numeric_limits<double>::max();
  } catch (const std::exception&) {
    out.ok = false;
  }
  return out;
}

/// One direct GJK run, set up as coal::GJKSolver::runGJKAndEPA sets it up (same Minkowski difference, convergence
/// criterion, default guess and zero support hint), with `early_break` as the distance upper bound.
struct DirectGjk {
  coal::details::MinkowskiDiff shape;
  coal::details::GJK gjk;
  coal::Transform3s tf_a;
  const coal::Vec3s guess{1, 0, 0};  // GJKInitialGuess::DefaultGuess

  DirectGjk(const coal::ShapeBase& a, const Pose& pa, const coal::ShapeBase& b, const Pose& pb, CoalGjkVariant variant,
            double tolerance, double early_break)
      : gjk(coal::GJK_DEFAULT_MAX_ITERATIONS, tolerance), tf_a(to_coal(pa)) {
    shape.set(&a, &b, tf_a, to_coal(pb));  // also sets the Nesterov normalization heuristic from the shape types
    gjk.setDistanceEarlyBreak(early_break);
    gjk.gjk_variant = variant == CoalGjkVariant::nesterov ? coal::GJKVariant::NesterovAcceleration
                                                          : coal::GJKVariant::DefaultGJK;
    gjk.convergence_criterion = coal::GJKConvergenceCriterion::Default;
    gjk.convergence_criterion_type = coal::GJKConvergenceCriterionType::Absolute;
    gjk.evaluate(shape, guess, coal::support_func_guess_t::Zero());
  }

  /// Witness points in the frame of shape a moved to the world, re-centred on their midpoint along the normal as
  /// GJKSolver's GJKExtractWitnessPointsAndNormal / EPAExtractWitnessPointsAndNormal do.
  void world_witnesses(coal::Vec3s w0, coal::Vec3s w1, const coal::Vec3s& normal, PeerAnswer& out) const {
    const coal::Vec3s mid = tf_a.transform(0.5 * (w0 + w1));
    const coal::Vec3s n = tf_a.getRotation() * normal;
    out.point_a = mid - 0.5 * out.distance * n;
    out.point_b = mid + 0.5 * out.distance * n;
  }
};

bool is_bounded(const coal::ShapeBase& s) { return s.getNodeType() != coal::GEOM_HALFSPACE; }

PeerAnswer direct_collide(const coal::ShapeBase& ga, const Pose& pa, const coal::ShapeBase& gb, const Pose& pb,
                          CoalGjkVariant variant) {
  PeerAnswer out;
  if (!is_bounded(ga) || !is_bounded(gb)) return out;
  try {
    const DirectGjk run(ga, pa, gb, pb, variant, coal::GJK_DEFAULT_TOLERANCE, 0.0);
    using S = coal::details::GJK::Status;
    switch (run.gjk.status) {
      case S::Collision: out.collide = true; break;
      // Converged within GJK's tolerance of contact: Coal's collide then compares the distance with the margin (0).
      case S::CollisionWithPenetrationInformation: out.collide = run.gjk.distance <= 0; break;
      case S::NoCollision:
      case S::NoCollisionEarlyStopped: out.collide = false; break;
      case S::Failed:
      case S::DidNotRun: return out;  // ran out of iterations: no answer
    }
    out.ok = true;
  } catch (const std::exception&) {
    out.ok = false;
  }
  return out;
}

PeerAnswer direct_distance(const coal::ShapeBase& ga, const Pose& pa, const coal::ShapeBase& gb, const Pose& pb,
                           CoalGjkVariant variant, double tolerance, bool want_depth) {
  PeerAnswer out;
  if (!is_bounded(ga) || !is_bounded(gb)) return out;
  try {
    DirectGjk run(ga, pa, gb, pb, variant, tolerance, std::numeric_limits<double>::max());
    coal::Vec3s w0, w1, normal;
    using S = coal::details::GJK::Status;
    switch (run.gjk.status) {
      case S::NoCollision:
      case S::CollisionWithPenetrationInformation:
        out.distance = run.gjk.distance;
        run.gjk.getWitnessPointsAndNormal(run.shape, w0, w1, normal);
        run.world_witnesses(w0, w1, normal, out);
        break;
      case S::Collision: {
        if (!want_depth) {
          out.collide = true;
          out.ok = true;
          return out;
        }
        coal::details::EPA epa(coal::EPA_DEFAULT_MAX_ITERATIONS, epa_tolerance(tolerance));
        epa.evaluate(run.gjk, -run.guess);
        // Coal's runGJKAndEPA reads the depth for every status but these two (no polytope was built).
        if (epa.status == coal::details::EPA::DidNotRun || epa.status == coal::details::EPA::FallBack) return out;
        out.distance = std::min(0.0, -epa.depth);
        if (!(out.distance > -std::numeric_limits<double>::max())) return out;  // no polytope: no depth
        epa.getWitnessPointsAndNormal(run.shape, w0, w1, normal);
        run.world_witnesses(w0, w1, normal, out);
        break;
      }
      case S::NoCollisionEarlyStopped:  // cannot happen without an early break
      case S::Failed:
      case S::DidNotRun: return out;
    }
    out.collide = out.distance <= 0;
    out.ok = std::isfinite(out.distance);
  } catch (const std::exception&) {
    out.ok = false;
  }
  return out;
}

/// Calls f(shape a, shape b) with Coal geometries built for this call; no answer (ok = false) when Coal rejects one.
template <class F> PeerAnswer with_shapes(const Shape& a, const Shape& b, F&& f) {
  std::shared_ptr<coal::ShapeBase> ga, gb;
  try {
    ga = make_shape(a);
    gb = make_shape(b);
  } catch (const std::exception&) {
    return {};
  }
  return f(*ga, *gb);
}

}  // namespace

const char* to_string(CoalGjkVariant variant) { return variant == CoalGjkVariant::nesterov ? "nesterov" : "gjk"; }

PeerAnswer coal_collide(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
  return with_shapes(a, b, [&](const auto& ga, const auto& gb) { return geometry_collide(ga, pa, gb, pb); });
}

PeerAnswer coal_distance(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double tolerance) {
  return with_shapes(a, b, [&](const auto& ga, const auto& gb) { return geometry_distance(ga, pa, gb, pb, tolerance); });
}

PeerAnswer coal_gjk_collide(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, CoalGjkVariant variant) {
  return with_shapes(a, b, [&](const auto& ga, const auto& gb) { return direct_collide(ga, pa, gb, pb, variant); });
}

PeerAnswer coal_gjk_distance(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, CoalGjkVariant variant,
                             double tolerance, bool want_depth) {
  return with_shapes(a, b, [&](const auto& ga, const auto& gb) {
    return direct_distance(ga, pa, gb, pb, variant, tolerance, want_depth);
  });
}

double coal_extent(const Shape& s, const Eigen::Vector3d& d) {
  const auto shape = make_shape(s);
  int hint = 0;
  const coal::Vec3s p =
      coal::details::getSupport<coal::details::SupportOptions::WithSweptSphere>(shape.get(), d, hint);
  return p.dot(d);
}

struct CoalShapeCache::Impl {
  std::vector<std::shared_ptr<coal::ShapeBase>> shapes;
};

CoalShapeCache::CoalShapeCache(const ShapeTable& shapes) : impl_(std::make_unique<Impl>()) {
  for (const Shape& s : shapes.shapes()) impl_->shapes.push_back(make_shape(s));
}

CoalShapeCache::~CoalShapeCache() = default;

PeerAnswer CoalShapeCache::collide(std::uint32_t a, const Pose& pa, std::uint32_t b, const Pose& pb) const {
  return geometry_collide(*impl_->shapes.at(a), pa, *impl_->shapes.at(b), pb);
}

PeerAnswer CoalShapeCache::distance(std::uint32_t a, const Pose& pa, std::uint32_t b, const Pose& pb,
                                    double tolerance) const {
  return geometry_distance(*impl_->shapes.at(a), pa, *impl_->shapes.at(b), pb, tolerance);
}

PeerAnswer CoalShapeCache::gjk_collide(std::uint32_t a, const Pose& pa, std::uint32_t b, const Pose& pb,
                                       CoalGjkVariant variant) const {
  return direct_collide(*impl_->shapes.at(a), pa, *impl_->shapes.at(b), pb, variant);
}

PeerAnswer CoalShapeCache::gjk_distance(std::uint32_t a, const Pose& pa, std::uint32_t b, const Pose& pb,
                                        CoalGjkVariant variant, double tolerance, bool want_depth) const {
  return direct_distance(*impl_->shapes.at(a), pa, *impl_->shapes.at(b), pb, variant, tolerance, want_depth);
}

}  // namespace batchcol::peers
