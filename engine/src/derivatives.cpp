// Entry points of the derivative API and the analytic / first-order-smoothed derivatives (derivatives.hpp).
#include "batchcol/derivatives.hpp"

#include "counter_rng.hpp"
#include "derivative_ift.hpp"
#include "derivative_pairs.hpp"
#include "derivative_support.hpp"
#include "kernels/simd/wide_gjk.hpp"
#include "shape_table_access.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace batchcol {
namespace detail {

namespace {

// The test of nominal_geometry() without its rotations and scale: a converged witness query between two shapes with
// support maps; fills the witness points, normal and distance of `g`. The gradients-only pass uses it alone, so the
// pairs that get a gradient are the same on both paths.
bool witness_geometry(const ShapeTable& shapes, const PairBatch& batch, const PairResults& results, std::size_t i,
                      PairGeometry& g) {
  if (results.status[i] != Status::converged) return false;
  const std::uint32_t a = batch.shape_a[i], b = batch.shape_b[i];
  if (a >= shapes.size() || b >= shapes.size()) return false;
  const auto& types = ShapeTableAccess::types(shapes);
  if (types[a] == ShapeType::halfspace || types[b] == ShapeType::halfspace) return false;
  g.witness_a = results.witness_a[i];
  g.witness_b = results.witness_b[i];
  g.normal = results.normal[i];
  g.distance = results.distance[i];
  return g.witness_a.allFinite() && g.witness_b.allFinite() && g.normal.allFinite() && std::isfinite(g.distance);
}

}  // namespace

namespace {

// witness_geometry() and the problem's length scale: nominal_geometry() without the rotations (the analytic path
// builds only those of shapes that are not spheres or ellipsoids; SmoothLanes builds theirs eight at a time).
bool scaled_geometry(const ShapeTable& shapes, const PairBatch& batch, const PairResults& results, std::size_t i,
                     PairGeometry& g) {
  if (!witness_geometry(shapes, batch, results, i, g)) return false;
  const std::uint32_t a = batch.shape_a[i], b = batch.shape_b[i];
  g.scale = ShapeTableAccess::bounding_radii(shapes)[a] + ShapeTableAccess::bounding_radii(shapes)[b];
  return true;
}

}  // namespace

bool nominal_geometry(const ShapeTable& shapes, const PairBatch& batch, const PairResults& results, std::size_t i,
                      PairGeometry& g, Eigen::Matrix3d& R_a, Eigen::Matrix3d& R_b) {
  if (!scaled_geometry(shapes, batch, results, i, g)) return false;
  R_a = batch.rotation_a[i].normalized().toRotationMatrix();
  R_b = batch.rotation_b[i].normalized().toRotationMatrix();
  return true;
}

void StoreBlock::add(std::size_t i, const PairJacobians& J) { write_jacobians(J, slot(i), kStride); }

void entry_rows(DerivativeResults& d, std::size_t first, double** rows) {
  const std::size_t n = d.status.size();
  double* const arrays[8] = {d.distance_gradient_a.data.data(), d.distance_gradient_b.data.data(),
                             d.witness_a_wrt_a.data.data(),     d.witness_a_wrt_b.data.data(),
                             d.witness_b_wrt_a.data.data(),     d.witness_b_wrt_b.data.data(),
                             d.normal_wrt_a.data.data(),        d.normal_wrt_b.data.data()};
  // Entries 0-11 are the two 6-vectors, then 18 per matrix: entry e is row e % 6 (vectors) or e - start of the
  // matrix's (6 r + c), which is exactly the SoA index k of data[k * n + i].
  int e = 0;
  for (int a = 0; a < 8; ++a)
    for (int k = 0, count = a < 2 ? 6 : 18; k < count; ++k) rows[e++] = arrays[a] + k * n + first;
}

void StoreBlock::start(std::size_t i) {
  flush();
  first_ = i;
  const auto phase = [](const double* p) { return reinterpret_cast<std::uintptr_t>(p) % 64 / sizeof(double); };
  if (!have_rows_) {
    entry_rows(d, 0, rows_), have_rows_ = true;
    if (isa == InstructionSet::avx512) {
      // The arrays are separate allocations (offsets in a line vary with the allocator's state): the most common
      // phase of the 120 rows.
      std::size_t rows_at[kStride] = {};
      for (int e = 0; e < kEntries; ++e) ++rows_at[phase(rows_[e])];
      phase_ = static_cast<std::size_t>(std::max_element(rows_at, rows_at + kStride) - rows_at);
      aligned_ = true;
      // Non-temporal stores for outputs beyond a core's L2 (1-2 MB on current x86 server cores): their lines would
      // leave the cache before a caller reads them, and a regular store first reads each line it misses.
      stream_ = !normal_b_only && d.status.size() * kEntries * sizeof(double) >= kStreamBytes;
      if (stream_)
        for (int e = 0; e < kEntries; ++e) {
          // Row e's line starts `shift` pairs before a block (a multiple of 8 doubles: rows of doubles).
          const std::size_t shift = (phase(rows_[e]) + kStride - phase_) % kStride;
          stream_rows_.shift[e] = static_cast<std::int64_t>(shift);
          if (shift == 0) stream_rows_.whole[e / 64] |= std::uint64_t(1) << (e % 64);
        }
    }
  }
  // A whole block when pair i's entries start a line in the phase_ rows.
  limit_ = aligned_ ? kStride - (phase_ + i) % kStride : kStride;
}

void StoreBlock::flush() {
  if (count_ == 0) return;
  double* const* const rows = rows_;
  const std::size_t at = first_;
  if (smoothed1_.pending != 0) smoothed1_.finish(smooth_, isa), smoothed1_.clear();
  // A block of smooth pairs only (every ellipsoid pair) straight to the arrays, or of polytope pairs only (hulls):
  // whole blocks on every set, the others (a task range's first and last) in AVX-512's masked registers.
  const bool smooth = smooth_.count == count_, polytope = !smooth && polytope_.count == count_;
  // A whole lane block of a large output is streamed; the previous streamed block's carried entries are stored
  // first unless this block continues its lines.
  const bool streamed = stream_ && count_ == kStride && (smooth || polytope);
  if (stream_rows_.carried && !(streamed && at == last_at_ + kStride)) flush_stream_carry(stream_rows_, rows, last_at_);
  StreamRows* const stream = streamed ? &stream_rows_ : nullptr;
  if (smooth) {
    smooth_.solve(rows, normal_b_only, isa, at, stream);
  } else if (polytope) {
    polytope_.solve(rows, isa, at, stream);
  } else {
    if (smooth_.count > 0 || polytope_.count > 0) {
      double* buffer_rows[kEntries];
      for (int k = 0; k < kEntries; ++k) buffer_rows[k] = buf_[k];
      if (smooth_.count > 0) smooth_.solve(buffer_rows, normal_b_only);
      if (polytope_.count > 0) polytope_.solve(buffer_rows);
    }
    // normal_b_only: only normal_wrt_b's rows are written (and read by the caller); the others are not copied.
    const int first = normal_b_only ? store_at::normal_b : 0, end = normal_b_only ? store_at::normal_b + 18 : kEntries;
    if (count_ == kStride) {  // a full block: fixed-size copies the compiler inlines as vector moves
      for (int k = first; k < end; ++k) std::memcpy(rows[k] + at, buf_[k], sizeof buf_[k]);
    } else {
      for (int k = first; k < end; ++k) std::copy_n(buf_[k], count_, rows[k] + at);
    }
  }
  if (streamed) stream_rows_.carried = true, last_at_ = at;
  smooth_.clear();
  polytope_.clear();
  count_ = 0;
}

void store_nothing(StoreBlock& out, std::size_t i) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  PairJacobians J;
  J.distance_a.setConstant(nan);
  J.distance_b.setConstant(nan);
  for (Mat36* m : {&J.witness_a_a, &J.witness_a_b, &J.witness_b_a, &J.witness_b_b, &J.normal_a, &J.normal_b})
    m->setConstant(nan);
  out.add(i, J);
  DerivativeResults& d = out.d;
  d.status[i] = DerivativeStatus::no_witness;
  if (!d.smoothed_distance.empty()) {
    d.smoothed_distance[i] = nan;
    const Eigen::Vector3d v = Eigen::Vector3d::Constant(nan);
    d.smoothed_witness_a.set(i, v);
    d.smoothed_witness_b.set(i, v);
    d.smoothed_normal.set(i, v);
  }
}

void size_for(DerivativeResults& d, std::size_t n, bool smoothed) {
  d.status.resize(n);
  for (Vec6Array* v : {&d.distance_gradient_a, &d.distance_gradient_b}) v->data.resize(6 * n);
  for (Mat36Array* m : {&d.witness_a_wrt_a, &d.witness_a_wrt_b, &d.witness_b_wrt_a, &d.witness_b_wrt_b,
                        &d.normal_wrt_a, &d.normal_wrt_b})
    m->data.resize(18 * n);
  d.smoothed_distance.resize(smoothed ? n : 0);
  for (Vec3Array* v : {&d.smoothed_witness_a, &d.smoothed_witness_b, &d.smoothed_normal}) v->resize(smoothed ? n : 0);
}

namespace {

// The analytic derivative of a separated pair of hulls without inflation (the polytope common case), without
// differentiate_pair()'s general setup: no rotation matrices (the quaternions turn n into each local frame and an
// edge back), the features from the vertices n exposes (exposed_feature()), straight into PolytopeLanes. The same
// features, statuses and formulas as the general path; false (nothing written) for any other pair.
// `g`: the caller's, reused from pair to pair (every field this pair reads is written first): a PairGeometry per
// pair zeroed its two flat matrices, 5 instructions per pair (callgrind AVX2).
// `directions`: the block's quaternions and local directions (hull_directions_block(), computed here at the block's
// first pair that needs them), or null.
bool hull_pair(const ShapeTable& shapes, const PairBatch& batch, const PairResults& results, std::size_t i,
               StoreBlock& out, PairGeometry& g, HullDirections* directions) {
  if (results.status[i] != Status::converged) return false;
  const std::uint32_t a = batch.shape_a[i], b = batch.shape_b[i];
  // The per-shape arrays grow with the table (ShapeTable::add()): types.size() is shapes.size() without its
  // division by sizeof(Shape).
  const auto& types = ShapeTableAccess::types(shapes);
  if (a >= types.size() || b >= types.size()) return false;
  const auto& inflations = ShapeTableAccess::inflations(shapes);
  if (types[a] != ShapeType::convex || types[b] != ShapeType::convex || inflations[a] != 0.0 ||
      inflations[b] != 0.0)
    return false;
  const auto& radii = ShapeTableAccess::bounding_radii(shapes);
  g.distance = results.distance[i];
  g.scale = radii[a] + radii[b];
  // Touching, penetrating (and NaN): the general path; past the first test only +inf is not finite.
  if (!(g.distance > 1e-9 * g.scale) || !(g.distance < std::numeric_limits<double>::infinity())) return false;
  g.witness_a = results.witness_a[i];
  g.witness_b = results.witness_b[i];
  g.normal = results.normal[i];
  if (!g.witness_a.allFinite() || !g.witness_b.allFinite() || !g.normal.allFinite()) return false;
  const auto& hulls = ShapeTableAccess::hulls(shapes);
  // Both sides' flats in one call (hull_pair_flats_packed(), as hull_pair_flats(): n in each hull's frame, b's
  // reversed, with the bits of the per-side Eigen expressions q.normalized(), sign * (unit.conjugate() * n); the
  // features n exposes; an edge's direction in the world orthogonal to n). A face's flats are only needed by the general path below
  // (PolytopeLanes uses n).
  Eigen::Vector3d flat[2];
  const double tolerance[2] = {kExposedFeature * radii[a], kExposedFeature * radii[b]};
  if (directions && !directions->filled) {
    hull_directions_block(batch.rotation_a, batch.rotation_b, results.normal, directions->block_first,
                          directions->block_count, *directions);
    directions->filled = true;
  }
  const int flats = hull_pair_flats_packed(batch.rotation_a, batch.rotation_b, i, g.normal, hulls[a], hulls[b],
                                           tolerance, flat, out.isa, directions);
  g.flats_a = flats & 3, g.flats_b = flats >> 2;
  if (g.flats_a == 1) g.flat_a.col(0) = flat[0];
  if (g.flats_b == 1) g.flat_b.col(0) = flat[1];
  const DerivativeStatus status =
      g.flats_a == 0 || g.flats_b == 0 ? DerivativeStatus::zero_curvature : DerivativeStatus::smooth;
  DerivativeResults& d = out.d;
  double* slot = nullptr;
  // polytope_pair(g) without its tests of what this function has already established (separated beyond the
  // threshold, H_a = H_b = 0): its two isZero() scans of the zeros just stored cost ~75 instructions per hull pair.
  if (g.flats_a + g.flats_b <= 2) {
    slot = out.add_polytope(i, g);
    if (!slot) {
      d.status[i] = status;
      return true;
    }
  }
  // The general path below reads the (zero) curvature; PolytopeLanes does not.
  g.H_a.setZero();
  g.H_b.setZero();
  // A face's flats: the tangent plane of n (support_jacobian() projects them on it too).
  const auto face = [&](int flats, Eigen::Matrix<double, 3, 2>& flat) {
    if (flats != 2) return;
    const Eigen::Vector3d t = g.normal.unitOrthogonal();
    flat.col(0) = t;
    flat.col(1) = g.normal.cross(t);
  };
  face(g.flats_a, g.flat_a);
  face(g.flats_b, g.flat_b);
  const IftFlags J = implicit_jacobians(g, slot ? slot : out.slot(i), StoreBlock::kStride);
  d.status[i] = J.dependent ? DerivativeStatus::nonsmooth : J.singular ? DerivativeStatus::singular : status;
  return true;
}

// One pair, analytic or smoothed1. The support directions are n for a and -n for b, taken to each local frame.
void differentiate_pair(const ShapeTable& shapes, const PairBatch& batch, const PairResults& results,
                        const DerivativeOptions& o, InstructionSet isa, std::size_t i, StoreBlock& out,
                        PairGeometry& hull_geometry, const double* noise,
                        HullDirections* directions = nullptr) {
  if (o.method == DerivativeMethod::analytic && hull_pair(shapes, batch, results, i, out, hull_geometry, directions))
    return;
  DerivativeResults& d = out.d;
  PairGeometry g;
  Eigen::Matrix3d R_a, R_b;  // the analytic path sets them only where it uses them (see side())
  const bool analytic = o.method == DerivativeMethod::analytic;
  if (!(analytic ? scaled_geometry(shapes, batch, results, i, g)
                 : nominal_geometry(shapes, batch, results, i, g, R_a, R_b))) {
    store_nothing(out, i);
    return;
  }
  const Shape& a = shapes[batch.shape_a[i]];
  const Shape& b = shapes[batch.shape_b[i]];
  DerivativeStatus status = DerivativeStatus::smooth;
  if (analytic) {
    // Spheres and ellipsoids (no features, no flats): their support-map Jacobian is left to the lanes of
    // SmoothLanes (or computed below when the other side has flats), which also build their rotations; the others
    // go through their local frame, where the features are tested.
    const auto plain_polytope = [](const Shape& s) {
      return s.inflation == 0.0 &&
             (s.type == ShapeType::convex || s.type == ShapeType::box || s.type == ShapeType::triangle);
    };
    // Separated pairs only: GJK ends on the exact features. (EPA's normals were exact on the saved overlapping hull
    // batches too, but EPA stops at a tolerance, and those pairs take the general solve anyway.)
    const bool exact_normal = g.distance > 0.0 && plain_polytope(a) && plain_polytope(b);
    const auto is_round = [](const Shape& s) { return s.type == ShapeType::sphere || s.type == ShapeType::ellipsoid; };
    const auto round_side = [](const Shape& s, const Eigen::Quaterniond& rotation, CurvedSide& curved) {
      for (int k = 0; k < 4; ++k) curved.q[k] = rotation.coeffs()[k];
      if (s.type == ShapeType::ellipsoid) curved.radii2 = s.size.cwiseProduct(s.size);
      curved.round = s.inflation + (s.type == ShapeType::sphere ? s.size.x() : 0.0);
    };
    const auto side = [&](const Shape& s, const Eigen::Quaterniond& rotation, Eigen::Matrix3d& R,
                          const Eigen::Vector3d& witness, const Eigen::Vector3d& t, double sign, Eigen::Matrix3d& H,
                          int& flats, Eigen::Matrix<double, 3, 2>& flat, bool& zero) {
      R = rotation.normalized().toRotationMatrix();
      const Eigen::Vector3d u = sign * (R.transpose() * g.normal);
      // Against a polytope, a hull's feature is the one n exposes (exposed_support_jacobian()); otherwise the
      // witness's position decides (GJK's normal is not exact against curved shapes).
      const SupportJacobian J = exact_normal && s.type == ShapeType::convex
                                    ? exposed_support_jacobian(s, u)
                                    : support_jacobian(s, u, R.transpose() * (witness - t));
      // Polytopes without inflation have no curvature: skip the two 3x3 products.
      if (J.H.isZero(0.0)) H.setZero();
      else H = R * J.H * R.transpose();
      flats = J.flats;
      if (flats > 0) flat = R * J.flat;
      zero = J.zero;
    };
    bool zero_a = false, zero_b = false;
    CurvedSide curved_a, curved_b;
    const Eigen::Quaterniond q_a = batch.rotation_a[i], q_b = batch.rotation_b[i];
    // Sphere and ellipsoid sides without side()'s call (~100 instructions per ellipsoid pair with its arguments).
    const bool round_a = is_round(a), round_b = is_round(b);
    if (round_a) round_side(a, q_a, curved_a);
    else side(a, q_a, R_a, g.witness_a, batch.translation_a[i], 1.0, g.H_a, g.flats_a, g.flat_a, zero_a);
    if (round_b) round_side(b, q_b, curved_b);
    else side(b, q_b, R_b, g.witness_b, batch.translation_b[i], -1.0, g.H_b, g.flats_b, g.flat_b, zero_b);
    if (zero_a || zero_b) status = DerivativeStatus::zero_curvature;
    // Polytopes without inflation (no curvature) go to PolytopeLanes below.
    if (smooth_pair(g) && (round_a || round_b || !g.H_a.isZero(0.0) || !g.H_b.isZero(0.0))) {
      out.add_smooth(i, g, round_a ? &curved_a : nullptr, round_b ? &curved_b : nullptr);
      d.status[i] = status;
      return;
    }
    if (round_a) world_support_jacobian(a, q_a.normalized().toRotationMatrix(), g.normal, g.H_a);
    if (round_b) world_support_jacobian(b, q_b.normalized().toRotationMatrix(), g.normal, g.H_b);
  } else {
    const Eigen::Vector3d u_a = R_a.transpose() * g.normal, u_b = -(R_b.transpose() * g.normal);
    const auto direction_noise = [&](const Shape& s) {
      return o.noise_scale == NoiseScale::relative ? o.noise : o.noise / s.bounding_radius();
    };
    // The pair's noise, drawn by differentiate_results_on() for 8 pairs at a time: side a's coordinate c at c draws,
    // b's at (3 + c) draws (the estimate reads coordinates 0 .. 2; z[3] is never read).
    const std::size_t draws = static_cast<std::size_t>(o.samples + 1) / 2;
    const double* const z_a[4] = {noise, noise + draws, noise + 2 * draws, noise + 2 * draws};
    const double* const z_b[4] = {noise + 3 * draws, noise + 4 * draws, noise + 5 * draws, noise + 5 * draws};
    Eigen::Matrix3d S_a =
        smoothed_support_estimate(shapes, batch.shape_a[i], u_a, direction_noise(a), o.samples, z_a, isa);
    Eigen::Matrix3d S_b =
        smoothed_support_estimate(shapes, batch.shape_b[i], u_b, direction_noise(b), o.samples, z_b, isa);
    // Separated pairs (every smooth_pair(): smoothed1 has no flats): the projections and rotations for the block's
    // pairs together at the flush, with these bits.
    if (smooth_pair(g)) {
      out.add_smoothed1(i, g, S_a, S_b, R_a, R_b);
      d.status[i] = status;
      return;
    }
    S_a = psd_projection(S_a);  // touching / overlapping pairs only (rare): the scalar projection
    S_b = psd_projection(S_b);
    g.H_a = R_a * S_a * R_a.transpose();
    g.H_b = R_b * S_b * R_b.transpose();
  }
  double* slot = nullptr;
  if (o.method == DerivativeMethod::analytic && polytope_pair(g)) {
    slot = out.add_polytope(i, g);
    if (!slot) {
      d.status[i] = status;
      return;
    }
  } else if (smooth_pair(g)) {
    out.add_smooth(i, g);
    d.status[i] = status;
    return;
  }
  const IftFlags J = implicit_jacobians(g, slot ? slot : out.slot(i), StoreBlock::kStride);
  d.status[i] = J.dependent ? DerivativeStatus::nonsmooth : J.singular ? DerivativeStatus::singular : status;
}

// The distance gradients alone (DerivativeOptions::jacobians false): distance_gradients()'s envelope formula from the
// witness results of every pair witness_geometry() (and so nominal_geometry()) accepts (the pairs the full derivative gives a gradient), without
// rotations, features or the implicit-function solve. Pairs go through a 12 x 8 buffer and each array gets 8
// consecutive entries per flush, for StoreBlock's reason: 12 arrays a power of two apart written pair by pair would
// share one L1 set.
void gradients_only(const ShapeTable& shapes, const PairBatch& batch, const PairResults& results, int threads,
                    DerivativeResults& d) {
  const std::size_t n = batch.size();
  d.status.resize(n);
  d.distance_gradient_a.data.resize(6 * n);
  d.distance_gradient_b.data.resize(6 * n);
  for (Mat36Array* m : {&d.witness_a_wrt_a, &d.witness_a_wrt_b, &d.witness_b_wrt_a, &d.witness_b_wrt_b,
                        &d.normal_wrt_a, &d.normal_wrt_b})
    m->data.clear();
  d.smoothed_distance.clear();
  for (Vec3Array* v : {&d.smoothed_witness_a, &d.smoothed_witness_b, &d.smoothed_normal}) v->resize(0);
  double* const ga = d.distance_gradient_a.data.data();
  double* const gb = d.distance_gradient_b.data.data();
  for_pairs(threads, n, [&](std::size_t begin, std::size_t end) {
    constexpr std::size_t kBlock = 8;
    double buf[12][kBlock];
    PairGeometry g;
    Row6 grad_a, grad_b;
    for (std::size_t first = begin; first < end; first += kBlock) {
      const std::size_t count = std::min(kBlock, end - first);
      for (std::size_t j = 0; j < count; ++j) {
        const std::size_t i = first + j;
        const bool ok = witness_geometry(shapes, batch, results, i, g);
        if (ok) {
          distance_gradients(g, grad_a, grad_b);
        } else {
          grad_a.setConstant(std::numeric_limits<double>::quiet_NaN());
          grad_b = grad_a;
        }
        for (int k = 0; k < 6; ++k) buf[k][j] = grad_a(k), buf[6 + k][j] = grad_b(k);
        d.status[i] = ok ? DerivativeStatus::smooth : DerivativeStatus::no_witness;
      }
      for (int k = 0; k < 6; ++k) {
        std::copy_n(buf[k], count, ga + k * n + first);
        std::copy_n(buf[6 + k], count, gb + k * n + first);
      }
    }
  });
}

void check_sizes(const PairBatch& batch, const PairResults& results) {
  const std::size_t n = batch.size();
  if (results.size() != n || results.distance.size() != n || results.witness_a.size() != n ||
      results.witness_b.size() != n || results.normal.size() != n)
    throw InputError("results: need one witness-level result per pair of the batch (" + std::to_string(n) +
                     " pairs; run collide() at QueryLevel::witness or penetration)");
}

/// differentiate_results() with the smoothed1 noise drawn by `isa`'s kernels (the same bits on every set: the
/// choice only follows QueryOptions::isa when differentiate() calls it).
void differentiate_results_on(const ShapeTable& shapes, const PairBatch& batch, const PairResults& results,
                              const DerivativeOptions& options, int threads, InstructionSet isa,
                              DerivativeResults& derivatives, bool normal_b_only = false) {
  validate(options);
  if (options.method == DerivativeMethod::smoothed0)
    throw InputError("method: smoothed0 runs new queries; call differentiate() instead of differentiate_results()");
  if (threads < 0) throw InputError("threads must be >= 0 (0 = all cores)");
  detail::check_sizes(batch, results);
  if (!options.jacobians) {
    detail::gradients_only(shapes, batch, results, threads, derivatives);
    return;
  }
  detail::size_for(derivatives, batch.size(), false);  // every pair writes all its entries
  detail::for_pairs(threads, batch.size(), [&](std::size_t begin, std::size_t end) {
    detail::StoreBlock out(derivatives);
    out.normal_b_only = normal_b_only;
    out.isa = isa;
    detail::PairGeometry hull_geometry;
    if (options.method != DerivativeMethod::smoothed1) {
      // The wide sets' hull pairs take their directions from 8 pairs computed side by side (HullDirections).
      if (isa != InstructionSet::avx2 && isa != InstructionSet::avx512) {
        for (std::size_t i = begin; i < end; ++i)
          differentiate_pair(shapes, batch, results, options, isa, i, out, hull_geometry, nullptr);
        return;
      }
      detail::HullDirections directions;
      for (std::size_t first = begin; first < end; first += detail::HullDirections::kPairs) {
        const std::size_t count = std::min(detail::HullDirections::kPairs, end - first);
        directions.block_first = first, directions.block_count = count, directions.filled = false;
        for (std::size_t i = first; i < first + count; ++i)
          differentiate_pair(shapes, batch, results, options, isa, i, out, hull_geometry, nullptr, &directions);
      }
      return;
    }
    // smoothed1: the 3 normals of every antithetic pair k of both sides (counter_rng.hpp's support_noise_pair(),
    // 6 per k) of kChunk pairs at a time, drawn by the SIMD kernels with a pair per lane (the same bits on every
    // set). The former draw, gaussian_vector<4>(seed, i, k, stream) per side and k with its own key set-up, cost
    // 570 instructions a pair at M = 4 (callgrind AVX2, convex8).
    constexpr std::size_t kChunk = 8;
    const std::size_t per_pair = 6 * (static_cast<std::size_t>(options.samples + 1) / 2);
    thread_local std::vector<double> noise;
    if (noise.size() < kChunk * per_pair) noise.resize(kChunk * per_pair);
    const std::uint64_t seed_key = detail::splitmix64(options.seed);
    for (std::size_t first = begin; first < end; first += kChunk) {
      const std::size_t count = std::min(kChunk, end - first);
      std::uint64_t keys[kChunk];
      for (std::size_t j = 0; j < count; ++j) keys[j] = detail::splitmix64(seed_key ^ (first + j));
      kernels::simd::draw_support_noise(isa, keys, count, per_pair / 6, noise.data());
      for (std::size_t j = 0; j < count; ++j)
        differentiate_pair(shapes, batch, results, options, isa, first + j, out, hull_geometry,
                           noise.data() + j * per_pair);
    }
  });
}

}  // namespace

void analytic_normal_b(const ShapeTable& shapes, const PairBatch& batch, const PairResults& results,
                       const DerivativeOptions& analytic, int threads, InstructionSet isa,
                       DerivativeResults& derivatives) {
  differentiate_results_on(shapes, batch, results, analytic, threads, isa, derivatives, true);
}
}  // namespace detail

void differentiate_results(const ShapeTable& shapes, const PairBatch& batch, const PairResults& results,
                           const DerivativeOptions& options, int threads, DerivativeResults& derivatives) {
  detail::differentiate_results_on(shapes, batch, results, options, threads, resolve_instruction_set(), derivatives);
}

void differentiate(const ShapeTable& shapes, const PairBatch& batch, const QueryOptions& query,
                   const DerivativeOptions& options, PairResults& results, DerivativeResults& derivatives) {
  validate(options);
  validate(query);
  if (query.level < QueryLevel::witness)
    throw InputError(std::string("level: derivatives need witness points (QueryLevel::witness or penetration), got ") +
                     to_string(query.level));
  collide(shapes, batch, query, results);
  if (options.method == DerivativeMethod::smoothed0) {
    detail::smoothed0(shapes, batch, query, options, results, derivatives);
  } else {
    detail::differentiate_results_on(shapes, batch, results, options, query.threads,
                                     resolve_instruction_set(query.isa), derivatives);
  }
}

}  // namespace batchcol
