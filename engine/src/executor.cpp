// The batch executor: validate, group pairs by shape-pair type, run tiles of pairs on TBB, write results in input
// order. Inside a tile, pairs of one type go through the SIMD GJK together (one pair per lane); every lane repeats
// the scalar reference's operations, so results are bitwise identical for any thread count and instruction set.
#include "batchcol/batch.hpp"
#include "kernels/narrowphase.hpp"
#include "kernels/segment_pairs_world.hpp"
#include "kernels/simd/wide_gjk.hpp"
#include "validate.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <array>
#include <limits>

namespace batchcol {
namespace {

/// Pairs per task: large enough to amortise scheduling (~1 us per pair at worst), small enough to balance
/// 2-64 cores on batches of a few thousand pairs, and small enough that the task's slice of the 14 input and 13
/// output arrays (~0.2 MB) stays in cache while its pairs are visited out of order (grouped by type).
constexpr std::size_t kTilePairs = 1024;

/// Indices [begin, end) of the batch sorted by (type of a, type of b), stable: pairs of one kernel run back to
/// back. Grouping stays inside a tile so that memory access stays local.
void group_by_type(const ShapeTable& shapes, const PairBatch& batch, std::size_t begin, std::size_t end,
                   std::vector<std::uint32_t>& order) {
  const auto key = [&](std::size_t i) -> std::size_t {
    const std::uint32_t a = batch.shape_a[i], b = batch.shape_b[i];
    if (a >= shapes.size() || b >= shapes.size()) return 0;  // invalid pairs: any group, they are rejected per pair
    return static_cast<std::size_t>(shapes[a].type) * kShapeTypeCount + static_cast<std::size_t>(shapes[b].type);
  };
  std::array<std::uint32_t, kShapeTypeCount * kShapeTypeCount + 1> start{};
  for (std::size_t i = begin; i < end; ++i) ++start[key(i) + 1];
  for (std::size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
  order.resize(end - begin);
  for (std::size_t i = begin; i < end; ++i) order[start[key(i)]++] = static_cast<std::uint32_t>(i - begin);
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
};

template <class T>
void write_output(const kernels::PairOutput<T>& r, const PairFrame& f, std::size_t i, PairResults& out) {
  out.status[i] = r.status;
  out.collide[i] = r.collide ? 1 : 0;
  out.distance[i] = static_cast<double>(r.distance);
  out.witness_a.set(i, f.Ra * r.witness_a.template cast<double>() + f.ta);
  out.witness_b.set(i, f.Ra * r.witness_b.template cast<double>() + f.ta);
  out.normal.set(i, f.Ra * r.normal.template cast<double>());
  out.direction.set(i, f.Ra * r.direction.template cast<double>());
  out.iterations[i] = r.iterations;
}

/// Validates pair i, computes B's pose in A's frame (double) and the setup. Returns false for an invalid pair
/// (status invalid_input written; everything else stays NaN / 0 from PairResults::resize).
template <class T>
bool prepare_pair(const ShapeTable& shapes, const PairBatch& batch, const QueryOptions& options, std::size_t i,
                  PairFrame& frame, kernels::PairSetup<T>& setup, PairResults& out) {
  const std::uint32_t ia = batch.shape_a[i], ib = batch.shape_b[i];
  const auto qa = detail::unit_quaternion(batch.rotation_a[i]);
  const auto qb = detail::unit_quaternion(batch.rotation_b[i]);
  const Eigen::Vector3d ta = batch.translation_a[i], tb = batch.translation_b[i];
  if (ia >= shapes.size() || ib >= shapes.size() || !qa || !qb || !ta.allFinite() || !tb.allFinite()) {
    out.status[i] = Status::invalid_input;
    return false;
  }
  frame.Ra = qa->toRotationMatrix();
  frame.ta = ta;
  const Eigen::Matrix3d Rb = qb->toRotationMatrix();
  kernels::RelativePose b_in_a;
  b_in_a.R = frame.Ra.transpose() * Rb;
  b_in_a.t = frame.Ra.transpose() * (tb - ta);
  Eigen::Vector3d warm = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  if (!batch.warm_start.empty()) warm = frame.Ra.transpose() * batch.warm_start[i];
  setup = kernels::setup_pair<T>(shapes[ia], shapes[ib], b_in_a, warm, options);
  return true;
}

/// Sphere and capsule pairs with closed forms on: world segments and the closed form, in double, without the
/// relative frame and the setup. Returns false (nothing written) when the pair is not one, or is invalid: the
/// generic path then answers it.
bool solve_segment_pair(const ShapeTable& shapes, const PairBatch& batch, const QueryOptions& options, std::size_t i,
                        PairResults& out) {
  const std::uint32_t ia = batch.shape_a[i], ib = batch.shape_b[i];
  if (ia >= shapes.size() || ib >= shapes.size()) return false;
  const Shape& a = shapes[ia];
  const Shape& b = shapes[ib];
  if (!kernels::is_segment_shape(a) || !kernels::is_segment_shape(b)) return false;
  const auto qa = detail::unit_quaternion(batch.rotation_a[i]);
  const auto qb = detail::unit_quaternion(batch.rotation_b[i]);
  const Eigen::Vector3d ta = batch.translation_a[i], tb = batch.translation_b[i];
  if (!qa || !qb || !ta.allFinite() || !tb.allFinite()) return false;
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

/// Pairs [begin, end) of the tile, grouped by type (`order` holds offsets from begin): closed forms answer at
/// setup, the rest run through the SIMD GJK in chunks of one shape-pair type, then complete_pair() per pair.
template <class T>
void run_tile(const ShapeTable& shapes, const PairBatch& batch, const QueryOptions& options, InstructionSet isa,
              std::size_t begin, ChunkScratch<T>& s, PairResults& out) {
  s.setups.resize(kChunkPairs);
  s.gjk.resize(kChunkPairs);
  s.frames.resize(kChunkPairs);
  s.pairs.resize(kChunkPairs);
  std::size_t pending = 0;
  ShapeType pending_a = ShapeType::sphere, pending_b = ShapeType::sphere;
  const auto flush = [&] {
    kernels::simd::gjk_lanes<T>(isa, s.setups.data(), pending, s.gjk.data(), options.solver,
                                options.level >= QueryLevel::witness);
    for (std::size_t j = 0; j < pending; ++j)
      write_output(kernels::complete_pair(s.setups[j], s.gjk[j], options), s.frames[j], s.pairs[j], out);
    pending = 0;
  };
  for (const std::uint32_t k : s.order) {
    const std::size_t i = begin + k;
    if (options.closed_forms && solve_segment_pair(shapes, batch, options, i, out)) continue;
    PairFrame frame;
    kernels::PairSetup<T>& setup = s.setups[pending];
    if (!prepare_pair(shapes, batch, options, i, frame, setup, out)) continue;
    if (setup.done) {
      write_output(setup.out, frame, i, out);
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

}  // namespace

void collide(const ShapeTable& shapes, const PairBatch& batch, const QueryOptions& options, PairResults& results) {
  validate(options);
  detail::validate_batch_layout(batch);
  results.resize(batch.size());
  const std::size_t n = batch.size();
  const std::size_t tiles = (n + kTilePairs - 1) / kTilePairs;
  const InstructionSet isa = resolve_instruction_set(options.isa);
  const auto run_tiles = [&](const tbb::blocked_range<std::size_t>& range) {
    ChunkScratch<double> scratch_double;
    ChunkScratch<float> scratch_float;
    for (std::size_t t = range.begin(); t != range.end(); ++t) {
      const std::size_t begin = t * kTilePairs, end = std::min(n, begin + kTilePairs);
      if (options.precision == Precision::float32) {
        group_by_type(shapes, batch, begin, end, scratch_float.order);
        run_tile(shapes, batch, options, isa, begin, scratch_float, results);
      } else {
        group_by_type(shapes, batch, begin, end, scratch_double.order);
        run_tile(shapes, batch, options, isa, begin, scratch_double, results);
      }
    }
  };
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.execute([&] { tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tiles), run_tiles); });
}

}  // namespace batchcol
