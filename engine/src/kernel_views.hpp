// The raw views the SIMD kernels read (kernels/simd/pair_views.hpp), filled from the public containers: a pair
// batch, the ShapeTable's per-shape arrays, the results. The kernels see only these plain pointers.
#pragma once

#include "batchcol/batch.hpp"
#include "kernels/simd/pair_views.hpp"
#include "shape_table_access.hpp"

#include <vector>

namespace batchcol::detail {

inline kernels::simd::PairView pair_view(const ShapeTable& shapes, const PairBatchView& batch) {
  kernels::simd::PairView v;
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
  v.shape_type = ShapeTableAccess::types(shapes).data();
  for (int k = 0; k < 3; ++k) v.shape_size[k] = ShapeTableAccess::sizes(shapes, k).data();
  v.shape_inflation = ShapeTableAccess::inflations(shapes).data();
  v.bounding_radii = ShapeTableAccess::bounding_radii(shapes).data();
  v.shape_hull = ShapeTableAccess::hulls(shapes).data();
  return v;
}
inline kernels::simd::PairView pair_view(const ShapeTable& shapes, const PairBatch& batch) {
  return pair_view(shapes, PairBatchView::of(batch));
}

/// Arrays the query level does not compute are empty: their pointers are null (see ResultView).
inline kernels::simd::ResultView result_view(PairResults& r) {
  const auto data = [](std::vector<double>& a) { return a.empty() ? nullptr : a.data(); };
  kernels::simd::ResultView v;
  v.status = r.status.data();
  v.collide = r.collide.data();
  v.distance = data(r.distance);
  Vec3Array* a[4] = {&r.witness_a, &r.witness_b, &r.normal, &r.direction};
  double** d[4] = {v.witness_a, v.witness_b, v.normal, v.direction};
  for (int k = 0; k < 4; ++k) d[k][0] = data(a[k]->x), d[k][1] = data(a[k]->y), d[k][2] = data(a[k]->z);
  v.iterations = r.iterations.data();
  return v;
}

}  // namespace batchcol::detail
