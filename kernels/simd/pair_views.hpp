// Raw views of a PairBatch and of PairResults for the SIMD kernels: plain pointers to the SoA component arrays
// (and to the shapes), so the per-instruction-set kernels index no std::vector; and the world-frame output writer
// the executor and the batch-array GJK share. Included before any `#pragma GCC target` (see isa_prelude.hpp).
#pragma once

#include "batchcol/batch.hpp"
#include "kernels/pair_output.hpp"

#include <cstddef>
#include <cstdint>
#include <limits>

namespace batchcol::kernels::simd {

struct PairView {
  const std::uint32_t* shape_a = nullptr;
  const std::uint32_t* shape_b = nullptr;
  const double* translation_a[3] = {};  // x, y, z
  const double* translation_b[3] = {};
  const double* rotation_a[4] = {};  // w, x, y, z
  const double* rotation_b[4] = {};
  // Shape fields as base pointers into the ShapeTable plus its stride in bytes (no Eigen code in the kernels).
  const double* shape_size = nullptr;       // Shape::size[0] of shape 0; [1], [2] follow
  const double* shape_inflation = nullptr;  // Shape::inflation of shape 0
  std::uint32_t shape_stride = 0;  // sizeof(Shape)
  std::uint32_t shape_count = 0;
  const Shape* shapes = nullptr;  // the table itself, for the per-lane setup of the batch-array GJK
  const double* bounding_radii = nullptr;  // ShapeTable::bounding_radii()

  static PairView of(const ShapeTable& shapes, const PairBatch& batch) { return of(shapes, PairBatchView::of(batch)); }
  static PairView of(const ShapeTable& shapes, const PairBatchView& batch) {
    PairView v;
    v.shape_a = batch.shape_a.data();
    v.shape_b = batch.shape_b.data();
    const Vec3View* t[2] = {&batch.translation_a, &batch.translation_b};
    const QuatView* q[2] = {&batch.rotation_a, &batch.rotation_b};
    const double** tv[2] = {v.translation_a, v.translation_b};
    const double** qv[2] = {v.rotation_a, v.rotation_b};
    for (int s = 0; s < 2; ++s) {
      tv[s][0] = t[s]->x.data(), tv[s][1] = t[s]->y.data(), tv[s][2] = t[s]->z.data();
      qv[s][0] = q[s]->w.data(), qv[s][1] = q[s]->x.data(), qv[s][2] = q[s]->y.data(), qv[s][3] = q[s]->z.data();
    }
    v.shape_count = static_cast<std::uint32_t>(shapes.size());
    v.shape_stride = sizeof(Shape);
    v.shapes = shapes.shapes().data();
    v.bounding_radii = shapes.bounding_radii().data();
    if (shapes.size() > 0) {
      v.shape_size = shapes[0].size.data();
      v.shape_inflation = &shapes[0].inflation;
    }
    return v;
  }
};

struct ResultView {
  Status* status = nullptr;
  std::uint8_t* collide = nullptr;
  double* distance = nullptr;
  double* witness_a[3] = {};
  double* witness_b[3] = {};
  double* normal[3] = {};
  double* direction[3] = {};
  std::int32_t* iterations = nullptr;

  /// Arrays the query level does not compute are empty: their pointers are null (an emptied vector's data() may
  /// still point at its old storage, which a stray write would corrupt silently; a null pointer faults).
  static ResultView of(PairResults& r) {
    const auto data = [](std::vector<double>& a) { return a.empty() ? nullptr : a.data(); };
    ResultView v;
    v.status = r.status.data();
    v.collide = r.collide.data();
    v.distance = data(r.distance);
    Vec3Array* a[4] = {&r.witness_a, &r.witness_b, &r.normal, &r.direction};
    double** d[4] = {v.witness_a, v.witness_b, v.normal, v.direction};
    for (int k = 0; k < 4; ++k) d[k][0] = data(a[k]->x), d[k][1] = data(a[k]->y), d[k][2] = data(a[k]->z);
    v.iterations = r.iterations.data();
    return v;
  }
};

/// Writes pair i's answer, computed in A's frame, to the result arrays in the world frame (A's rotation Ra and
/// translation ta): the executor's per-pair path and the batch-array GJK both write through this.
/// The distance is written from QueryLevel::distance on, witness points and normal from QueryLevel::witness on (the
/// arrays below are empty: see PairResults).
template <class T>
void write_pair_output(const PairOutput<T>& r, const Eigen::Matrix3d& Ra, const Eigen::Vector3d& ta, std::size_t i,
                       QueryLevel level, const ResultView& out) {
  out.status[i] = r.status;
  out.collide[i] = r.collide ? 1 : 0;
  if (level >= QueryLevel::distance) out.distance[i] = static_cast<double>(r.distance);
  const auto put = [&](double* const* dst, const Eigen::Vector3d& v) {
    for (int c = 0; c < 3; ++c) dst[c][i] = v[c];
  };
  if (level >= QueryLevel::witness) {
    put(out.witness_a, mul<double>(Ra, r.witness_a.template cast<double>()) + ta);
    put(out.witness_b, mul<double>(Ra, r.witness_b.template cast<double>()) + ta);
    put(out.normal, mul<double>(Ra, r.normal.template cast<double>()));
  }
  put(out.direction, mul<double>(Ra, r.direction.template cast<double>()));
  out.iterations[i] = r.iterations;
}

/// What the closed forms need of QueryOptions.
struct ClosedFormQuery {
  QueryLevel level = QueryLevel::boolean;
  double margin = 0.0;
};

}  // namespace batchcol::kernels::simd
