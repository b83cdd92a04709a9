// The SIMD GJK against the scalar reference, lane by lane: for every shape-pair type, solver, precision, query
// kind (distance or boolean) and every instruction set this CPU runs, each pair's GjkResult must be bitwise the
// reference gjk()'s (status, iterations, simplex, x, lower bound, direction).
#include "kernel_views.hpp"  // engine/src: pair_view, result_view
#include "kernels/simd/wide_gjk.hpp"
#include "shape_table_access.hpp"  // engine/src: OwnedShapeView
#include "support/generators.hpp"
#include "support/reference_gjk.hpp"
#include "support/same_results.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace batchcol {
namespace {

using testing::Rng;

std::vector<InstructionSet> runnable_sets() {
  std::vector<InstructionSet> sets;
  for (const InstructionSet isa : {InstructionSet::scalar, InstructionSet::avx2, InstructionSet::avx512})
    if (kernels::simd::cpu_has(isa)) sets.push_back(isa);
  return sets;
}

template <class T> bool same_bits(const T& a, const T& b) { return std::memcmp(&a, &b, sizeof(T)) == 0; }

template <class T>
std::string compare(const kernels::GjkResult<T>& want, const kernels::GjkResult<T>& got, bool points = true) {
  if (want.status != got.status) return "status";
  if (want.iterations != got.iterations) return "iterations " + std::to_string(want.iterations) + " vs " +
                                                 std::to_string(got.iterations);
  if (want.newton_steps != got.newton_steps) return "newton steps";
  if (want.simplex.count != got.simplex.count) return "simplex count";
  for (int m = 0; m < want.simplex.count; ++m) {
    if (!same_bits(want.simplex.lambda[m], got.simplex.lambda[m])) return "lambda";
    if (!same_bits(want.simplex.v[m].w, got.simplex.v[m].w)) return "simplex w";
    if (points && !same_bits(want.simplex.v[m].a, got.simplex.v[m].a)) return "simplex a";
    if (points && !same_bits(want.simplex.v[m].b, got.simplex.v[m].b)) return "simplex b";
    if (!points && !(got.simplex.v[m].a.array().isNaN().all() && got.simplex.v[m].b.array().isNaN().all()))
      return "untracked simplex points should be NaN";
  }
  if (!same_bits(want.x, got.x)) return "x";
  if (!same_bits(want.lower_bound, got.lower_bound)) return "lower bound";
  if (!same_bits(want.direction, got.direction)) return "direction";
  return "";
}

/// Pairs of types (ta, tb): B around A at centre distances from overlapping to ~0.5 m, random rotations.
template <class T>
std::vector<kernels::PairSetup<T>> make_setups(Rng& rng, ShapeType ta, ShapeType tb, int count,
                                               const QueryOptions& options, std::deque<OwnedShapeView>& keep) {
  std::vector<kernels::PairSetup<T>> setups;
  for (int i = 0; setups.size() < std::size_t(count) && i < 20 * count; ++i) {
    keep.emplace_back(ta == ShapeType::convex && i % 3 == 0
                          ? Shape::convex(testing::random_hull_points(rng, 120, 0.05, 0.3))  // hill climbing
                          : testing::random_shape(rng, ta));
    const ShapeView& a = keep.back().view;
    keep.emplace_back(testing::random_shape(rng, tb));
    const ShapeView& b = keep.back().view;
    kernels::RelativePose X;
    X.R = testing::random_rotation(rng).toRotationMatrix();
    X.t = testing::random_unit_vector(rng) * testing::uniform(rng, 0.0, 0.9);
    Eigen::Vector3d warm = Eigen::Vector3d::Constant(std::nan(""));
    if (i % 4 == 1) warm = testing::random_unit_vector(rng);
    const kernels::PairSetup<T> s = kernels::setup_pair<T>(a, b, X, warm, options);
    if (!s.done) setups.push_back(s);
  }
  return setups;
}

template <class T> void check_all_types(Solver solver, QueryLevel level) {
  Rng rng(1234 + int(solver) * 7 + int(level));
  QueryOptions options;
  options.solver = solver;
  options.level = level;
  options.tolerance = 1e-9;
  options.margin = level == QueryLevel::boolean ? 0.01 : 0.0;
  const auto sets = runnable_sets();
  int compared = 0, spread = 0;
  long newton_steps = 0, newton_pairs = 0;  // Newton directions taken (reference): the lanes must have run them
  long feature_pairs = 0;  // ... of them, polytope-curved pairs (feature_direction())
  long side_closed = 0;    // cylinder / capsule pairs answered from side_start()'s point in one iteration
  for (const ShapeType ta : testing::bounded_shape_types()) {
    for (const ShapeType tb : testing::bounded_shape_types()) {
      std::deque<OwnedShapeView> keep;  // the setups' cores point into it: a deque never moves its elements
      const auto setups = make_setups<T>(rng, ta, tb, 37, options, keep);
      if (setups.empty()) continue;  // closed forms only (sphere / capsule pairs, sphere-box)
      std::vector<kernels::GjkResult<T>> want;
      int lo = 1 << 30, hi = 0;
      for (const auto& s : setups) {
        want.push_back(test_reference::gjk(s.difference(), s.initial_direction, s.params));
        newton_steps += want.back().newton_steps;
        newton_pairs += want.back().newton_steps > 0 ? 1 : 0;
        feature_pairs += want.back().newton_steps > 0 && kernels::flat_newton_side(ta, tb) != 0 ? 1 : 0;
        side_closed += kernels::side_start_pair(ta, tb) && want.back().iterations == 1 &&
                               want.back().status == kernels::GjkStatus::converged ? 1 : 0;
        lo = std::min(lo, want.back().iterations);
        hi = std::max(hi, want.back().iterations);
      }
      spread = std::max(spread, hi - lo);
      for (const InstructionSet isa : sets) {
        std::vector<kernels::GjkResult<T>> got(setups.size());
        kernels::simd::gjk_lanes<T>(isa, setups.data(), setups.size(), got.data(), solver);
        for (std::size_t i = 0; i < setups.size(); ++i) {
          const std::string diff = compare(want[i], got[i]);
          ASSERT_EQ(diff, "") << to_string(ta) << "-" << to_string(tb) << " pair " << i << " isa " << to_string(isa)
                              << " solver " << to_string(solver) << " level " << to_string(level);
          ++compared;
        }
        // Without the points of A and B: the same run, only w tracked.
        kernels::simd::gjk_lanes<T>(isa, setups.data(), setups.size(), got.data(), solver, false);
        for (std::size_t i = 0; i < setups.size(); ++i)
          ASSERT_EQ(compare(want[i], got[i], false), "") << to_string(ta) << "-" << to_string(tb) << " pair " << i;
      }
    }
  }
  EXPECT_GT(compared, 1000);
  EXPECT_GE(spread, 4) << "lanes should finish at different iterations";
  // Newton directions are for distance / witness lanes of curved pairs only; boolean lanes never take them.
  if (level == QueryLevel::boolean) EXPECT_EQ(newton_steps, 0);
  else {
    EXPECT_GT(newton_pairs, 50) << "too few pairs took Newton steps to check them lane by lane";
    EXPECT_GT(feature_pairs, 20) << "too few polytope-curved pairs took feature Newton steps";
    EXPECT_GT(side_closed, 10) << "too few cylinder / capsule pairs started from the closed-form side contact";
  }
}

TEST(WideGjk, EqualsReferenceBitwiseDouble) {
  for (const Solver solver : {Solver::gjk, Solver::nesterov, Solver::polyak}) {
    check_all_types<double>(solver, QueryLevel::witness);
    check_all_types<double>(solver, QueryLevel::boolean);
  }
}

TEST(WideGjk, EqualsReferenceBitwiseFloat) {
  for (const Solver solver : {Solver::gjk, Solver::nesterov, Solver::polyak}) {
    check_all_types<float>(solver, QueryLevel::witness);
    check_all_types<float>(solver, QueryLevel::boolean);
  }
}

// Cylinder / capsule pairs whose closest points lie on the cylinders' sides (the axis segments' closest points
// interior to every cylinder's axis): the lanes start from the closed-form point (side_start()), which the first
// plain step certifies. Crossed axes at a known gap, the closest points placed by construction, moved by a random
// rigid transform; GJK from the support points alone takes ~20 iterations on such pairs (side lines).
TEST(WideGjk, CylinderSideContactsStartInClosedForm) {
  Rng rng(2026);
  QueryOptions opt;
  opt.level = QueryLevel::witness;
  opt.tolerance = 1e-8;
  for (const bool capsule_b : {false, true}) {
    for (int trial = 0; trial < 50; ++trial) {
      const double ra = testing::uniform(rng, 0.02, 0.2), ha = testing::uniform(rng, 0.02, 0.3);
      const double rb = testing::uniform(rng, 0.02, 0.2), hb = testing::uniform(rng, 0.02, 0.3);
      const Shape a = Shape::cylinder(ra, ha), b = capsule_b ? Shape::capsule(rb, hb) : Shape::cylinder(rb, hb);
      Eigen::Vector3d axis_b = testing::random_unit_vector(rng);
      if (std::abs(axis_b.z()) > 0.95) axis_b = Eigen::Vector3d(1, 0, 0);
      const Eigen::Vector3d m = Eigen::Vector3d::UnitZ().cross(axis_b).normalized();  // the common normal
      const double za = testing::uniform(rng, -0.9, 0.9) * ha, zb = testing::uniform(rng, -0.9, 0.9) * hb;
      const double gap = std::pow(10.0, testing::uniform(rng, -5, -1));
      const Eigen::Vector3d pa = Eigen::Vector3d(0, 0, za) + ra * m, pb = pa + gap * m;
      const Eigen::Vector3d cb = pb + rb * m - zb * axis_b;
      const Eigen::Quaterniond qb = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis_b);
      const Eigen::Quaterniond Q = testing::random_rotation(rng);
      const Eigen::Vector3d T = testing::random_vector(rng);
      const Pose pose_a{T, Q}, pose_b{T + Q * cb, Q * qb};
      const auto r = testing::run_pair(a, pose_a, b, pose_b, opt);
      SCOPED_TRACE("capsule " + std::to_string(capsule_b) + " trial " + std::to_string(trial) + " gap " +
                   std::to_string(gap));
      EXPECT_EQ(r.status, Status::converged);
      EXPECT_EQ(r.iterations, 1);
      EXPECT_NEAR(r.distance, gap, 1e-12);
      EXPECT_LT((r.witness_a - (T + Q * pa)).norm(), 1e-12);
      EXPECT_LT((r.witness_b - (T + Q * pb)).norm(), 1e-12);
    }
  }
}

// The lanes take the solver the setups were made with; `automatic` must have been resolved before.
template <class T> void expect_start_cells_match(const std::vector<Eigen::Matrix<T, 3, 1>>& dirs) {
  std::vector<T> xyz;
  for (const auto& d : dirs) xyz.insert(xyz.end(), {d.x(), d.y(), d.z()});
  for (const InstructionSet isa : runnable_sets()) {
    std::vector<std::uint32_t> cells(dirs.size(), 0u);
    kernels::simd::start_cells_lanes<T>(isa, xyz.data(), dirs.size(), cells.data());
    int mismatches = 0;
    for (std::size_t i = 0; i < dirs.size() && mismatches < 10; ++i) {
      const std::uint32_t want = kernels::start_cell(dirs[i]);
      if (cells[i] != want) ++mismatches;
      EXPECT_EQ(cells[i], want) << to_string(isa) << " " << sizeof(T) << "-byte d " << dirs[i].transpose();
    }
  }
}

namespace {

/// The closed-form start tests below: every pair's certified distance is the gap it was built with, and the share
/// of pairs done in <= 2 iterations (the start certified by the first plain step) is counted.
struct StartTally {
  /// The start tests' query: witness level at tolerance 1e-9, the bound add() checks the distance against.
  static QueryOptions options() {
    QueryOptions opt;
    opt.level = QueryLevel::witness;
    opt.tolerance = 1e-9;
    return opt;
  }
  int trials = 0, one_or_two = 0;
  void add(const testing::SingleResult& res, double gap) {
    EXPECT_EQ(res.status, Status::converged);
    EXPECT_NEAR(res.distance, gap, 1e-9);  // GJK's certified gap: the tests' opt.tolerance
    ++trials;
    one_or_two += res.iterations <= 2 ? 1 : 0;
  }
  /// Runs X against Y, or Y against X when `swap` (a start must work in both orders), and adds the result.
  void run(const Shape& x, const Pose& px, const Shape& y, const Pose& py, bool swap, const QueryOptions& opt,
           double gap) {
    add(swap ? testing::run_pair(y, py, x, px, opt) : testing::run_pair(x, px, y, py, opt), gap);
  }
  void expect_at_least(int num, int den) const {
    EXPECT_GE(one_or_two, trials * num / den) << one_or_two << " of " << trials << " pairs in <= 2 iterations";
  }
};

/// An ellipsoid of radii r in a random orientation (drawn from rng) touching, from beyond, the plane through pb
/// orthogonal to the unit m: its centre pb + Q m / sqrt(m^T Q m) (Q = E diag(r^2) E^T) and its rotation.
std::pair<Eigen::Vector3d, Eigen::Quaterniond> ellipsoid_touching(Rng& rng, const Eigen::Vector3d& r,
                                                                 const Eigen::Vector3d& pb, const Eigen::Vector3d& m) {
  const Eigen::Quaterniond qe = testing::random_rotation(rng);
  const Eigen::Matrix3d E = qe.toRotationMatrix();
  const Eigen::Matrix3d Qm = E * r.cwiseProduct(r).asDiagonal() * E.transpose();
  return {pb + Qm * m / std::sqrt(m.dot(Qm * m)), qe};
}

/// Sizes of X and Y (radius, half height: 3-30 cm) and the radial direction of Y's feature for the rim / slant start
/// tests, drawn in this order: rx, hx, ry, hy, the angle.
struct RimSizes {
  double rx, hx, ry, hy;
  Eigen::Vector3d radial;
};
RimSizes draw_rim_sizes(Rng& rng) {
  RimSizes d;
  d.rx = testing::uniform(rng, 0.03, 0.3);
  d.hx = testing::uniform(rng, 0.03, 0.3);
  d.ry = testing::uniform(rng, 0.03, 0.3);
  d.hy = testing::uniform(rng, 0.03, 0.3);
  const double th = testing::uniform(rng, 0, 6.283185307179586);
  d.radial = Eigen::Vector3d(std::cos(th), std::sin(th), 0);
  return d;
}

/// X's rim point at height zx * hx (X's frame) and an outward normal between X's lateral (a cone's slant) and cap
/// normals there (one draw: the mix).
std::pair<Eigen::Vector3d, Eigen::Vector3d> x_rim_feature(Rng& rng, bool xcone, double rx, double hx, double zx) {
  const Eigen::Vector3d lat_x = xcone ? Eigen::Vector3d(2 * hx, 0, rx).normalized() : Eigen::Vector3d(1, 0, 0);
  const double mu = testing::uniform(rng, 0.1, 0.9);
  return {Eigen::Vector3d(rx, 0, zx * hx), ((1 - mu) * lat_x + mu * zx * Eigen::Vector3d::UnitZ()).normalized()};
}

/// X placed against Y for the rim / slant start tests: X's feature xf (X's frame) with outward normal nx goes to Y's
/// point x (Y's frame) moved out by a gap of 1e-5..1e-1 along Y's outward normal m, spun about nx; then both are
/// posed by one random pose. The random draws in this order: spin, gap, rotation, translation.
struct FeaturePlacement {
  Eigen::Matrix3d Rx;      // X's rotation in Y's frame
  Eigen::Vector3d centre;  // X's origin in Y's frame
  double gap;
  Pose pose_x, pose_y;
};
FeaturePlacement place_feature(Rng& rng, const Eigen::Vector3d& x, const Eigen::Vector3d& m,
                               const Eigen::Vector3d& xf, const Eigen::Vector3d& nx) {
  const Eigen::AngleAxisd spin(testing::uniform(rng, 0, 6.283185307179586), nx);
  FeaturePlacement f;
  f.Rx = (Eigen::Quaterniond::FromTwoVectors(nx, -m) * spin).toRotationMatrix();
  f.gap = std::pow(10.0, testing::uniform(rng, -5, -1));
  f.centre = x + f.gap * m - f.Rx * xf;
  const Eigen::Quaterniond Q = testing::random_rotation(rng);
  const Eigen::Vector3d T = testing::random_vector(rng);
  f.pose_y = Pose{T, Q};
  f.pose_x = Pose{T + Q * f.centre, Q * Eigen::Quaterniond(f.Rx)};
  return f;
}

/// The pair (X, Y) placed by place_feature() as the lanes see it: A first in run()'s order (Y when swap), B's pose in
/// A's frame; the shapes are kept in `keep` (the set-up's cores point into them). Empty when the set-up answers alone.
std::optional<kernels::PairSetup<double>> placed_setup(std::deque<OwnedShapeView>& keep, const Shape& sx,
                                                       const Shape& sy, const FeaturePlacement& f, bool swap,
                                                       const QueryOptions& opt) {
  kernels::RelativePose X;
  X.R = swap ? f.Rx : Eigen::Matrix3d(f.Rx.transpose());
  X.t = swap ? f.centre : Eigen::Vector3d(-(f.Rx.transpose() * f.centre));
  keep.emplace_back(swap ? sy : sx);
  const ShapeView& a = keep.back().view;
  keep.emplace_back(swap ? sx : sy);
  const ShapeView& b = keep.back().view;
  const kernels::PairSetup<double> s =
      kernels::setup_pair<double>(a, b, X, Eigen::Vector3d::Constant(std::nan("")), opt);
  if (s.done) return std::nullopt;
  return s;
}

/// The lanes of every instruction set this CPU runs against the scalar reference on `setups`, bit for bit; counts the
/// comparisons in `compared`.
void expect_lanes_equal_reference(const std::vector<kernels::PairSetup<double>>& setups, int& compared,
                                  const std::string& label) {
  std::vector<kernels::GjkResult<double>> want;
  for (const auto& s : setups) want.push_back(test_reference::gjk(s.difference(), s.initial_direction, s.params));
  for (const InstructionSet isa : runnable_sets()) {
    std::vector<kernels::GjkResult<double>> got(setups.size());
    kernels::simd::gjk_lanes<double>(isa, setups.data(), setups.size(), got.data(), Solver::gjk);
    for (std::size_t i = 0; i < setups.size(); ++i, ++compared)
      ASSERT_EQ(compare(want[i], got[i]), "") << label << " pair " << i << " isa " << to_string(isa);
  }
}

}  // namespace

/// Box edge and vertex contacts with an ellipsoid, built with a known gap: the ellipsoid touches the plane through
/// pb = pa + gap m (m in the feature's normal cone, pa on the edge or the vertex) from beyond, its centre at pb +
/// Q m / sqrt(m^T Q m) (Q = E diag(r^2) E^T). GJK converged in 18.7 mean iterations on such close pairs (21.0 on
/// edges, 27.4 on vertices) before wide_gjk_box_ellipsoid.inl's start point; with it the first plain step
/// certifies the start in almost every lane, in either pair order.
TEST(WideGjk, BoxEllipsoidEdgeAndVertexContactsStartInClosedForm) {
  Rng rng(2027);
  const QueryOptions opt = StartTally::options();
  StartTally tally;
  for (const bool swap : {false, true}) {
    for (const bool vertex : {false, true}) {
      for (int trial = 0; trial < 50; ++trial) {
        const Eigen::Vector3d h(testing::uniform(rng, 0.02, 0.3), testing::uniform(rng, 0.02, 0.3),
                                testing::uniform(rng, 0.02, 0.3));
        const Eigen::Vector3d r(testing::uniform(rng, 0.03, 0.3), testing::uniform(rng, 0.03, 0.3),
                                testing::uniform(rng, 0.03, 0.3));
        Eigen::Vector3d m, pa;
        if (vertex) {
          m = Eigen::Vector3d(testing::uniform(rng, 0.1, 1), testing::uniform(rng, 0.1, 1), testing::uniform(rng, 0.1, 1));
          pa = h;
        } else {  // the edge along x at (+hy, +hz)
          const double phi = testing::uniform(rng, 0.1, 1.47);
          m = Eigen::Vector3d(0, std::cos(phi), std::sin(phi));
          pa = Eigen::Vector3d(testing::uniform(rng, -0.9, 0.9) * h.x(), h.y(), h.z());
        }
        m.normalize();
        const double gap = std::pow(10.0, testing::uniform(rng, -5, -1));
        const Eigen::Vector3d pb = pa + gap * m;
        const auto [ce, qe] = ellipsoid_touching(rng, r, pb, m);
        const Eigen::Quaterniond Q = testing::random_rotation(rng);
        const Eigen::Vector3d T = testing::random_vector(rng);
        const Pose pose_box{T, Q}, pose_ell{T + Q * ce, Q * qe};
        const Shape box = Shape::box(h), ell = Shape::ellipsoid(r.x(), r.y(), r.z());
        SCOPED_TRACE("swap " + std::to_string(swap) + " vertex " + std::to_string(vertex) + " trial " +
                     std::to_string(trial) + " gap " + std::to_string(gap));
        tally.run(box, pose_box, ell, pose_ell, swap, opt, gap);
      }
    }
  }
  tally.expect_at_least(9, 10);
}

/// Box edges against a cylinder's or a cone's rim and box vertices against the side (slant), built with a known
/// gap in Y's frame: m in the normal cone of Y's contact point x (between the rim's cap normal and the lateral
/// normal; on the side its normal), the box's feature at pa = x + gap m with -m in its normal cone, so the plane
/// through pa orthogonal to m separates the shapes and |pa - x| = gap is the distance. Close witness double
/// box-cylinder took 19.4 mean iterations on edge-rim contacts and 19.6 on vertex-side ones before
/// wide_gjk_box_round.inl's start point; with it the first plain step certifies the start in almost every lane,
/// in either pair order.
TEST(WideGjk, BoxCylinderAndConeRimAndSideContactsStartInClosedForm) {
  Rng rng(2028);
  const double two_pi = 6.283185307179586;
  const QueryOptions opt = StartTally::options();
  StartTally tally;
  for (const bool cone : {false, true}) {
    for (const bool swap : {false, true}) {
      for (const bool vertex : {false, true}) {
        for (int trial = 0; trial < 50; ++trial) {
          const Eigen::Vector3d h(testing::uniform(rng, 0.02, 0.3), testing::uniform(rng, 0.02, 0.3),
                                  testing::uniform(rng, 0.02, 0.3));
          const double r = testing::uniform(rng, 0.03, 0.3), hy = testing::uniform(rng, 0.03, 0.3);
          const double th = testing::uniform(rng, 0, two_pi);
          const Eigen::Vector3d radial(std::cos(th), std::sin(th), 0);
          // Y's lateral normal at height z: a cylinder's radial, a cone's slant normal (2 hy radial + r e_z).
          const Eigen::Vector3d lateral = cone ? (2 * hy * radial + r * Eigen::Vector3d::UnitZ()).normalized() : radial;
          const double gap = std::pow(10.0, testing::uniform(rng, -5, -1));
          Eigen::Vector3d x, m;
          Eigen::Matrix3d Rb;  // the box's rotation in Y's frame
          Eigen::Vector3d feature;  // the box's contact point in its own frame
          if (vertex) {
            const double sg = testing::uniform(rng, 0.1, 0.9);
            x = cone ? Eigen::Vector3d(sg * r * radial.x(), sg * r * radial.y(), hy - 2 * hy * sg)
                     : Eigen::Vector3d(r * radial.x(), r * radial.y(), (2 * sg - 1) * hy);
            m = lateral;
            const Eigen::Vector3d q = Eigen::Vector3d(testing::uniform(rng, 0.1, 1), testing::uniform(rng, 0.1, 1),
                                                      testing::uniform(rng, 0.1, 1)).normalized();
            const Eigen::AngleAxisd spin(testing::uniform(rng, 0, two_pi), q);
            Rb = (Eigen::Quaterniond::FromTwoVectors(q, -m) * spin).toRotationMatrix();
            feature = h;
          } else {
            const double top = cone || testing::uniform(rng, 0, 1) < 0.5 ? -1.0 : 1.0;
            x = r * radial + top * hy * Eigen::Vector3d::UnitZ();
            const double lambda = testing::uniform(rng, 0.1, 0.9);
            m = ((1 - lambda) * lateral + lambda * top * Eigen::Vector3d::UnitZ()).normalized();
            Eigen::Vector3d d = testing::random_unit_vector(rng);
            d = (d - d.dot(m) * m).normalized();
            const Eigen::Vector3d w = d.cross(-m);
            const double om = testing::uniform(rng, 0.1, 1.47);
            const Eigen::Vector3d n1 = std::cos(om) * -m + std::sin(om) * w, n2 = std::sin(om) * -m - std::cos(om) * w;
            Rb.col(0) = d;
            Rb.col(1) = n1;
            Rb.col(2) = n2;
            if (Rb.determinant() < 0) Rb.col(0) = -d;
            feature = Eigen::Vector3d(testing::uniform(rng, -0.9, 0.9) * h.x(), h.y(), h.z());
          }
          const Eigen::Vector3d pa = x + gap * m;
          const Eigen::Vector3d centre = pa - Rb * feature;
          const Eigen::Quaterniond Q = testing::random_rotation(rng);
          const Eigen::Vector3d T = testing::random_vector(rng);
          const Pose pose_round{T, Q}, pose_box{T + Q * centre, Q * Eigen::Quaterniond(Rb)};
          const Shape box = Shape::box(h), round = cone ? Shape::cone(r, hy) : Shape::cylinder(r, hy);
          SCOPED_TRACE("cone " + std::to_string(cone) + " swap " + std::to_string(swap) + " vertex " +
                       std::to_string(vertex) + " trial " + std::to_string(trial) + " gap " + std::to_string(gap));
          tally.run(box, pose_box, round, pose_round, swap, opt, gap);
        }
      }
    }
  }
  // Measured 330 of 400 (edge-rim contacts whose rim angle the samples and Newton steps leave a little off take a
  // few more iterations); without the start almost none of these pairs converges in 2.
  tally.expect_at_least(3, 4);
}

/// Cylinder / cone pairs touching rim to rim, rim to cap (a cone's base) and apex to side (slant), built with a
/// known gap in Y's frame: Y's contact point x with m in its normal cone (a rim: between the lateral and the cap
/// normal; a cap: its normal; the side / slant: its normal), X's feature at pa = x + gap m with -m in X's normal
/// cone there (a rim: between X's lateral and cap normals; the apex: within the apex's cone of normals, 2 hx <n,
/// a> >= r |n - <n, a> a|), so the planes through x and pa orthogonal to m separate the shapes and gap is the
/// distance. Close witness double took 26.5 mean iterations on rim-rim contacts, 12.1 on rim-cap and 14-20 on
/// apex-side / slant ones before wide_gjk_rim_rim.inl's candidates; with them the first plain step certifies the
/// start in most lanes, in either pair order.
TEST(WideGjk, CylinderAndConeRimRimCapAndApexContactsStartInClosedForm) {
  Rng rng(2029);
  const QueryOptions opt = StartTally::options();
  StartTally tally;
  enum Kind { rim_rim, rim_cap, apex_side };
  for (const Kind kind : {rim_rim, rim_cap, apex_side}) {
    for (const bool xcone : {false, true}) {
      if (kind == apex_side && !xcone) continue;
      for (const bool ycone : {false, true}) {
        for (const bool swap : {false, true}) {
          for (int trial = 0; trial < 25; ++trial) {
            const auto [rx, hx, ry, hy, radial] = draw_rim_sizes(rng);
            const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ();
            const Eigen::Vector3d lateral = ycone ? (2 * hy * radial + ry * ez).normalized() : radial;
            const double top = ycone || testing::uniform(rng, 0, 1) < 0.5 ? -1.0 : 1.0;
            Eigen::Vector3d x, m;
            if (kind == rim_rim) {
              x = ry * radial + top * hy * ez;
              const double lambda = testing::uniform(rng, 0.1, 0.9);
              m = ((1 - lambda) * lateral + lambda * top * ez).normalized();
            } else if (kind == rim_cap) {
              x = testing::uniform(rng, 0, 0.8) * ry * radial + top * hy * ez;
              m = top * ez;
            } else {
              const double sg = testing::uniform(rng, 0.1, 0.9);
              x = ycone ? Eigen::Vector3d(sg * ry * radial.x(), sg * ry * radial.y(), hy - 2 * hy * sg)
                        : Eigen::Vector3d(ry * radial.x(), ry * radial.y(), (2 * sg - 1) * hy);
              m = lateral;
            }
            // X's feature in its own frame (xf) and the outward normal there (nx), -m in Y's frame.
            Eigen::Vector3d xf, nx;
            if (kind == apex_side) {
              const double beta = testing::uniform(rng, 0, 0.9) * std::atan(2 * hx / rx);
              xf = Eigen::Vector3d(0, 0, hx);
              nx = Eigen::Vector3d(std::sin(beta), 0, std::cos(beta));
            } else {
              std::tie(xf, nx) = x_rim_feature(rng, xcone, rx, hx, xcone ? -1.0 : 1.0);  // a cylinder's top, a cone's base
            }
            const auto [Rx, centre, gap, pose_x, pose_y] = place_feature(rng, x, m, xf, nx);
            const Shape sx = xcone ? Shape::cone(rx, hx) : Shape::cylinder(rx, hx);
            const Shape sy = ycone ? Shape::cone(ry, hy) : Shape::cylinder(ry, hy);
            SCOPED_TRACE("kind " + std::to_string(kind) + " xcone " + std::to_string(xcone) + " ycone " +
                         std::to_string(ycone) + " swap " + std::to_string(swap) + " trial " + std::to_string(trial) +
                         " gap " + std::to_string(gap));
            tally.run(sx, pose_x, sy, pose_y, swap, opt, gap);
          }
        }
      }
    }
  }
  // Measured 471 of 500 (the facing-rim choices miss a few rim-rim contacts, which then take a few more iterations).
  tally.expect_at_least(9, 10);
}

/// A cylinder's or a cone's rim against a cone's slant, and a cone's slant against a cone's slant, built with a known
/// gap in Y's frame (as the rim-rim test): Y's slant point x with its normal m, X's feature at pa = x + gap m with
/// -m in X's normal cone there (a rim: between X's lateral and cap normals; a slant point: the slant's normal), so
/// the planes through x and pa orthogonal to m separate the shapes and gap is the distance. Close witness double
/// took 8.1 mean iterations on cylinder-cone's rim-slant contacts and 8.9 on cone-cone's slant-slant ones before
/// rim_lateral()'s sampled start (lateral_start()) and cone step, and slant_slant() (wide_gjk_rim_rim.inl); with
/// them the first plain step certifies the start in most lanes, in either pair order. The same pairs through the
/// lanes of every instruction set must give the reference's results bit for bit (these starts are the new code).
TEST(WideGjk, ConeRimSlantAndSlantSlantContactsStartNearTheOptimum) {
  Rng rng(2030);
  const QueryOptions opt = StartTally::options();
  StartTally tally;
  std::deque<OwnedShapeView> keep;  // the setups' cores point into it
  int compared = 0;
  enum Kind { rim_slant, slant_slant };
  for (const Kind kind : {rim_slant, slant_slant}) {
    for (const bool xcone : {false, true}) {
      if (kind == slant_slant && !xcone) continue;
      for (const bool swap : {false, true}) {
        std::vector<kernels::PairSetup<double>> setups;  // one type pair: a run of the lanes takes one
        for (int trial = 0; trial < 40; ++trial) {
          const auto [rx, hx, ry, hy, radial] = draw_rim_sizes(rng);
          const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ();
          const double sg = testing::uniform(rng, 0.1, 0.9);
          const Eigen::Vector3d x(sg * ry * radial.x(), sg * ry * radial.y(), hy - 2 * hy * sg);
          const Eigen::Vector3d m = (2 * hy * radial + ry * ez).normalized();
          Eigen::Vector3d xf, nx;  // X's feature in its own frame and the outward normal there, -m in Y's frame
          if (kind == rim_slant) {
            const double zx = xcone || testing::uniform(rng, 0, 1) < 0.5 ? -1.0 : 1.0;  // a cone's base rim
            std::tie(xf, nx) = x_rim_feature(rng, xcone, rx, hx, zx);
          } else {
            const double sx = testing::uniform(rng, 0.1, 0.9);
            xf = Eigen::Vector3d(sx * rx, 0, hx - 2 * hx * sx);
            nx = Eigen::Vector3d(2 * hx, 0, rx).normalized();
          }
          const FeaturePlacement f = place_feature(rng, x, m, xf, nx);
          const Shape sx = xcone ? Shape::cone(rx, hx) : Shape::cylinder(rx, hx), sy = Shape::cone(ry, hy);
          SCOPED_TRACE("kind " + std::to_string(kind) + " xcone " + std::to_string(xcone) + " swap " +
                       std::to_string(swap) + " trial " + std::to_string(trial) + " gap " + std::to_string(f.gap));
          tally.run(sx, f.pose_x, sy, f.pose_y, swap, opt, f.gap);
          if (auto s = placed_setup(keep, sx, sy, f, swap, opt)) setups.push_back(*s);
        }
        ASSERT_EQ(setups.size(), std::size_t(40));
        expect_lanes_equal_reference(setups, compared, "kind " + std::to_string(kind) + " xcone " +
                                                           std::to_string(xcone) + " swap " + std::to_string(swap));
        if (::testing::Test::HasFatalFailure()) return;
      }
    }
  }
  // Measured 240 of 240 (the scalar reference on these pairs); before the starts 88 of 240 (rim-slant 88 of 160,
  // slant-slant 0 of 80).
  tally.expect_at_least(9, 10);
  EXPECT_EQ(compared, tally.trials * int(runnable_sets().size()));
}

/// Cylinder / cone pairs touching rim to rim (as the rim-rim test above: Y's rim point x with m between its lateral
/// and cap normals, X's rim at x + gap m with -m between X's lateral and cap normals), more of them and in both
/// pair orders, checked through the scalar reference and the lanes of every instruction set bit for bit. rim_rim()
/// runs in A's frame only, so where X is B (swap) its Newton steps start from A's sampled angle on the other rim.
/// Measured on these 480 pairs (the scalar reference): kRimRimNewtonSteps 3: 410 in <= 2 iterations (swap 172 of
/// 240, up to 42 iterations); 4: 444 (up to 37). The bound 9 / 10 (432) fails with 3 steps.
TEST(WideGjk, RimRimContactsStartNearTheOptimumInBothOrders) {
  Rng rng(2031);
  const QueryOptions opt = StartTally::options();
  StartTally tally;
  std::deque<OwnedShapeView> keep;  // the setups' cores point into it
  int compared = 0;
  for (const bool xcone : {false, true}) {
    for (const bool ycone : {false, true}) {
      for (const bool swap : {false, true}) {
        std::vector<kernels::PairSetup<double>> setups;  // one type pair: a run of the lanes takes one
        for (int trial = 0; trial < 60; ++trial) {
          const auto [rx, hx, ry, hy, radial] = draw_rim_sizes(rng);
          const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ();
          const Eigen::Vector3d lateral = ycone ? (2 * hy * radial + ry * ez).normalized() : radial;
          const double top = ycone || testing::uniform(rng, 0, 1) < 0.5 ? -1.0 : 1.0;
          const Eigen::Vector3d x = ry * radial + top * hy * ez;
          const double lambda = testing::uniform(rng, 0.1, 0.9);
          const Eigen::Vector3d m = ((1 - lambda) * lateral + lambda * top * ez).normalized();
          const auto [xf, nx] = x_rim_feature(rng, xcone, rx, hx, xcone ? -1.0 : 1.0);  // a cylinder's top, a cone's base
          const FeaturePlacement f = place_feature(rng, x, m, xf, nx);
          const Shape sx = xcone ? Shape::cone(rx, hx) : Shape::cylinder(rx, hx);
          const Shape sy = ycone ? Shape::cone(ry, hy) : Shape::cylinder(ry, hy);
          SCOPED_TRACE("xcone " + std::to_string(xcone) + " ycone " + std::to_string(ycone) + " swap " +
                       std::to_string(swap) + " trial " + std::to_string(trial) + " gap " + std::to_string(f.gap));
          tally.run(sx, f.pose_x, sy, f.pose_y, swap, opt, f.gap);
          if (auto s = placed_setup(keep, sx, sy, f, swap, opt)) setups.push_back(*s);
        }
        ASSERT_EQ(setups.size(), std::size_t(60));
        expect_lanes_equal_reference(setups, compared, "xcone " + std::to_string(xcone) + " ycone " +
                                                           std::to_string(ycone) + " swap " + std::to_string(swap));
        if (::testing::Test::HasFatalFailure()) return;
      }
    }
  }
  tally.expect_at_least(9, 10);
  EXPECT_EQ(compared, tally.trials * int(runnable_sets().size()));
}

/// lateral_start()'s cylinder form (-|D1| - B^2 over pairs of opposite angles) against the squared distance of the
/// rim point to Y's axis line evaluated directly at each of the kEdgeRimSamples angles: the chosen angle's value is
/// the smallest up to rounding (a sign or term error in the shared products would pick another sample).
TEST(WideGjk, CylinderLateralStartTakesTheBestSample) {
  Rng rng(2032);
  int checked = 0, distinct = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const double r = testing::uniform(rng, 0.03, 0.3), zr = testing::uniform(rng, -0.3, 0.3);
    const Eigen::Vector3d c = testing::random_vector(rng, 0.6), b = testing::random_unit_vector(rng);
    double C, S;
    test_reference::lateral_start(r, zr, c, b, 0.1, 0.1, false, C, S);
    const auto phi = [&](double cs, double sn) {
      const Eigen::Vector3d v = Eigen::Vector3d(r * cs, r * sn, zr) - c;
      return v.squaredNorm() - v.dot(b) * v.dot(b);
    };
    double lo = std::numeric_limits<double>::infinity(), second = lo;
    for (int j = 0; j < kernels::kEdgeRimSamples; ++j) {
      const double sg = j < kernels::kEdgeRimSamples / 2 ? 1.0 : -1.0;
      const int k = j % (kernels::kEdgeRimSamples / 2);
      const double f = phi(sg * kernels::kEdgeRimCos[k], sg * kernels::kEdgeRimSin[k]);
      if (f < lo) second = lo, lo = f;
      else if (f < second) second = f;
    }
    EXPECT_LE(phi(C, S), lo + 1e-12) << "trial " << trial;
    ++checked;
    distinct += second - lo > 1e-3 ? 1 : 0;
  }
  EXPECT_EQ(checked, 2000);
  EXPECT_GT(distinct, 500) << "too few trials whose best sample is clearly apart from the others";
}

/// Sphere and capsule against an ellipsoid at a known gap (the ellipsoid touching the plane through pb = pa + (gap +
/// radius) m from beyond, pa the sphere's centre, or a point of the capsule's segment with m orthogonal to it, or
/// its end with m in the end's normal cone): the cores are a box with zero extents (a point, a segment), whose
/// box_ellipsoid_point() start (kPointCore, kSegmentCore) GJK's first plain step certifies. Measured before it,
/// close witness double (20000 pairs): sphere-ellipsoid 4.91, capsule-ellipsoid 6.77 mean iterations.
TEST(WideGjk, SphereAndCapsuleAgainstEllipsoidStartInClosedForm) {
  Rng rng(2028);
  const QueryOptions opt = StartTally::options();
  StartTally tally;
  for (const bool swap : {false, true}) {
    for (const int kind : {0, 1, 2}) {  // sphere, capsule side, capsule end
      for (int trial = 0; trial < 50; ++trial) {
        const double radius = testing::uniform(rng, 0.01, 0.2), half = testing::uniform(rng, 0.02, 0.3);
        const Eigen::Vector3d r(testing::uniform(rng, 0.03, 0.3), testing::uniform(rng, 0.03, 0.3),
                                testing::uniform(rng, 0.03, 0.3));
        Eigen::Vector3d m = testing::random_unit_vector(rng), pa = Eigen::Vector3d::Zero();
        if (kind == 1) {
          m.z() = 0;
          pa.z() = testing::uniform(rng, -0.9, 0.9) * half;
        } else if (kind == 2) {
          m.z() = std::abs(m.z()) + 0.1;
          pa.z() = half;
        }
        m.normalize();
        const double gap = std::pow(10.0, testing::uniform(rng, -5, -1));
        const Eigen::Vector3d pb = pa + (gap + radius) * m;
        const auto [ce, qe] = ellipsoid_touching(rng, r, pb, m);
        const Eigen::Quaterniond Q = testing::random_rotation(rng);
        const Eigen::Vector3d T = testing::random_vector(rng);
        const Pose pose_a{T, Q}, pose_ell{T + Q * ce, Q * qe};
        const Shape a = kind == 0 ? Shape::sphere(radius) : Shape::capsule(radius, half);
        const Shape ell = Shape::ellipsoid(r.x(), r.y(), r.z());
        SCOPED_TRACE("swap " + std::to_string(swap) + " kind " + std::to_string(kind) + " trial " +
                     std::to_string(trial) + " gap " + std::to_string(gap));
        tally.run(a, pose_a, ell, pose_ell, swap, opt, gap);
      }
    }
  }
  tally.expect_at_least(9, 10);
}

/// Cylinder and cone contacts with an ellipsoid, built with a known gap: x on the round core (a rim point, a side or
/// slant point, a point of the cap's interior, a cone's apex), m in x's normal cone (rim: between the cap normal and
/// the lateral normal; side / slant: the lateral normal; cap: the axis; apex: around the axis, inside the apex's
/// normal cone 2 hy m_z >= r |m_xy|), the ellipsoid touching the plane through pb = x + gap m orthogonal to m from
/// beyond (ellipsoid_touching()), so gap is the distance. Close witness double cylinder-ellipsoid took 13.3 mean
/// bench iterations (cone-ellipsoid 14.4) before wide_gjk_round_ellipsoid.inl's start point; with it the first
/// plain step certifies the start in almost every lane, in either pair order.
TEST(WideGjk, CylinderAndConeAgainstEllipsoidStartByNewton) {
  Rng rng(2029);
  const double two_pi = 6.283185307179586;
  const QueryOptions opt = StartTally::options();
  StartTally tally;
  for (const bool cone : {false, true}) {
    for (const bool swap : {false, true}) {
      for (const int kind : {0, 1, 2, 3}) {  // rim, side / slant, cap, apex (a cylinder: its other cap)
        for (int trial = 0; trial < 40; ++trial) {
          const double r = testing::uniform(rng, 0.03, 0.3), hy = testing::uniform(rng, 0.03, 0.3);
          const Eigen::Vector3d rad(testing::uniform(rng, 0.03, 0.3), testing::uniform(rng, 0.03, 0.3),
                                    testing::uniform(rng, 0.03, 0.3));
          const double th = testing::uniform(rng, 0, two_pi);
          const Eigen::Vector3d radial(std::cos(th), std::sin(th), 0), ez = Eigen::Vector3d::UnitZ();
          const Eigen::Vector3d lateral = cone ? (2 * hy * radial + r * ez).normalized() : radial;
          const double top = cone ? -1.0 : (kind == 3 ? -1.0 : 1.0);  // the rim's / cap's side: a cone's base
          Eigen::Vector3d x, m;
          if (kind == 0) {
            x = r * radial + top * hy * ez;
            const double lambda = testing::uniform(rng, 0.1, 0.9);
            m = (1 - lambda) * lateral + lambda * top * ez;
          } else if (kind == 1) {
            const double sg = testing::uniform(rng, 0.1, 0.9);
            x = cone ? Eigen::Vector3d(sg * r * radial.x(), sg * r * radial.y(), hy - 2 * hy * sg)
                     : Eigen::Vector3d(r * radial.x(), r * radial.y(), (2 * sg - 1) * hy);
            m = lateral;
          } else if (kind == 2 || !cone) {
            x = testing::uniform(rng, 0, 0.9) * r * radial + top * hy * ez;
            m = top * ez;
          } else {
            x = hy * ez;
            m = radial * testing::uniform(rng, 0, 0.9) * 2 * hy / r + ez;  // inside the apex's normal cone
          }
          m.normalize();
          const double gap = std::pow(10.0, testing::uniform(rng, -5, -1));
          const auto [ce, qe] = ellipsoid_touching(rng, rad, x + gap * m, m);
          const Eigen::Quaterniond Q = testing::random_rotation(rng);
          const Eigen::Vector3d T = testing::random_vector(rng);
          const Pose pose_round{T, Q}, pose_ell{T + Q * ce, Q * qe};
          const Shape round = cone ? Shape::cone(r, hy) : Shape::cylinder(r, hy);
          const Shape ell = Shape::ellipsoid(rad.x(), rad.y(), rad.z());
          SCOPED_TRACE("cone " + std::to_string(cone) + " swap " + std::to_string(swap) + " kind " +
                       std::to_string(kind) + " trial " + std::to_string(trial) + " gap " + std::to_string(gap));
          tally.run(round, pose_round, ell, pose_ell, swap, opt, gap);
        }
      }
    }
  }
  // Measured 540 of 640 (3 Newton steps leave some rim and slant contacts a little off, a few more iterations);
  // without the start almost none of these pairs converges in 2.
  tally.expect_at_least(3, 4);
}

TEST(WideGjk, StartCellsOfTheLanesAreTheScalarStartCell) {
  // The large-hull supports look up the direction table with the cells start_cells() computes W lanes at a time;
  // the reference computes start_cell() per call. They must name the same cell (or none) for every direction:
  // random, of every magnitude, on cube edges and corners (face ties), on cell boundaries, tiny (no cell, or
  // just one), zero and NaN.
  Rng rng(52);
  std::vector<Eigen::Vector3d> dirs;
  for (int q = 0; q < 4000; ++q)
    dirs.push_back(testing::random_unit_vector(rng) * std::pow(10.0, double(q % 60) - 30.0));
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        for (const double scale : {1.0, 3e-7, 1e-300, 1e-310, 1e-39, 1e-37, 1e30})
          dirs.push_back(Eigen::Vector3d(x, y, z) * scale);
  for (int q = 0; q < 2000; ++q) {  // exactly on a cell boundary of one face, and the neighbouring doubles
    Eigen::Vector3d d(1.0, double(q % (kHullStartGrid + 1)) * 2 / kHullStartGrid - 1.0,
                      double(q / 7 % (kHullStartGrid + 1)) * 2 / kHullStartGrid - 1.0);
    if (q % 3 == 1) d.y() = std::nextafter(d.y(), 2.0);
    if (q % 3 == 2) d.z() = std::nextafter(d.z(), -2.0);
    const int axis = q % 3;
    std::swap(d[0], d[axis]);
    dirs.push_back(q % 2 ? -d : d);
    dirs.push_back(dirs.back() * 1e-20);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  dirs.push_back(Eigen::Vector3d(nan, 1.0, 0.5));
  dirs.push_back(Eigen::Vector3d(1.0, nan, 0.5));
  dirs.push_back(Eigen::Vector3d(nan, nan, nan));
  dirs.push_back(Eigen::Vector3d(inf, 1.0, -2.0));
  expect_start_cells_match<double>(dirs);
  std::vector<Eigen::Vector3f> dirs_f;
  for (const auto& d : dirs) dirs_f.push_back(d.cast<float>());
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        for (const float scale : {1e-38f, 1e-40f, 2e-45f, 1e-37f, 3e38f}) dirs_f.push_back(Eigen::Vector3f(x, y, z) * scale);
  expect_start_cells_match<float>(dirs_f);
}

TEST(WideGjk, AutomaticSolverIsRejectedByTheLanes) {
  Rng rng(77);
  QueryOptions options;  // solver automatic: setup_pair resolves it into the parameters
  std::deque<OwnedShapeView> keep;  // the setups' cores point into it: a deque never moves its elements
  const auto setups = make_setups<double>(rng, ShapeType::cylinder, ShapeType::box, 8, options, keep);
  ASSERT_FALSE(setups.empty());
  for (const auto& s : setups) EXPECT_EQ(s.params.solver, Solver::gjk);  // witness level: gjk
  std::vector<kernels::GjkResult<double>> got(setups.size());
  EXPECT_THROW(kernels::simd::gjk_lanes<double>(InstructionSet::scalar, setups.data(), setups.size(), got.data(),
                                                Solver::automatic),
               InputError);
  // The batch-array entry point too: collide() resolves the solver once for every kernel.
  ShapeTable table;
  table.add(Shape::cylinder(0.1, 0.2));
  PairBatch batch;
  batch.add(0, Pose{}, 0, Pose{Eigen::Vector3d(1, 0, 0), Eigen::Quaterniond::Identity()});
  PairResults results;
  results.resize(1);
  const std::uint32_t pair = 0;
  std::uint32_t fallback = 0;
  EXPECT_THROW(kernels::simd::gjk_pairs<double>(InstructionSet::scalar, detail::pair_view(table, batch),
                                                ShapeType::cylinder, ShapeType::cylinder, &pair, 1, options,
                                                detail::result_view(results), &fallback),
               InputError);
}

// The public choice of instruction set follows the CPU: `automatic` runs the best set it has (BATCHCOL_ISA unset),
// a set it lacks is refused with InputError, and every set it has runs collide()'s GJK lanes with the scalar's bits.
TEST(WideGjk, InstructionSetChoiceFollowsTheCpu) {
  const auto sets = runnable_sets();
  ASSERT_EQ(sets.front(), InstructionSet::scalar);
  EXPECT_EQ(sets.back(), kernels::simd::detected_instruction_set());
  if (std::getenv("BATCHCOL_ISA") == nullptr) {
    EXPECT_EQ(resolve_instruction_set(InstructionSet::automatic), sets.back());
  }
  Rng rng(91);
  ShapeTable table;
  const std::uint32_t a = table.add(testing::random_shape(rng, ShapeType::cylinder));
  const std::uint32_t b = table.add(testing::random_shape(rng, ShapeType::convex));
  PairBatch batch;
  for (int i = 0; i < 100; ++i) {
    const Pose pa{testing::random_vector(rng, 0.3), testing::random_rotation(rng)};
    batch.add(a, pa, b, Pose{pa.translation + testing::random_vector(rng, 0.3), testing::random_rotation(rng)});
  }
  QueryOptions o;
  o.level = QueryLevel::witness;
  o.isa = InstructionSet::scalar;
  PairResults reference;
  collide(table, batch, o, reference);
  for (const InstructionSet isa : {InstructionSet::avx2, InstructionSet::avx512}) {
    o.isa = isa;
    PairResults r;
    if (kernels::simd::cpu_has(isa)) {
      collide(table, batch, o, r);
      testing::expect_same_results(reference, r, to_string(isa));
    } else {
      EXPECT_THROW(collide(table, batch, o, r), InputError) << to_string(isa);
    }
  }
}

}  // namespace
}  // namespace batchcol
