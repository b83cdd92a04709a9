// The batch executor: validate, group pairs by shape-pair type, run tiles of pairs on TBB, write results in input
// order. Each pair is computed by the same sequential code whatever thread runs it, so results are bitwise
// identical for any thread count.
#include "batchcol/batch.hpp"
#include "kernels/narrowphase.hpp"
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

template <class T>
void run_pair(const ShapeTable& shapes, const PairBatch& batch, const QueryOptions& options, std::size_t i,
              PairResults& out) {
  const std::uint32_t ia = batch.shape_a[i], ib = batch.shape_b[i];
  const auto qa = detail::unit_quaternion(batch.rotation_a[i]);
  const auto qb = detail::unit_quaternion(batch.rotation_b[i]);
  const Eigen::Vector3d ta = batch.translation_a[i], tb = batch.translation_b[i];
  if (ia >= shapes.size() || ib >= shapes.size() || !qa || !qb || !ta.allFinite() || !tb.allFinite()) {
    out.status[i] = Status::invalid_input;  // everything else stays NaN / 0 from PairResults::resize
    return;
  }
  const Eigen::Matrix3d Ra = qa->toRotationMatrix(), Rb = qb->toRotationMatrix();
  kernels::RelativePose b_in_a;
  b_in_a.R = Ra.transpose() * Rb;
  b_in_a.t = Ra.transpose() * (tb - ta);
  Eigen::Vector3d warm = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  if (!batch.warm_start.empty()) warm = Ra.transpose() * batch.warm_start[i];

  const kernels::PairOutput<T> r = kernels::solve_pair<T>(shapes[ia], shapes[ib], b_in_a, warm, options);
  out.status[i] = r.status;
  out.collide[i] = r.collide ? 1 : 0;
  out.distance[i] = static_cast<double>(r.distance);
  out.witness_a.set(i, Ra * r.witness_a.template cast<double>() + ta);
  out.witness_b.set(i, Ra * r.witness_b.template cast<double>() + ta);
  out.normal.set(i, Ra * r.normal.template cast<double>());
  out.direction.set(i, Ra * r.direction.template cast<double>());
  out.iterations[i] = r.iterations;
}

}  // namespace

void collide(const ShapeTable& shapes, const PairBatch& batch, const QueryOptions& options, PairResults& results) {
  validate(options);
  detail::validate_batch_layout(batch);
  results.resize(batch.size());
  const std::size_t n = batch.size();
  const std::size_t tiles = (n + kTilePairs - 1) / kTilePairs;
  const auto run_tiles = [&](const tbb::blocked_range<std::size_t>& range) {
    std::vector<std::uint32_t> order;
    for (std::size_t t = range.begin(); t != range.end(); ++t) {
      const std::size_t begin = t * kTilePairs, end = std::min(n, begin + kTilePairs);
      group_by_type(shapes, batch, begin, end, order);
      for (const std::uint32_t k : order) {
        if (options.precision == Precision::float32) run_pair<float>(shapes, batch, options, begin + k, results);
        else run_pair<double>(shapes, batch, options, begin + k, results);
      }
    }
  };
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.execute([&] { tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tiles), run_tiles); });
}

}  // namespace batchcol
