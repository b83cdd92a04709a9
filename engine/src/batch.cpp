#include "batchcol/batch.hpp"

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

void PairResults::resize(std::size_t n) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  status.assign(n, Status::invalid_input);
  collide.assign(n, 0);
  distance.assign(n, nan);
  for (Vec3Array* v : {&witness_a, &witness_b, &normal, &direction}) {
    v->x.assign(n, nan);
    v->y.assign(n, nan);
    v->z.assign(n, nan);
  }
  iterations.assign(n, 0);
}

}  // namespace batchcol
