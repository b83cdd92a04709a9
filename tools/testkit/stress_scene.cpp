// Building and moving the stress scene (see stress_scene.hpp).
//
// Sizing: for two boxes of half extents a and b, centres uniform in a cube of side L, the boxes overlap with
// probability prod_k 2 (a_k + b_k) / L (ignoring the faces). With n objects, each overlaps on average
// (n - 1) E[prod_k 2 (a_k + b_k)] / L^3 others; the expectation is estimated on random pairs of the actual
// (rotated) objects and L is solved for `density`. Clustered: Gaussian clusters of ~2000 objects, 4x denser than
// `density` inside; layered: horizontal layers (shelves) about one object thick, each with `density` overlaps per
// object, stacked far enough apart not to touch.
#include "testkit/stress_scene.hpp"

#include "testkit/portable_random.hpp"

#include <algorithm>
#include <cmath>

namespace batchcol::testkit {
namespace {

constexpr int kShapesPerType = 8;
constexpr std::size_t kSizingPairs = 4096;
constexpr std::size_t kObjectsPerCluster = 2000;
constexpr double kClusterDensityFactor = 4.0;
constexpr double kPi = 3.14159265358979323846;

std::shared_ptr<ShapeTable> make_palette(PortableRandom& rng) {
  auto t = std::make_shared<ShapeTable>();
  for (int k = 0; k < kShapesPerType; ++k) {
    t->add(Shape::sphere(rng.uniform(0.04, 0.08)));
    t->add(Shape::box(rng.uniform(0.03, 0.08), rng.uniform(0.03, 0.08), rng.uniform(0.03, 0.08)));
    t->add(Shape::capsule(rng.uniform(0.02, 0.04), rng.uniform(0.03, 0.06)));
    t->add(Shape::cylinder(rng.uniform(0.03, 0.06), rng.uniform(0.03, 0.06)));
    std::vector<Eigen::Vector3d> points;  // a small hull: 10 points on a sphere of radius 4-8 cm
    const double r = rng.uniform(0.04, 0.08);
    for (int p = 0; p < 10; ++p) points.push_back(r * rng.unit_vector());
    t->add(Shape::convex(points));
  }
  return t;
}

Eigen::Vector3d half_extent(const Shape& shape, const Eigen::Quaterniond& q) {
  const Aabb b = compute_aabb(shape, q, Eigen::Vector3d::Zero());
  return 0.5 * (b.max - b.min);
}

}  // namespace

Distribution parse_distribution(const std::string& name) {
  if (name == "uniform") return Distribution::uniform;
  if (name == "clustered") return Distribution::clustered;
  if (name == "layered") return Distribution::layered;
  throw InputError("--distribution " + name + ": unknown (valid: uniform, clustered, layered)");
}

StressScene make_stress_scene(const StressSceneSpec& spec) {
  PortableRandom rng(spec.seed);
  StressScene s;
  s.shapes = make_palette(rng);
  const std::size_t n = spec.objects;
  std::vector<std::uint32_t> shape(n);
  std::vector<Eigen::Vector3d> half(n);
  s.poses.resize(n);
  double mean_size = 0;
  for (std::size_t i = 0; i < n; ++i) {
    shape[i] = static_cast<std::uint32_t>(rng.index(s.shapes->size()));
    s.poses[i].rotation = rng.rotation();
    half[i] = half_extent((*s.shapes)[shape[i]], s.poses[i].rotation);
    mean_size += half[i].mean() / static_cast<double>(n);
  }
  double e3 = 0, exy = 0;  // E[prod_k (a_k + b_k)] over 3 axes and over x, y
  for (std::size_t k = 0; k < kSizingPairs; ++k) {
    const Eigen::Vector3d sum = half[rng.index(n)] + half[rng.index(n)];
    e3 += sum.prod() / kSizingPairs;
    exy += sum.x() * sum.y() / kSizingPairs;
  }
  const double others = std::max<double>(1.0, static_cast<double>(n) - 1.0);
  const double side = std::cbrt(others * 8.0 * e3 / spec.density);
  s.world_side = side;
  switch (spec.distribution) {
    case Distribution::uniform:
      for (auto& p : s.poses) p.translation = {rng.uniform(0, side), rng.uniform(0, side), rng.uniform(0, side)};
      break;
    case Distribution::clustered: {
      const std::size_t clusters = std::max<std::size_t>(1, n / kObjectsPerCluster);
      const double m = static_cast<double>(n) / static_cast<double>(clusters);
      // A Gaussian cluster of m objects with deviation sigma: a pair's centre offset has density
      // 1 / ((4 pi)^1.5 sigma^3) at 0, so an object overlaps about m 8 E / ((4 pi)^1.5 sigma^3) others.
      const double sigma = std::cbrt(m * 8.0 * e3 / (kClusterDensityFactor * spec.density * std::pow(4 * kPi, 1.5)));
      std::vector<Eigen::Vector3d> centre(clusters);
      for (auto& c : centre) c = {rng.uniform(0, side), rng.uniform(0, side), rng.uniform(0, side)};
      for (auto& p : s.poses) {
        const Eigen::Vector3d& c = centre[rng.index(clusters)];
        // Box-Muller from the portable source.
        Eigen::Vector3d g;
        for (int a = 0; a < 3; ++a) {
          const double u = std::max(rng.uniform(), 1e-300), v = rng.uniform();
          g[a] = std::sqrt(-2.0 * std::log(u)) * std::cos(2 * kPi * v);
        }
        p.translation = c + sigma * g;
      }
      break;
    }
    case Distribution::layered: {
      const std::size_t layers = std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(std::cbrt(double(n)) / 10)));
      const double per_layer = std::max(1.0, static_cast<double>(n) / static_cast<double>(layers) - 1.0);
      // Objects of one layer overlap in z (jitter within one mean size): overlaps ~ m 4 E_xy / A^2.
      const double area_side = std::sqrt(per_layer * 4.0 * exy / spec.density);
      s.world_side = area_side;
      const double spacing = 8.0 * mean_size + 0.2;
      for (auto& p : s.poses) {
        const double layer = static_cast<double>(rng.index(layers));
        p.translation = {rng.uniform(0, area_side), rng.uniform(0, area_side),
                         layer * spacing + rng.uniform(-mean_size, mean_size)};
      }
      break;
    }
  }
  s.scene = std::make_unique<Scene>(s.shapes);
  s.handles.reserve(n);
  for (std::size_t i = 0; i < n; ++i) s.handles.push_back(s.scene->add(shape[i], s.poses[i]));
  s.velocity.resize(n);
  s.spin.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    s.velocity[i] = spec.move * half[i].mean() * rng.unit_vector();
    s.spin[i] = Eigen::Quaterniond(Eigen::AngleAxisd(spec.move, rng.unit_vector()));
  }
  return s;
}

void step_stress_scene(StressScene& s) {
  for (std::size_t i = 0; i < s.handles.size(); ++i) {
    Pose& p = s.poses[i];
    p.translation += s.velocity[i];
    p.rotation = (s.spin[i] * p.rotation).normalized();
    s.scene->set_pose(s.handles[i], p);
  }
}

}  // namespace batchcol::testkit
