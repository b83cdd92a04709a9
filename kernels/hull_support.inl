// Support of a convex hull: a linear scan for small hulls, hill climbing over the vertex adjacency for large ones.
//
// No include guard: kernels/support.hpp includes it in namespace batchcol::kernels (the scalar paths: EPA, the
// tests' reference GJK) and kernels/simd/isa_body.inl once more inside each instruction set's namespace, where the
// wide GJK's large-hull lanes call it compiled for that set. Both copies are this text, so they compute the same
// bits. No lambdas here: GCC does not give a lambda the `#pragma GCC target` of its region.

/// The cell of the hull's direction table (HullView::start_vertices) that direction d falls in, or kNoHullVertex
/// when d has no direction (zero, NaN). The table is a cube map: d's largest component picks one of 6 faces, the
/// other two divided by it pick one of kHullStartGrid^2 cells. A climb started from the support vertex of the
/// cell's centre direction is a few moves from the answer; started from vertex 0 it crossed half the hull.
template <class T> inline std::uint32_t start_cell_index(T c, T k, T half) {
  // c / major in [-1, 1] -> [0, kHullStartGrid); NaN -> 0
  const T f = c * k + half;
  return f >= T(1) ? (f < T(kHullStartGrid) ? std::uint32_t(f) : kHullStartGrid - 1) : 0u;
}
template <class T> inline std::uint32_t start_cell(const Vec3<T>& d) {
  const T x = d.x(), y = d.y(), z = d.z();
  const T ax = std::abs(x), ay = std::abs(y), az = std::abs(z);
  // The face: the largest |component| (first of equals), its sign; u, v: the next two components cyclically.
  std::uint32_t face = ay > ax ? 2u : 0u;
  T major = ay > ax ? ay : ax, u = ay > ax ? z : y, v = ay > ax ? x : z;
  if (az > major) face = 4u, major = az, u = x, v = y;
  if (!(major > T(0))) return kNoHullVertex;  // zero, or NaN (every comparison false)
  face += (face == 0u ? x : face == 2u ? y : z) < T(0) ? 1u : 0u;
  const T k = T(0.5 * kHullStartGrid) / major, half = T(0.5 * kHullStartGrid);
  // A major component below ~8 / max overflows k: u * k would be NaN or infinite and name a cell d is not in (a
  // kHullPureCell entry is trusted without a climb).
  if (!(k <= std::numeric_limits<T>::max())) return kNoHullVertex;
  return (face * kHullStartGrid + start_cell_index(u, k, half)) * kHullStartGrid + start_cell_index(v, k, half);
}

/// Four neighbours' dot products with d at once (a block of HullView::neighbor_block_xyz): GCC vector types, one
/// register on AVX2 / AVX-512, two SSE registers on the baseline; each lane is dot3's arithmetic in T.
template <class T> struct HullBlock;
template <> struct HullBlock<double> {
  typedef double V __attribute__((vector_size(32)));
  static void load(const double* p, V& v) { std::memcpy(&v, p, sizeof v); }
};
template <> struct HullBlock<float> {
  typedef float V __attribute__((vector_size(16)));
  typedef double D __attribute__((vector_size(32)));
  static void load(const double* p, V& v) {  // (by reference: a vector return value would change the ABI)
    D w;
    std::memcpy(&w, p, sizeof w);
    v = __builtin_convertvector(w, V);  // T(p[j]), rounded to nearest as the scalar conversion
  }
};

template <class T> inline T hull_dot(const HullView& hull, std::uint32_t i, const Vec3<T>& d) {
  const double* p = hull.vertices + 3 * std::size_t(i);
  return (T(p[0]) * d.x() + T(p[1]) * d.y()) + T(p[2]) * d.z();
}

/// Vertex i of the hull in precision T.
template <class T> inline Vec3<T> hull_point(const HullView& hull, std::uint32_t i) {
  const double* p = hull.vertices + 3 * std::size_t(i);
  return Vec3<T>(T(p[0]), T(p[1]), T(p[2]));
}

/// Whether the hull is climbed (with the direction table's cells) rather than scanned.
inline bool hull_climbs(const HullView& hull) {
  return hull.vertex_count >= kHillClimbMinVertices && hull.neighbor_block_offsets != nullptr;
}

/// The support vertex straight from a pure cell of the direction table (kHullPureCell: inside one vertex's normal
/// cone, with a margin above rounding), when `cell` (start_cell of d, or kNoHullVertex) is one: no dot product, no
/// climb. Returns kNoHullVertex otherwise. Only for a climbed hull (hull_climbs()).
inline std::uint32_t pure_cell_vertex(const HullView& hull, std::uint32_t cell) {
  if (hull.start_vertices == nullptr || cell == kNoHullVertex) return kNoHullVertex;
  const std::uint32_t e = hull.start_vertices[cell], v = e & ~kHullPureCell;
  return (e & kHullPureCell) && v < hull.vertex_count ? v : kNoHullVertex;
}

/// The vertex coordinates cell_vertex() reads in precision T: the doubles, or for float the hull's float copies
/// when it has them (HullView::vertex_floats: the same values, float(p) is the conversion hull_dot does), which
/// spares a conversion per coordinate in the GJK loop's lookups.
template <class T> struct ListCoords {
  static const double* of(const HullView& hull) { return hull.vertices; }
};
template <> struct ListCoords<float> {
  static const float* of(const HullView& hull) { return hull.vertex_floats; }
};
/// hull_dot() of vertex i from coordinates xyz (doubles or floats): the same operations in T.
template <class T, class C> inline T list_dot(const C* xyz, std::uint32_t i, const Vec3<T>& d) {
  const C* p = xyz + 3 * std::size_t(i);
  return (T(p[0]) * d.x() + T(p[1]) * d.y()) + T(p[2]) * d.z();
}
template <class T, class C> inline std::uint32_t list_first_max(const C* xyz, const std::uint32_t* list, std::uint32_t n,
                                                                const Vec3<T>& d) {
  std::uint32_t best = list[0];
  T best_dot = list_dot(xyz, best, d);
  for (std::uint32_t i = 1; i < n; ++i) {
    const T di = list_dot(xyz, list[i], d);
    if (di > best_dot) best_dot = di, best = list[i];
  }
  return best;
}

/// The support vertex of d from its cell's entry of HullView::cell_candidates (`cell` = start_cell(d)): a pure
/// cell's vertex as it is, else the first maximum of hull_dot over the cell's list, whose indices ascend: the
/// linear scan's vertex (engine/src/convex_hull.cpp, build_cell_candidates(), has the argument). A few dot
/// products where a climb takes a few dozen. Returns kNoHullVertex when the cell has no entry (its supports climb)
/// or names a vertex the hull does not have. Only for a climbed hull (hull_climbs()).
template <class T> inline std::uint32_t cell_vertex(const HullView& hull, std::uint32_t cell, const Vec3<T>& d) {
  if (hull.cell_candidates == nullptr || cell >= kHullStartCells) return kNoHullVertex;
  const std::uint32_t e = hull.cell_candidates[cell], n = e & 15u;
  if (n <= 1) return n == 1 && (e >> 4) < hull.vertex_count ? e >> 4 : kNoHullVertex;
  const std::uint32_t* list = hull.cell_candidates + (e >> 4);
  // The indices ascend (build_cell_candidates()), so the last one is the largest: one range check for the list.
  if (!(list[n - 1] < hull.vertex_count)) return kNoHullVertex;
  const auto* xyz = ListCoords<T>::of(hull);
  return xyz != nullptr ? list_first_max(xyz, list, n, d) : list_first_max(hull.vertices, list, n, d);
}

/// Vertex i in precision T from the coordinates cell_vertex() read (ListCoords): hull_point()'s values.
template <class T> inline Vec3<T> list_point(const HullView& hull, std::uint32_t i) {
  const auto* xyz = ListCoords<T>::of(hull);
  if (xyz == nullptr) return hull_point<T>(hull, i);
  const auto* p = xyz + 3 * std::size_t(i);
  return Vec3<T>(T(p[0]), T(p[1]), T(p[2]));
}

template <class T> Vec3<T> hull_support_in_cell(const HullView& hull, const Vec3<T>& d, SupportHint& hint,
                                                std::uint32_t cell);

template <class T> Vec3<T> hull_support(const HullView& hull, const Vec3<T>& d, SupportHint& hint) {
  const bool table = hull_climbs(hull) && hull.start_vertices != nullptr;
  return hull_support_in_cell(hull, d, hint, table ? start_cell(d) : kNoHullVertex);
}

/// hull_support() with d's cell given (start_cell(d), or kNoHullVertex for a hull without a table; the wide GJK
/// computes the cells of all its lanes at once).
template <class T> Vec3<T> hull_support_in_cell(const HullView& hull, const Vec3<T>& d, SupportHint& hint,
                                                std::uint32_t cell) {
  const std::uint32_t count = hull.vertex_count;
  std::uint32_t best = 0;
  constexpr std::uint32_t B = kHullNeighborBlock;
  static_assert(B == 4, "HullBlock computes four dot products at once");
  // Small hulls, and a hull without its blocks (Shape::convex builds them for every hull it accepts), are scanned.
  if (!hull_climbs(hull)) {
    T best_dot = hull_dot(hull, 0, d);
    for (std::uint32_t i = 1; i < count; ++i) {
      const T di = hull_dot(hull, i, d);
      if (di > best_dot) { best_dot = di; best = i; }
    }
    return hull_point<T>(hull, best);
  }
  // Hill climbing: on a convex polytope a vertex no neighbour improves on is a global maximiser. The strict '>'
  // guarantees termination (the dot product increases at every move).
  // Start from the better of the previous support vertex and the direction table's vertex: GJK's directions
  // swing by up to 180 degrees in the first iterations, and a climb from the previous vertex then crosses the
  // hull, while the table's vertex is within a cell (~3 degrees) of the answer. A pure cell is the answer itself
  // (pure_cell_vertex()); most other cells list the few vertices the answer is among (cell_vertex()).
  best = hint.vertex < count ? hint.vertex : 0;
  std::uint32_t known = cell_vertex(hull, cell, d);
  if (known == kNoHullVertex) known = pure_cell_vertex(hull, cell);  // (a hull without lists: only pure cells)
  if (known != kNoHullVertex) {
    hint.vertex = known;
    return hull_point<T>(hull, known);
  }
  // Not pure: the entry is a plain vertex index (a flagged entry left here names no vertex of this hull).
  std::uint32_t t = hull.start_vertices != nullptr && cell != kNoHullVertex ? hull.start_vertices[cell] : kNoHullVertex;
  if (t >= count) t = kNoHullVertex;
  T best_dot = hull_dot(hull, best, d);
  if (t != kNoHullVertex) {
    const T dt = hull_dot(hull, t, d);
    if (hint.vertex >= count || dt > best_dot) best = t, best_dot = dt;
  }
  // Steepest ascent a block of neighbours at a time: the first neighbour with the largest dot product, taken when
  // it beats the current vertex strictly. The block's four dot products are one vector expression; only a block
  // with a neighbour above the current vertex (the rare case: most blocks visited do not improve) is looked at
  // lane by lane, with the sequential first-maximum rule.
  using Block = HullBlock<T>;
  const typename Block::V dx = {d.x(), d.x(), d.x(), d.x()}, dy = {d.y(), d.y(), d.y(), d.y()},
                          dz = {d.z(), d.z(), d.z(), d.z()};
  const std::uint32_t* offsets = hull.neighbor_block_offsets;
  const std::uint32_t* index = hull.neighbor_block_index;
  const double* xyz = hull.neighbor_block_xyz;
  for (bool moved = true; moved;) {
    moved = false;
    const std::uint32_t from = best;
    for (std::uint32_t b = offsets[from]; b < offsets[from + 1]; ++b) {
      const double* p = xyz + 3 * B * b;
      typename Block::V x, y, z;
      Block::load(p, x);
      Block::load(p + B, y);
      Block::load(p + 2 * B, z);
      const typename Block::V dots = (x * dx + y * dy) + z * dz;
      const auto above = dots > best_dot;
      if (!(above[0] | above[1] | above[2] | above[3])) continue;
      T top = dots[0];
      for (std::uint32_t j = 1; j < B; ++j) top = dots[j] > top ? dots[j] : top;
      if (!(top > best_dot)) continue;  // dots[0] is NaN: the sequential rule never moves
      std::uint32_t j = 0;
      while (!(dots[j] == top)) ++j;  // top is one of dots[] and not NaN (it beat best_dot)
      best_dot = top;
      best = index[B * b + j];
      moved = true;
    }
  }
  hint.vertex = best;
  return hull_point<T>(hull, best);
}
