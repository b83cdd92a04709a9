#include "support/derivative_reference.hpp"

#include "kernels/shape_core.hpp"
#include "kernels/support.hpp"
#include "shape_table_access.hpp"  // engine/src: OwnedShapeView, ShapeTableAccess

#include <algorithm>
#include <cmath>
#include <limits>

namespace batchcol::testing {
namespace {

Eigen::Vector3d world_support(const Shape& shape, const Pose& pose, const Eigen::Vector3d& u) {
  const OwnedShapeView view(shape);
  const auto core = kernels::make_core<double>(view.view);
  kernels::SupportHint hint;
  const Eigen::Matrix3d R = pose.rotation.toRotationMatrix();
  const Eigen::Vector3d d = R.transpose() * u;
  Eigen::Vector3d p = kernels::support(core, d, hint);
  if (core.radius > 0.0) p += core.radius * d.normalized();
  return R * p + pose.translation;
}

bool strictly_convex(const Shape& s) {
  return s.type == ShapeType::ellipsoid || s.type == ShapeType::sphere;
}

// Newton on f(z) = z + S_a(z) - S_b(-z) from GJK's z, with a forward-difference Jacobian (step 1e-7 |z|: the
// Jacobian's own error only slows convergence, the fixed point is f's).
void polish(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Eigen::Vector3d& xa, Eigen::Vector3d& xb) {
  Eigen::Vector3d z = xb - xa;
  const auto f = [&](const Eigen::Vector3d& v) {
    return Eigen::Vector3d(v + world_support(a, pa, v) - world_support(b, pb, -v));
  };
  for (int it = 0; it < 40; ++it) {
    const Eigen::Vector3d r = f(z);
    if (r.norm() <= 1e-17 * (1.0 + z.norm())) break;
    Eigen::Matrix3d J;
    const double step = 1e-7 * z.norm();
    for (int k = 0; k < 3; ++k) J.col(k) = (f(z + step * Eigen::Vector3d::Unit(k)) - r) / step;
    z -= J.lu().solve(r);
  }
  xa = world_support(a, pa, z);
  xb = world_support(b, pb, -z);
}

// The closest point of a (non-inflated) cylinder or box to a point q, in closed form (local frame: clamp the
// radial distance or each coordinate; a point inside is not handled, the tests' pairs are separated).
bool closest_on_solid(const Shape& s, const Pose& pose, const Eigen::Vector3d& q, Eigen::Vector3d& out) {
  if (s.inflation != 0.0 || (s.type != ShapeType::cylinder && s.type != ShapeType::box)) return false;
  const Eigen::Matrix3d R = pose.rotation.toRotationMatrix();
  Eigen::Vector3d p = R.transpose() * (q - pose.translation);
  if (s.type == ShapeType::box) {
    p = p.cwiseMax(-s.size).cwiseMin(s.size);
  } else {
    const double rho = std::hypot(p.x(), p.y());
    if (rho > s.size.x()) p.head<2>() *= s.size.x() / rho;
    p.z() = std::clamp(p.z(), -s.size.y(), s.size.y());
  }
  out = R * p + pose.translation;
  return true;
}

// Spheres against cylinders and boxes: the closest point to the sphere's centre, then the sphere's witness on the
// segment to it.
bool sphere_against_solid(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, Eigen::Vector3d& xa,
                          Eigen::Vector3d& xb) {
  if (a.type == ShapeType::sphere && closest_on_solid(b, pb, pa.translation, xb)) {
    xa = pa.translation + (a.size.x() + a.inflation) * (xb - pa.translation).normalized();
    return true;
  }
  if (b.type == ShapeType::sphere && closest_on_solid(a, pa, pb.translation, xa)) {
    xb = pb.translation + (b.size.x() + b.inflation) * (xa - pb.translation).normalized();
    return true;
  }
  return false;
}


// ---- Feature-locked exact witness points (feature_witness()) ----

// The round radius swept around a feature: a sphere's or capsule's radius plus the inflation (an ellipsoid's is in
// its support map).
double swept_radius(const Shape& s) {
  double r = s.inflation;
  if (s.type == ShapeType::sphere || s.type == ShapeType::capsule) r += s.size.x();
  return r;
}

// A box feature's index: (s0 + 1) + 3 (s1 + 1) + 9 (s2 + 1), s_k in {-1, 0, 1} (0: free along axis k).
int box_sign(int index, int k) { return (k == 0 ? index : k == 1 ? index / 3 : index / 9) % 3 - 1; }

// The closest point to x (local frame) of feature f of the core, the feature extended beyond its extent (a line,
// a plane, an infinite cylinder or cone: smooth in x), and in `outside` how far beyond its extent that point is
// (<= 0: on the feature itself).
Eigen::Vector3d feature_point(const Shape& s, const Feature& f, const Eigen::Vector3d& x, double& outside) {
  outside = 0.0;
  const double R = s.size.x(), h = s.size.y();
  const double rho = std::hypot(x.x(), x.y());
  switch (s.type) {
    case ShapeType::sphere: return Eigen::Vector3d::Zero();
    case ShapeType::capsule:
      if (f.kind == Feature::point) return {0.0, 0.0, f.index ? h : -h};
      outside = std::abs(x.z()) - h;
      return {0.0, 0.0, x.z()};
    case ShapeType::box: {
      Eigen::Vector3d p;
      outside = -1e300;
      for (int k = 0; k < 3; ++k) {
        const int sign = box_sign(f.index, k);
        p(k) = sign ? sign * s.size(k) : x(k);
        if (!sign) outside = std::max(outside, std::abs(x(k)) - s.size(k));
      }
      outside = std::max(outside, 0.0);
      return p;
    }
    case ShapeType::cylinder: {
      const double z = f.index ? h : -h;
      if (f.kind == Feature::plane) {
        outside = rho - R;
        return {x.x(), x.y(), z};
      }
      const double c = R / rho;
      if (f.kind == Feature::circle) return {c * x.x(), c * x.y(), z};
      outside = std::abs(x.z()) - h;  // the side
      return {c * x.x(), c * x.y(), x.z()};
    }
    case ShapeType::cone: {
      if (f.kind == Feature::point) return {0.0, 0.0, h};
      if (f.kind == Feature::plane) {
        outside = rho - R;
        return {x.x(), x.y(), -h};
      }
      if (f.kind == Feature::circle) return {R / rho * x.x(), R / rho * x.y(), -h};
      // The side: the generator through x, in the (rho, z) half-plane from the apex (0, h) to the rim (R, -h).
      const double L = std::hypot(R, 2.0 * h), gr = R / L, gz = -2.0 * h / L;
      const double t = rho * gr + (x.z() - h) * gz;
      outside = std::max(-t, t - L);
      const double c = t * gr / rho;
      return {c * x.x(), c * x.y(), h + t * gz};
    }
    case ShapeType::convex: {
      const ConvexHull& hull = *s.hull;
      if (f.kind == Feature::point) return hull.vertices[static_cast<std::size_t>(f.index)];
      if (f.kind == Feature::line) {
        const Eigen::Vector3d& a = hull.vertices[static_cast<std::size_t>(f.index >> 16)];
        const Eigen::Vector3d e = hull.vertices[static_cast<std::size_t>(f.index & 0xffff)] - a;
        const double t = e.dot(x - a) / e.squaredNorm();
        outside = std::max(-t, t - 1.0) * e.norm();
        return a + t * e;
      }
      const std::size_t face = static_cast<std::size_t>(f.index);
      const Eigen::Vector3d& n = hull.face_normals[face];
      const Eigen::Vector3d p = x - n.dot(x - hull.vertices[hull.faces[face][0]]) * n;
      outside = -1e300;  // inside every face plane (the face's own and coplanar ones give ~0)
      for (std::size_t g = 0; g < hull.faces.size(); ++g)
        outside = std::max(outside, hull.face_normals[g].dot(p - hull.vertices[hull.faces[g][0]]));
      return p;
    }
    default: outside = 1e300; return x;
  }
}

std::vector<Feature> all_features(const Shape& s) {
  std::vector<Feature> out;
  switch (s.type) {
    case ShapeType::sphere: out.push_back({Feature::point, 0}); break;
    case ShapeType::ellipsoid: out.push_back({Feature::smooth, 0}); break;
    case ShapeType::capsule: out = {{Feature::point, 0}, {Feature::point, 1}, {Feature::line, 0}}; break;
    case ShapeType::box:
      for (int i = 0; i < 27; ++i) {
        const int free = (box_sign(i, 0) == 0) + (box_sign(i, 1) == 0) + (box_sign(i, 2) == 0);
        if (free < 3) out.push_back({free == 0 ? Feature::point : free == 1 ? Feature::line : Feature::plane, i});
      }
      break;
    case ShapeType::cylinder:
      out = {{Feature::plane, 0}, {Feature::plane, 1}, {Feature::circle, 0}, {Feature::circle, 1},
             {Feature::cylinder_side, 0}};
      break;
    case ShapeType::cone:
      out = {{Feature::point, 0}, {Feature::plane, 0}, {Feature::circle, 0}, {Feature::cone_side, 0}};
      break;
    case ShapeType::convex: {
      const ConvexHull& hull = *s.hull;
      for (std::size_t v = 0; v < hull.vertices.size(); ++v) {
        out.push_back({Feature::point, static_cast<int>(v)});
        for (std::uint32_t k = hull.neighbor_offsets[v]; k < hull.neighbor_offsets[v + 1]; ++k)
          if (hull.neighbors[k] > v) out.push_back({Feature::line, static_cast<int>((v << 16) | hull.neighbors[k])});
      }
      for (std::size_t f = 0; f < hull.faces.size(); ++f) out.push_back({Feature::plane, static_cast<int>(f)});
      break;
    }
    default: break;
  }
  return out;
}

// One side of a pair on a locked feature, in the world frame.
struct Side {
  const Shape* shape;
  Pose pose;
  Eigen::Matrix3d R;
  Feature f;
  double radius;  // swept
  Side(const Shape& s, const Pose& p, const Feature& feature)
      : shape(&s), pose(p), R(p.rotation.toRotationMatrix()), f(feature), radius(swept_radius(s)) {}
  bool smooth() const { return f.kind == Feature::smooth; }
  // The closest point to x of the swept (extended) feature; `outside` as feature_point().
  Eigen::Vector3d project(const Eigen::Vector3d& x, double& outside) const {
    Eigen::Vector3d p = R * feature_point(*shape, f, R.transpose() * (x - pose.translation), outside) + pose.translation;
    if (radius > 0.0) p += radius * (x - p).normalized();
    return p;
  }
  Eigen::Vector3d project(const Eigen::Vector3d& x) const {
    double outside;
    return project(x, outside);
  }
  Eigen::Vector3d support(const Eigen::Vector3d& u) const { return world_support(*shape, pose, u); }
};

// Newton on F(v) = 0 from v with a forward-difference Jacobian (step 1e-7 scale): the Jacobian's error only slows
// the convergence, the root is F's. Returns the iterate of smallest residual.
template <class F> Eigen::Vector3d newton(const F& f, Eigen::Vector3d v, double scale) {
  Eigen::Vector3d best = v;
  double best_norm = std::numeric_limits<double>::infinity();
  int stalls = 0;
  for (int it = 0; it < 40 && stalls < 3; ++it) {
    const Eigen::Vector3d r = f(v);
    const double norm = r.norm();
    if (!std::isfinite(norm)) break;
    if (norm < best_norm) {
      best_norm = norm;
      best = v;
      stalls = 0;
    } else {
      ++stalls;
    }
    if (norm == 0.0) break;
    Eigen::Matrix3d J;
    const double step = 1e-7 * scale;
    for (int k = 0; k < 3; ++k) J.col(k) = (f(v + step * Eigen::Vector3d::Unit(k)) - r) / step;
    v -= J.lu().solve(r);
  }
  return best;
}

// The witness points of two locked features from the starting points xa, xb (both moved to the solution).
void solve_features(const Side& a, const Side& b, Eigen::Vector3d& xa, Eigen::Vector3d& xb, double scale) {
  if (a.smooth() && b.smooth()) {
    polish(*a.shape, a.pose, *b.shape, b.pose, xa, xb);
  } else if (a.smooth()) {  // z = x_b - x_a with x_a = S_a(z), x_b = P_b(x_a)
    const auto f = [&](const Eigen::Vector3d& z) {
      const Eigen::Vector3d p = a.support(z);
      return Eigen::Vector3d(z + p - b.project(p));
    };
    const Eigen::Vector3d z = newton(f, xb - xa, (xb - xa).norm());
    xa = a.support(z);
    xb = b.project(xa);
  } else if (b.smooth()) {  // x_b = S_b(-z), x_a = P_a(x_b)
    const auto f = [&](const Eigen::Vector3d& z) {
      const Eigen::Vector3d p = b.support(-z);
      return Eigen::Vector3d(z - p + a.project(p));
    };
    const Eigen::Vector3d z = newton(f, xb - xa, (xb - xa).norm());
    xb = b.support(-z);
    xa = a.project(xb);
  } else {  // x_a a fixed point of P_a o P_b
    const auto f = [&](const Eigen::Vector3d& x) { return Eigen::Vector3d(a.project(b.project(x)) - x); };
    const Eigen::Vector3d x = newton(f, xa, scale);
    xa = a.project(b.project(x));
    xb = b.project(xa);
  }
}

// Certifies that (xa, xb) is the closest pair: each point on its feature's extent, and a support point of its
// whole shape along the normal (so the two parallel planes through them separate the shapes), to 1e-12 scale.
bool certified(const Side& a, const Side& b, const Eigen::Vector3d& xa, const Eigen::Vector3d& xb, double scale) {
  const double tol = 1e-12 * scale;
  const Eigen::Vector3d d = xb - xa;
  if (!d.allFinite() || !(d.norm() > 0.0)) return false;
  const Eigen::Vector3d n = d.normalized();
  double outside = 0.0;
  if (!a.smooth() && ((a.project(xa, outside) - xa).norm() > tol || !(outside <= tol))) return false;
  if (!b.smooth() && ((b.project(xb, outside) - xb).norm() > tol || !(outside <= tol))) return false;
  return n.dot(a.support(n) - xa) <= tol && n.dot(xb - b.support(-n)) <= tol;
}
}  // namespace

Pose twisted(const Pose& pose, const Eigen::Matrix<double, 6, 1>& xi, double h) {
  const Eigen::Vector3d w = h * xi.tail<3>();
  const double angle = w.norm();
  const Eigen::Quaterniond q =
      angle > 0 ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, w / angle)) : Eigen::Quaterniond::Identity();
  return {q * pose.translation + h * xi.head<3>(), (q * pose.rotation).normalized()};
}

QueryOptions tight_query() {
  QueryOptions q;
  q.level = QueryLevel::witness;
  q.tolerance = 1e-15;  // raised to the precision floor by collide()
  q.max_iterations = 1000;
  return q;
}

PairResults exact_witness(const ShapeTable& shapes, const PairBatch& batch) {
  PairResults r;
  collide(shapes, batch, tight_query(), r);
  for (std::size_t i = 0; i < batch.size(); ++i) {
    const Shape& a = shapes[batch.shape_a[i]];
    const Shape& b = shapes[batch.shape_b[i]];
    if (r.status[i] != Status::converged) continue;
    Eigen::Vector3d xa = r.witness_a[i], xb = r.witness_b[i];
    if (!sphere_against_solid(a, batch.pose_a(i), b, batch.pose_b(i), xa, xb)) {
      if (!strictly_convex(a) || !strictly_convex(b)) continue;
      polish(a, batch.pose_a(i), b, batch.pose_b(i), xa, xb);
    }
    const double d = (xb - xa).norm();
    r.witness_a.set(i, xa);
    r.witness_b.set(i, xb);
    r.normal.set(i, (xb - xa) / d);
    r.distance[i] = d;
  }
  return r;
}

FiniteDifferences finite_differences(const ShapeTable& shapes, const PairBatch& batch, const std::vector<double>& h) {
  const std::vector<double>& radii = detail::ShapeTableAccess::bounding_radii(shapes);
  const std::size_t n = batch.size();
  PairBatch perturbed;
  for (std::size_t i = 0; i < n; ++i) {
    const double scale = radii[batch.shape_a[i]] + radii[batch.shape_b[i]];
    for (int body = 0; body < 2; ++body)
      for (int k = 0; k < 6; ++k)
        for (int sign = -1; sign <= 1; sign += 2) {
          Eigen::Matrix<double, 6, 1> xi = Eigen::Matrix<double, 6, 1>::Zero();
          xi(k) = k < 3 ? 1.0 : 1.0 / scale;
          Pose pa = batch.pose_a(i), pb = batch.pose_b(i);
          (body == 0 ? pa : pb) = twisted(body == 0 ? pa : pb, xi, sign * h[i]);
          perturbed.add(batch.shape_a[i], pa, batch.shape_b[i], pb);
        }
  }
  const PairResults r = exact_witness(shapes, perturbed);
  FiniteDifferences fd;
  for (auto* v : {&fd.distance_a, &fd.distance_b}) v->resize(n);
  for (auto* m : {&fd.witness_a_a, &fd.witness_a_b, &fd.witness_b_a, &fd.witness_b_b, &fd.normal_a, &fd.normal_b})
    m->resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double scale = radii[batch.shape_a[i]] + radii[batch.shape_b[i]];
    for (int body = 0; body < 2; ++body)
      for (int k = 0; k < 6; ++k) {
        const std::size_t minus = 24 * i + 12 * body + 2 * k, plus = minus + 1;
        const double step = 2.0 * h[i] * (k < 3 ? 1.0 : 1.0 / scale);
        const double dd = (r.distance[plus] - r.distance[minus]) / step;
        const Eigen::Vector3d da = (r.witness_a[plus] - r.witness_a[minus]) / step;
        const Eigen::Vector3d db = (r.witness_b[plus] - r.witness_b[minus]) / step;
        const Eigen::Vector3d dn = (r.normal[plus] - r.normal[minus]) / step;
        (body == 0 ? fd.distance_a : fd.distance_b)[i](k) = dd;
        (body == 0 ? fd.witness_a_a : fd.witness_a_b)[i].col(k) = da;
        (body == 0 ? fd.witness_b_a : fd.witness_b_b)[i].col(k) = db;
        (body == 0 ? fd.normal_a : fd.normal_b)[i].col(k) = dn;
      }
  }
  return fd;
}

PairBatch random_separated_pairs(Rng& rng, ShapeTable& shapes, const std::vector<ShapeType>& types, int count) {
  const std::vector<double>& radii = detail::ShapeTableAccess::bounding_radii(shapes);  // grows with the table
  PairBatch batch;
  while (static_cast<int>(batch.size()) < count) {
    PairBatch trial;
    for (int k = 0; k < count; ++k) {
      const ShapeType ta = types[static_cast<std::size_t>(uniform(rng, 0, types.size())) % types.size()];
      const ShapeType tb = types[static_cast<std::size_t>(uniform(rng, 0, types.size())) % types.size()];
      Shape sa = random_shape(rng, ta, 0.05, 0.4), sb = random_shape(rng, tb, 0.05, 0.4);
      if (uniform(rng, 0, 1) < 0.25) sa = sa.inflated(uniform(rng, 0.01, 0.05));
      const std::uint32_t a = shapes.add(sa), b = shapes.add(sb);
      const double sum = radii[a] + radii[b];
      const Pose pa{random_unit_vector(rng) * uniform(rng, 0.0, 1.0), random_rotation(rng)};
      const Pose pb{pa.translation + random_unit_vector(rng) * sum * uniform(rng, 0.8, 2.0), random_rotation(rng)};
      trial.add(a, pa, b, pb);
    }
    PairResults r;
    collide(shapes, trial, tight_query(), r);
    for (std::size_t i = 0; i < trial.size() && static_cast<int>(batch.size()) < count; ++i) {
      const double sum = radii[trial.shape_a[i]] + radii[trial.shape_b[i]];
      if (r.status[i] == Status::converged && r.distance[i] > 0.02 * sum)
        batch.add(trial.shape_a[i], trial.pose_a(i), trial.shape_b[i], trial.pose_b(i));
    }
  }
  return batch;
}

}  // namespace batchcol::testing

namespace batchcol::testing {

std::string feature_name(const Shape& shape, const Feature& f) {
  static const char* const kinds[] = {"none", "surface", "vertex", "edge", "face", "rim", "side", "side"};
  std::string kind = kinds[f.kind];
  if (shape.type == ShapeType::capsule) kind = f.kind == Feature::point ? "end" : f.kind == Feature::line ? "side" : kind;
  if (shape.type == ShapeType::cylinder && f.kind == Feature::plane) kind = "cap";
  if (shape.type == ShapeType::cone) kind = f.kind == Feature::point ? "apex" : f.kind == Feature::plane ? "base" : kind;
  return std::string(to_string(shape.type)) + " " + kind;
}

FeatureReference feature_witness(const ShapeTable& shapes, const PairBatch& batch) {
  FeatureReference out;
  collide(shapes, batch, tight_query(), out.exact);
  PairResults& r = out.exact;
  const std::vector<double>& radii = detail::ShapeTableAccess::bounding_radii(shapes);
  const std::size_t n = batch.size();
  out.feature_a.assign(n, Feature{});
  out.feature_b.assign(n, Feature{});
  out.certified.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (r.status[i] != Status::converged || !(r.distance[i] > 0.0)) continue;
    const Shape& sa = shapes[batch.shape_a[i]];
    const Shape& sb = shapes[batch.shape_b[i]];
    const double scale = radii[batch.shape_a[i]] + radii[batch.shape_b[i]];
    // The candidates: the features within 1e-7 bounding radii of GJK's witness (its error on curved shapes is
    // ~sqrt(2 R 1e-15) ~ 5e-8 R).
    const auto candidates = [&](const Shape& s, const Pose& pose, const Eigen::Vector3d& x, double radius) {
      std::vector<Feature> out_features;
      for (const Feature& f : all_features(s)) {
        const Side side(s, pose, f);
        double outside = 0.0;
        if (side.smooth() ||
            ((side.project(x, outside) - x).norm() <= 1e-7 * radius && outside <= 1e-7 * radius))
          out_features.push_back(f);
      }
      return out_features;
    };
    const Eigen::Vector3d xa0 = r.witness_a[i], xb0 = r.witness_b[i];
    double best = std::numeric_limits<double>::infinity();
    for (const Feature& fa : candidates(sa, batch.pose_a(i), xa0, radii[batch.shape_a[i]]))
      for (const Feature& fb : candidates(sb, batch.pose_b(i), xb0, radii[batch.shape_b[i]])) {
        const Side a(sa, batch.pose_a(i), fa), b(sb, batch.pose_b(i), fb);
        Eigen::Vector3d xa = xa0, xb = xb0;
        solve_features(a, b, xa, xb, scale);
        const double d = (xb - xa).norm();
        if (!(d < best) || !certified(a, b, xa, xb, scale)) continue;
        best = d;
        out.feature_a[i] = fa;
        out.feature_b[i] = fb;
        out.certified[i] = 1;
        r.witness_a.set(i, xa);
        r.witness_b.set(i, xb);
        r.normal.set(i, (xb - xa) / d);
        r.distance[i] = d;
      }
  }
  return out;
}

FeatureDifferences feature_finite_differences(const ShapeTable& shapes, const PairBatch& batch,
                                              const FeatureReference& nominal, const std::vector<double>& h) {
  const std::vector<double>& radii = detail::ShapeTableAccess::bounding_radii(shapes);
  const std::size_t n = batch.size();
  FeatureDifferences fd;
  for (auto* v : {&fd.distance_a, &fd.distance_b}) v->assign(n, Row6::Constant(std::nan("")));
  for (auto* m : {&fd.witness_a_a, &fd.witness_a_b, &fd.witness_b_a, &fd.witness_b_b, &fd.normal_a, &fd.normal_b})
    m->assign(n, Mat36::Constant(std::nan("")));
  fd.same_features.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!nominal.certified[i]) continue;
    const Shape& sa = shapes[batch.shape_a[i]];
    const Shape& sb = shapes[batch.shape_b[i]];
    const double scale = radii[batch.shape_a[i]] + radii[batch.shape_b[i]];
    bool same = true;
    for (int body = 0; body < 2 && same; ++body)
      for (int k = 0; k < 6 && same; ++k) {
        Eigen::Vector3d xa[2], xb[2];
        for (int s = 0; s < 2 && same; ++s) {
          Eigen::Matrix<double, 6, 1> xi = Eigen::Matrix<double, 6, 1>::Zero();
          xi(k) = k < 3 ? 1.0 : 1.0 / scale;
          Pose pa = batch.pose_a(i), pb = batch.pose_b(i);
          (body == 0 ? pa : pb) = twisted(body == 0 ? pa : pb, xi, (2 * s - 1) * h[i]);
          const Side a(sa, pa, nominal.feature_a[i]), b(sb, pb, nominal.feature_b[i]);
          xa[s] = nominal.exact.witness_a[i];
          xb[s] = nominal.exact.witness_b[i];
          solve_features(a, b, xa[s], xb[s], scale);
          same = certified(a, b, xa[s], xb[s], scale);
        }
        if (!same) break;
        const double step = 2.0 * h[i] * (k < 3 ? 1.0 : 1.0 / scale);
        const double d_minus = (xb[0] - xa[0]).norm(), d_plus = (xb[1] - xa[1]).norm();
        (body == 0 ? fd.distance_a : fd.distance_b)[i](k) = (d_plus - d_minus) / step;
        (body == 0 ? fd.witness_a_a : fd.witness_a_b)[i].col(k) = (xa[1] - xa[0]) / step;
        (body == 0 ? fd.witness_b_a : fd.witness_b_b)[i].col(k) = (xb[1] - xb[0]) / step;
        (body == 0 ? fd.normal_a : fd.normal_b)[i].col(k) =
            ((xb[1] - xa[1]) / d_plus - (xb[0] - xa[0]) / d_minus) / step;
      }
    fd.same_features[i] = same ? 1 : 0;
  }
  return fd;
}

}  // namespace batchcol::testing
