// Raw views of a PairBatch, of a ShapeTable and of PairResults for the SIMD kernels: plain pointers to the SoA
// component arrays, so the per-instruction-set kernels index no std::vector and see no public container; and the
// world-frame output writer the executor and the batch-array GJK share. Included before any `#pragma GCC target`
// (see isa_prelude.hpp).
#pragma once

#include "batchcol/types.hpp"
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
  // The ShapeTable's per-shape arrays (one entry per shape, kept at ShapeTable::add()): a lane gathers a field of
  // its shape from one contiguous array, indexed by the shape index.
  std::uint32_t shape_count = 0;
  const ShapeType* shape_type = nullptr;
  const double* shape_size[3] = {};          // Shape::size x, y, z
  const double* shape_inflation = nullptr;   // Shape::inflation
  const double* bounding_radii = nullptr;    // Shape::bounding_radius()
  const HullView* shape_hull = nullptr;      // the hull's view (convex shapes only)
};

/// The result arrays of PairResults. Arrays the query level does not compute are empty: their pointers are null
/// (an emptied vector's data() may still point at its old storage, which a stray write would corrupt silently; a
/// null pointer faults). The engine fills both views (engine/src/kernel_views.hpp).
struct ResultView {
  Status* status = nullptr;
  std::uint8_t* collide = nullptr;
  double* distance = nullptr;
  double* witness_a[3] = {};
  double* witness_b[3] = {};
  double* normal[3] = {};
  double* direction[3] = {};
  std::int32_t* iterations = nullptr;
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
