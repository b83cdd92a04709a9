#include "batchcol/batch.hpp"
#include "results_fill.hpp"

#include <limits>

namespace batchcol {

void PairBatch::reserve(std::size_t n) {
  shape_a.reserve(n);
  shape_b.reserve(n);
  translation_a.reserve(n);
  translation_b.reserve(n);
  rotation_a.reserve(n);
  rotation_b.reserve(n);
}

std::size_t PairBatch::add(std::uint32_t a, const Pose& pose_a, std::uint32_t b, const Pose& pose_b) {
  shape_a.push_back(a);
  shape_b.push_back(b);
  translation_a.push_back(pose_a.translation);
  translation_b.push_back(pose_b.translation);
  rotation_a.push_back(pose_a.rotation);
  rotation_b.push_back(pose_b.rotation);
  return shape_a.size() - 1;
}

PairBatchView PairBatchView::of(const PairBatch& b) {
  return {ConstSpan<std::uint32_t>::of(b.shape_a), ConstSpan<std::uint32_t>::of(b.shape_b),
          Vec3View::of(b.translation_a),          Vec3View::of(b.translation_b),
          QuatView::of(b.rotation_a),             QuatView::of(b.rotation_b),
          Vec3View::of(b.warm_start)};
}

void PairResults::resize(std::size_t n, QueryLevel level) {
  detail::size_results(*this, n, level);
  for (std::size_t i = 0; i < n; ++i) detail::fill_pair_defaults(*this, i);
}

namespace detail {

void size_results(PairResults& r, std::size_t n, QueryLevel level) {
  const std::size_t with_distance = level >= QueryLevel::distance ? n : 0;
  const std::size_t with_points = level >= QueryLevel::witness ? n : 0;
  r.status.resize(n);
  r.collide.resize(n);
  r.distance.resize(with_distance);
  for (Vec3Array* v : {&r.witness_a, &r.witness_b, &r.normal}) v->resize(with_points);
  r.direction.resize(n);
  r.iterations.resize(n);
}

}  // namespace detail

}  // namespace batchcol
