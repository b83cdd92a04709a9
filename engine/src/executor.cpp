// The batch executor: validate, group pairs by shape-pair type, run tiles of pairs on TBB, write results in input
// order. Inside a tile, pairs of one type go through the SIMD GJK together (one pair per lane); every lane repeats
// the scalar reference's operations, so results are bitwise identical for any thread count and instruction set.
#include "batchcol/batch.hpp"
#include "kernels/narrowphase.hpp"
#include "kernels/segment_pairs_world.hpp"
#include "kernels/simd/wide_closed_forms.hpp"
#include "kernels/simd/wide_gjk.hpp"
#include "kernel_views.hpp"
#include "results_fill.hpp"
#include "shape_table_access.hpp"
#include "validate.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>

namespace batchcol {
namespace {

/// Largest tile (pairs per task): small enough that the task's slice of the 14 input and 13 output arrays
/// (~0.9 MB, ~230 bytes per pair) stays in a core's L2 (2 MB on the Xeons measured) while its pairs are visited
/// out of order (grouped by type), large enough that a mixed batch's type groups keep the GJK lanes full: every
/// group's run ends by draining its lanes (W pairs in flight, fewer and fewer live), and the demo's 49 type pairs
/// left ~21 pairs per group in a 1024-pair tile. 1024 -> 4096, demo --pairs 50000 --threads 1, callgrind AVX2:
/// 2098 -> 1997 instructions per pair (the GJK loop 1425 -> 1364, the per-group set-up of run_plain 16 -> 4).
constexpr std::size_t kMaxTilePairs = 4096;
/// Smallest tile: a TBB task costs ~1 us to schedule, as much as ~50 closed-form pairs; 128 keeps that below ~20%
/// for the cheapest kernels and far below 1% for GJK pairs (~0.1-3 us each).
constexpr std::size_t kMinTilePairs = 128;
/// Tiles per worker thread when the batch is small enough to need sizing: GJK pairs differ in cost by 10x
/// (iterations), so a thread needs several tiles for the two threads' work to end together.
constexpr std::size_t kTilesPerThread = 8;

/// Pairs per tile for a batch of n pairs on `threads` workers: a fixed 1024 left a batch of up to 1024 GJK pairs on
/// one thread. A pair's result does not depend on its tile (no state crosses pairs), so this changes no bit.
std::size_t tile_pairs(std::size_t n, int threads) {
  const std::size_t workers = static_cast<std::size_t>(std::max(threads, 1));
  const std::size_t even = (n + workers * kTilesPerThread - 1) / (workers * kTilesPerThread);
  return std::clamp(even, kMinTilePairs, kMaxTilePairs);
}

constexpr std::size_t kTypePairs = kShapeTypeCount * kShapeTypeCount;
/// Start of each shape-pair type's run in a tile's `order`; group g is order[start[g] .. start[g + 1]).
using GroupStarts = std::array<std::uint32_t, kTypePairs + 1>;

/// All n pairs of a tile in group `group`, in input order.
void one_group(std::size_t group, std::size_t n, std::vector<std::uint32_t>& order, GroupStarts& groups) {
  for (std::size_t k = 0; k < n; ++k) order[k] = static_cast<std::uint32_t>(k);
  for (std::size_t g = group + 1; g < groups.size(); ++g) groups[g] = static_cast<std::uint32_t>(n);
}

/// Indices [begin, end) of the batch sorted by (type of a, type of b), stable: pairs of one kernel run back to
/// back. Grouping stays inside a tile so that memory access stays local. `keys` is scratch.
void group_by_type(const ShapeTable& shapes, const PairBatchView& batch, std::size_t begin, std::size_t end,
                   std::vector<std::uint32_t>& order, std::vector<std::uint8_t>& keys, GroupStarts& groups) {
  static_assert(kTypePairs <= 256, "keys are bytes");
  const std::size_t n = end - begin, count = shapes.size();
  keys.resize(n);
  order.resize(n);
  groups.fill(0);
  if (n == 0) return;
  // Plain local pointers: a store through std::uint8_t* may alias anything, so with the vectors' own pointers the
  // compiler reloads every one of them after each key. Types come from the table's contiguous type array.
  const ShapeType* const type = detail::ShapeTableAccess::types(shapes).data();
  const std::uint32_t* const shape_a = batch.shape_a.data() + begin;
  const std::uint32_t* const shape_b = batch.shape_b.data() + begin;
  std::uint8_t* const key = keys.data();
  const auto key_of = [&](std::size_t k) {
    const std::uint32_t a = shape_a[k], b = shape_b[k];
    // Invalid pairs go to group 0; whatever kernel runs them rejects them per pair. (Branches: a branch-free
    // version reading shape 0's types for them cost more.)
    return a < count && b < count
               ? static_cast<std::uint8_t>(static_cast<std::size_t>(type[a]) * kShapeTypeCount +
                                           static_cast<std::size_t>(type[b]))
               : std::uint8_t{0};
  };
  if (detail::ShapeTableAccess::one_type(shapes)) {
    // Every pair is of the table's one type pair, read from no pair (grouping then costs a few instructions per
    // pair instead of a dozen). Pairs with an invalid index join that group; its kernels reject them per pair, as
    // group 0's do below.
    const auto group = static_cast<std::uint8_t>(static_cast<std::size_t>(type[0]) * kShapeTypeCount +
                                                 static_cast<std::size_t>(type[0]));
    std::memset(key, group, n);  // run_generic() reads the keys of the pairs the kernels give back
    one_group(group, n, order, groups);
    return;
  }
  const std::uint8_t first = key_of(0);
  unsigned differ = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint8_t kk = key_of(k);
    key[k] = kk;
    differ |= unsigned(kk ^ first);
  }
  const bool uniform = differ == 0;
  if (uniform) {  // one type (the common case in large batches): no sort
    one_group(keys[0], n, order, groups);
    return;
  }
  GroupStarts start{};
  for (std::size_t k = 0; k < n; ++k) ++start[keys[k] + 1];
  for (std::size_t g = 1; g < start.size(); ++g) start[g] += start[g - 1];
  groups = start;
  for (std::size_t k = 0; k < n; ++k) order[start[keys[k]]++] = static_cast<std::uint32_t>(k);
}

ShapeType type_a(std::size_t group) { return static_cast<ShapeType>(group / kShapeTypeCount); }
ShapeType type_b(std::size_t group) { return static_cast<ShapeType>(group % kShapeTypeCount); }

using kernels::simd::WideClosedForm;
/// Which SIMD closed form answers a group of this shape-pair type, if any.
WideClosedForm wide_closed_form(std::size_t group, const QueryOptions& options) {
  return kernels::simd::wide_closed_form(type_a(group), type_b(group), options);
}

/// Whether a group's pairs run through the SIMD GJK straight from the batch arrays (kernels::simd::gjk_pairs):
/// below QueryLevel::penetration (EPA stays per pair), without warm start, for types other than triangle and
/// halfspace, when setup_pair_into() has no closed form for the type pair.
bool wide_gjk_group(std::size_t group, const QueryOptions& options, const PairBatchView& batch) {
  if (options.level >= QueryLevel::penetration || !batch.warm_start.empty()) return false;
  const ShapeType a = type_a(group), b = type_b(group);
  const auto plain = [](ShapeType t) { return t != ShapeType::triangle && t != ShapeType::halfspace; };
  return plain(a) && plain(b) && !kernels::may_have_closed_form(a, b, options);
}

/// World frame of shape A for one pair: outputs are computed in A's frame and mapped back with it.
struct PairFrame {
  Eigen::Matrix3d Ra;
  Eigen::Vector3d ta;
};

/// Pairs of one shape-pair type handed to the SIMD kernels at once: enough to keep every lane busy through the
/// refills, few enough that their setups (~0.5 KB each) stay in L1/L2.
constexpr std::size_t kChunkPairs = 64;

/// Per-task scratch, reused across the task's tiles.
template <class T> struct ChunkScratch {
  std::vector<kernels::PairSetup<T>> setups;
  std::vector<kernels::GjkResult<T>> gjk;
  std::vector<PairFrame> frames;
  std::vector<std::uint32_t> pairs;
  std::vector<std::uint32_t> order;
  std::vector<std::uint8_t> keys;
  GroupStarts groups{};
  std::vector<std::uint32_t> group_pairs;  // one group's batch indices
  std::vector<std::uint32_t> fallback;     // pairs the SIMD closed forms left to the scalar path
};

/// Validates pair i, computes B's pose in A's frame (double) and the setup. Returns false for an invalid pair
/// (status invalid_input written; everything else stays NaN / 0 from fill_pair_defaults). The pose arithmetic is
/// spelled out (kernels/math.hpp) so that every path computing a relative pose gets the same bits.
template <class T>
bool prepare_pair(const ShapeTable& shapes, const PairBatchView& batch, const QueryOptions& options, std::size_t i,
                  PairFrame& frame, kernels::PairSetup<T>& setup, PairResults& out) {
  const std::uint32_t ia = batch.shape_a[i], ib = batch.shape_b[i];
  double qa[4] = {batch.rotation_a.w[i], batch.rotation_a.x[i], batch.rotation_a.y[i], batch.rotation_a.z[i]};
  double qb[4] = {batch.rotation_b.w[i], batch.rotation_b.x[i], batch.rotation_b.y[i], batch.rotation_b.z[i]};
  const Eigen::Vector3d ta = batch.translation_a[i], tb = batch.translation_b[i];
  if (ia >= shapes.size() || ib >= shapes.size() || !detail::normalize_unit_quaternion(qa) ||
      !detail::normalize_unit_quaternion(qb) || !detail::translation_in_range(ta) || !detail::translation_in_range(tb)) {
    out.status[i] = Status::invalid_input;
    return false;
  }
  frame.Ra = kernels::rotation_matrix(qa[0], qa[1], qa[2], qa[3]);
  frame.ta = ta;
  kernels::RelativePose b_in_a;
  b_in_a.R = kernels::transposed_product(frame.Ra, kernels::rotation_matrix(qb[0], qb[1], qb[2], qb[3]));
  b_in_a.t = kernels::mul_transposed<double>(frame.Ra, tb - ta);
  Eigen::Vector3d warm = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  if (!batch.warm_start.empty()) warm = kernels::mul_transposed<double>(frame.Ra, batch.warm_start[i]);
  // Views into the table: a convex core keeps a pointer to the table's hull view, which outlives the chunk.
  kernels::setup_pair_into<T>(detail::ShapeTableAccess::view(shapes, ia), detail::ShapeTableAccess::view(shapes, ib),
                              b_in_a, warm, options, setup);
  return true;
}

/// Sphere and capsule pairs with closed forms on: world segments and the closed form, in double, without the
/// relative frame and the setup. Returns false (nothing written) when the pair is not one, or is invalid: the
/// generic path then answers it.
bool solve_segment_pair(const ShapeTable& shapes, const PairBatchView& batch, const QueryOptions& options, std::size_t i,
                        PairResults& out) {
  const std::uint32_t ia = batch.shape_a[i], ib = batch.shape_b[i];
  if (ia >= shapes.size() || ib >= shapes.size()) return false;
  const auto& types = detail::ShapeTableAccess::types(shapes);
  if (!kernels::is_segment_shape(types[ia]) || !kernels::is_segment_shape(types[ib])) return false;
  const ShapeView a = detail::ShapeTableAccess::view(shapes, ia), b = detail::ShapeTableAccess::view(shapes, ib);
  const auto qa = detail::unit_quaternion(batch.rotation_a[i]);
  const auto qb = detail::unit_quaternion(batch.rotation_b[i]);
  const Eigen::Vector3d ta = batch.translation_a[i], tb = batch.translation_b[i];
  if (!qa || !qb || !detail::translation_in_range(ta) || !detail::translation_in_range(tb)) return false;
  const kernels::WorldSegment A = kernels::world_segment(a, *qa, ta), B = kernels::world_segment(b, *qb, tb);
  const kernels::PairOutput<double> r =
      kernels::segments_with_radii<double>(A.p0, A.p1, B.p0, B.p1, A.radius, B.radius, tb - ta);
  out.status[i] = r.status;
  out.collide[i] = r.distance <= options.margin ? 1 : 0;
  if (options.level >= QueryLevel::distance) out.distance[i] = r.distance;
  if (options.level >= QueryLevel::witness) {
    out.witness_a.set(i, r.witness_a);
    out.witness_b.set(i, r.witness_b);
    out.normal.set(i, r.normal);
  }
  return true;
}

/// The tile's pairs listed in s.order[0 .. count) (offsets from begin, grouped by type): closed forms answer at setup, the
/// rest run through the SIMD GJK in chunks of one shape-pair type, then complete_pair() per pair.
template <class T>
void run_generic(const ShapeTable& shapes, const PairBatchView& batch, const QueryOptions& options, InstructionSet isa,
                 std::size_t begin, std::size_t count, ChunkScratch<T>& s, PairResults& out) {
  if (count == 0) return;
  const kernels::simd::ResultView results = detail::result_view(out);
  s.setups.resize(kChunkPairs);
  s.gjk.resize(kChunkPairs);
  s.frames.resize(kChunkPairs);
  s.pairs.resize(kChunkPairs);
  std::size_t pending = 0;
  ShapeType pending_a = ShapeType::sphere, pending_b = ShapeType::sphere;
  const auto flush = [&] {
    // The chunk's one shape-pair type (set_gjk_parameters() resolved its setups' solver alike).
    kernels::simd::gjk_lanes<T>(isa, s.setups.data(), pending, s.gjk.data(),
                                resolve_solver(options.solver, options.level, pending_a, pending_b),
                                options.level >= QueryLevel::witness);
    for (std::size_t j = 0; j < pending; ++j)
      kernels::simd::write_pair_output(kernels::complete_pair(s.setups[j], s.gjk[j], options), s.frames[j].Ra,
                                       s.frames[j].ta, s.pairs[j], options.level, results);
    pending = 0;
  };
  for (std::size_t n = 0; n < count; ++n) {
    const std::uint32_t k = s.order[n];
    const std::size_t i = begin + k;
    detail::fill_pair_defaults(out, i);  // the paths below write only what they compute
    // Sphere/capsule pairs reach this path only when the SIMD closed form left them (touching cores, bad input).
    if (options.closed_forms && wide_closed_form(s.keys[k], options) == WideClosedForm::segments &&
        solve_segment_pair(shapes, batch, options, i, out))
      continue;
    PairFrame frame;
    kernels::PairSetup<T>& setup = s.setups[pending];
    if (!prepare_pair(shapes, batch, options, i, frame, setup, out)) continue;
    if (setup.done) {
      kernels::simd::write_pair_output(setup.out, frame.Ra, frame.ta, i, options.level, results);
      continue;
    }
    // A chunk holds one shape-pair type (the kernels branch on the type once per chunk, not per lane).
    if (pending > 0 && (setup.A.type != pending_a || setup.B.type != pending_b)) {
      const kernels::PairSetup<T> keep = setup;
      flush();
      s.setups[0] = keep;
    }
    pending_a = s.setups[pending].A.type;
    pending_b = s.setups[pending].B.type;
    s.frames[pending] = frame;
    s.pairs[pending] = static_cast<std::uint32_t>(i);
    if (++pending == kChunkPairs) flush();
  }
  if (pending > 0) flush();
}

template <class T>
void run_tile(const ShapeTable& shapes, const PairBatchView& batch, const QueryOptions& options, InstructionSet isa,
              std::size_t begin, std::size_t end, ChunkScratch<T>& s, PairResults& out) {
  group_by_type(shapes, batch, begin, end, s.order, s.keys, s.groups);
  // Groups with a SIMD closed form or the batch-array GJK first; the pairs they leave (invalid input, touching
  // cores, inflated boxes, float stalls redone in double) join the generic per-pair path below with every other
  // group.
  const kernels::simd::PairView view = detail::pair_view(shapes, batch);
  const kernels::simd::ResultView results = detail::result_view(out);
  const kernels::simd::ClosedFormQuery query{options.level, options.margin};
  s.fallback.resize(end - begin);  // no-ops after the first tile: sizes, not contents, change
  std::size_t kept = 0, fallbacks = 0;
  for (std::size_t g = 0; g < kTypePairs; ++g) {
    const std::uint32_t first = s.groups[g], last = s.groups[g + 1];
    if (first == last) continue;
    const WideClosedForm kind = wide_closed_form(g, options);
    const bool gjk = kind == WideClosedForm::none && wide_gjk_group(g, options, batch);
    if (kind == WideClosedForm::none && !gjk) {
      for (std::uint32_t k = first; k < last; ++k) s.order[kept++] = s.order[k];
      continue;
    }
    s.group_pairs.resize(last - first);
    for (std::uint32_t k = first; k < last; ++k) s.group_pairs[k - first] = static_cast<std::uint32_t>(begin + s.order[k]);
    std::uint32_t* left_out = s.fallback.data() + fallbacks;
    const std::uint32_t* pairs = s.group_pairs.data();
    const std::size_t count = s.group_pairs.size();
    if (gjk) {
      QueryOptions group = options;
      group.solver = resolve_solver(options.solver, options.level, type_a(g), type_b(g));
      fallbacks += kernels::simd::gjk_pairs<T>(isa, view, type_a(g), type_b(g), pairs, count, group, results, left_out);
    } else if (kind == WideClosedForm::segments) {
      fallbacks += kernels::simd::segment_pairs(isa, view, type_a(g) == ShapeType::capsule,
                                                type_b(g) == ShapeType::capsule, pairs, count, query, results, left_out);
    } else if (kind == WideClosedForm::point_solids) {
      const bool sphere_a = type_a(g) == ShapeType::sphere;
      const auto solid = kernels::simd::point_solid_of(sphere_a ? type_b(g) : type_a(g));
      fallbacks += kernels::simd::point_solid_pairs(isa, view, sphere_a, solid, pairs, count, query, results, left_out);
    } else {
      fallbacks += kernels::simd::box_pairs_boolean(isa, view, pairs, count, results, left_out);
    }
  }
  for (std::size_t f = 0; f < fallbacks; ++f) s.order[kept++] = static_cast<std::uint32_t>(s.fallback[f] - begin);
  run_generic(shapes, batch, options, isa, begin, kept, s, out);
}

}  // namespace

void collide(const ShapeTable& shapes, const PairBatch& batch, const QueryOptions& options, PairResults& results) {
  detail::validate_batch_layout(batch);
  collide(shapes, PairBatchView::of(batch), options, results);
}

void collide(const ShapeTable& shapes, const PairBatchView& batch, const QueryOptions& requested, PairResults& results) {
  validate(requested);
  detail::validate_shapes_for(shapes, requested);
  // options.solver stays the requested one: the kernels see the solver that runs, never `automatic`, resolved per
  // shape-pair type where they are called (resolve_solver() with the types; set_gjk_parameters() per setup).
  const QueryOptions& options = requested;
  detail::validate_batch_layout(batch);
  // Every computed array's entries are written once, by the pair's kernel; the others stay empty.
  detail::size_results(results, batch.size(), options.level);
  const std::size_t n = batch.size();
  const int workers = options.threads > 0 ? options.threads : tbb::this_task_arena::max_concurrency();
  const std::size_t tile = tile_pairs(n, workers);
  const std::size_t tiles = (n + tile - 1) / tile;
  const InstructionSet isa = resolve_instruction_set(options.isa);
  const auto run_tiles = [&](const tbb::blocked_range<std::size_t>& range) {
    // Reused by every task this thread runs (a task never waits on TBB, so it cannot nest on its thread):
    // fresh scratch per task cost ~13 KB of allocation and zeroing per 1024 closed-form pairs.
    thread_local ChunkScratch<double> scratch_double;
    thread_local ChunkScratch<float> scratch_float;
    for (std::size_t t = range.begin(); t != range.end(); ++t) {
      const std::size_t begin = t * tile, end = std::min(n, begin + tile);
      if (options.precision == Precision::float32) {
        run_tile(shapes, batch, options, isa, begin, end, scratch_float, results);
        detail::refuse_beyond_float_limits(batch, begin, end, results);
      } else {
        run_tile(shapes, batch, options, isa, begin, end, scratch_double, results);
      }
    }
  };
  const auto run_all = [&] { tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tiles), run_tiles); };
  // One tile, or one thread asked for: the tiles run here, in order, as a one-thread arena would run them (the same
  // bits: a tile's answers never depend on where it runs), without an arena's set-up (~9.7k instructions a call,
  // more than 16 GJK pairs' work; callgrind of 16-pair calls with threads = 1) or a parallel_for's.
  if (tiles <= 1 || options.threads == 1) {
    run_tiles(tbb::blocked_range<std::size_t>(0, tiles));
    return;
  }
  // A new arena costs tens of microseconds (as much as ~1000 closed-form pairs): only when the caller's arena has
  // a different size.
  if (options.threads <= 0 || options.threads == tbb::this_task_arena::max_concurrency()) {
    run_all();
  } else {
    tbb::task_arena arena(options.threads);
    arena.execute(run_all);
  }
}

const char* kernel_for(const Shape& a, const Shape& b, const QueryOptions& options) {
  // Sphere-cylinder and sphere-cone have a closed form only in SIMD lanes (sphere-box also has a per-pair one); the
  // others are what the per-pair setup answers (it also knows that inflated boxes run GJK).
  if (kernels::simd::wide_closed_form(a.type, b.type, options) == WideClosedForm::point_solids) return "closed form";
  const OwnedShapeView va(a), vb(b);
  kernels::RelativePose apart;
  apart.t = Eigen::Vector3d(1e3, 0, 0);  // the kernel depends on the types and options only, not on the pose
  const auto setup = kernels::setup_pair<double>(va.view, vb.view, apart, Eigen::Vector3d::Zero(), options);
  return setup.done ? "closed form" : "gjk";
}

}  // namespace batchcol
