// WideGjk's start point for a sphere against a small hull (kernels/gjk.hpp's point_hull_pair()), either order, in
// double distance and witness lanes (gjk.hpp says why not boolean and float).
// Included inside WideGjk<T> (kernels/simd/wide_gjk.inl); tests/support/reference_point_hull.hpp is its scalar
// transcription, with the same operations in the same order.
//
// The sphere's core is a point c, so D is the hull mirrored and moved, and GJK's answer is c's nearest point on the
// hull. The candidate: the face whose plane c is farthest above (the largest signed distance <n_f, c - v_f>; the
// first of equals), and c's nearest point q on that triangle (Ericson, "Real-Time Collision Detection", 5.1.5). The
// nearest point of the hull lies on a face c sees, and in practice on the most separating one: q was the hull's
// nearest point in 3927 of 4000 close sphere-convex8 bench pairs (3882 distant, 3932 overlapping; brute force over
// every triangle), against 963 of 4000 for the face's interior alone. The lane starts from q (a point of D, so any
// start is sound) in place of the first support point, with a plain first step: its duality gap certifies q where
// q is the hull's nearest point (the face's, edge's or vertex's support points reach <q, x> exactly), and GJK goes
// on from q elsewhere. Before: 2.2 mean iterations plus the first support per close witness pair.
// Hulls of at most kPointHullMaxFaces faces only (the face loop costs one plane per face per lane); larger hulls,
// and lanes where the candidate is not finite, keep the first support point.

/// Lane addresses as 64-bit integers whatever T (float lanes: W of them in a wider vector, split into native
/// registers by the compiler). Never returned by value: float lanes' are wider than a register (AVX2: 64 bytes),
/// whose return GCC warns changes the ABI (-Wpsabi); out-parameters instead.
/// (Element types spelled as dependent types: GCC 12 drops vector_size from a typedef whose element type is not
/// dependent when only its size is, leaving a scalar in the W = 1 build.)
using I64 = std::conditional_t<sizeof(T) == 0, T, std::int64_t>;
using F64 = std::conditional_t<sizeof(T) == 0, T, double>;
typedef I64 Addr __attribute__((vector_size(8 * W)));
typedef F64 Doubles __attribute__((vector_size(8 * W)));

/// The doubles at the lanes' addresses, as T (T(v): the hull's own conversion in hull_point()). One hardware gather
/// per native register of 64-bit lanes.
AI static real gather_t(const Addr& addr) {
  Doubles r{};
#if BATCHCOL_SIMD_BYTES == 32
  for (int k = 0; k < W; k += 4) {
    __m256i a;
    std::memcpy(&a, reinterpret_cast<const char*>(&addr) + 8 * k, sizeof a);
    const __m256d g = _mm256_i64gather_pd(static_cast<const double*>(nullptr), a, 1);
    std::memcpy(reinterpret_cast<char*>(&r) + 8 * k, &g, sizeof g);
  }
#elif BATCHCOL_SIMD_BYTES == 64
  for (int k = 0; k < W; k += 8) {
    __m512i a;
    std::memcpy(&a, reinterpret_cast<const char*>(&addr) + 8 * k, sizeof a);
    const __m512d g = _mm512_i64gather_pd(a, static_cast<const double*>(nullptr), 1);
    std::memcpy(reinterpret_cast<char*>(&r) + 8 * k, &g, sizeof g);
  }
#else
  for (int l = 0; l < W; ++l) r[l] = *reinterpret_cast<const double*>(static_cast<std::uintptr_t>(addr[l]));
#endif
  if constexpr (std::is_same_v<T, double>) return r;
  else return __builtin_convertvector(r, real);
}
/// The 64-bit words at the lanes' addresses, into r.
AI static void gather_words(const Addr& addr, Addr& r) {
#if BATCHCOL_SIMD_BYTES == 32
  for (int k = 0; k < W; k += 4) {
    __m256i a;
    std::memcpy(&a, reinterpret_cast<const char*>(&addr) + 8 * k, sizeof a);
    const __m256i g = _mm256_i64gather_epi64(static_cast<const long long*>(nullptr), a, 1);
    std::memcpy(reinterpret_cast<char*>(&r) + 8 * k, &g, sizeof g);
  }
#elif BATCHCOL_SIMD_BYTES == 64
  for (int k = 0; k < W; k += 8) {
    __m512i a;
    std::memcpy(&a, reinterpret_cast<const char*>(&addr) + 8 * k, sizeof a);
    const __m512i g = _mm512_i64gather_epi64(a, static_cast<const long long*>(nullptr), 1);
    std::memcpy(reinterpret_cast<char*>(&r) + 8 * k, &g, sizeof g);
  }
#else
  for (int l = 0; l < W; ++l) {
    std::int64_t v;
    std::memcpy(&v, reinterpret_cast<const void*>(static_cast<std::uintptr_t>(addr[l])), sizeof v);
    r[l] = v;
  }
#endif
}
/// A point of every lane's hull: the lanes' hull rows as an Addr per array (faces, normals, vertices) and the
/// last face index, for lanes whose hull takes a candidate; the others read a one-face dummy hull.
struct HullAddr {
  Addr faces, normals, vertices, last;
};
static void hull_addresses(const HullView* const* hull, std::uint32_t lanes, HullAddr& h) {
  static constexpr std::uint32_t dummy_face[3] = {0, 0, 0};
  static constexpr double dummy_xyz[3] = {0, 0, 0};
  // Through arrays: element writes into the vectors made GCC warn (maybe-uninitialized) in the W = 1 build.
  std::int64_t faces[W], normals[W], vertices[W], last[W];
  for (int l = 0; l < W; ++l) {
    const HullView* v = (lanes >> l & 1u) ? hull[l] : nullptr;
    faces[l] = std::int64_t(reinterpret_cast<std::uintptr_t>(v ? v->faces : dummy_face));
    normals[l] = std::int64_t(reinterpret_cast<std::uintptr_t>(v ? v->face_normals : dummy_xyz));
    vertices[l] = std::int64_t(reinterpret_cast<std::uintptr_t>(v ? v->vertices : dummy_xyz));
    last[l] = v ? std::int64_t(v->face_count) - 1 : 0;
  }
  std::memcpy(&h.faces, faces, sizeof faces);
  std::memcpy(&h.normals, normals, sizeof normals);
  std::memcpy(&h.vertices, vertices, sizeof vertices);
  std::memcpy(&h.last, last, sizeof last);
}
/// Whether a lane's hull takes a candidate: a small hull (linear-scan supports) with at most kPointHullMaxFaces
/// faces, and its faces and normals present.
static bool point_hull_takes(const HullView& h) {
  return h.vertex_count < kHillClimbMinVertices && h.face_count >= 1 && h.face_count <= kPointHullMaxFaces &&
         h.faces != nullptr && h.face_normals != nullptr;
}
/// Vertex `index` (64-bit lanes) of each lane's hull, as T.
AI static V3 hull_vertex(const HullAddr& h, const Addr& index) {
  const Addr p = h.vertices + index * std::int64_t(3 * sizeof(double));
  return {gather_t(p), gather_t(p + std::int64_t(sizeof(double))), gather_t(p + std::int64_t(2 * sizeof(double)))};
}

/// c's nearest point on triangle (a, b, e), Ericson's ClosestPtPointTriangle with its region order (vertex a,
/// vertex b, edge ab, vertex e, edge ae, edge be, interior), each lane taking the first region that holds.
AI static V3 triangle_point(const V3& c, const V3& a, const V3& b, const V3& e) {
  const real zero = splat(T(0));
  const V3 ab = sub(b, a), ae = sub(e, a), ap = sub(c, a), bp = sub(c, b), ep = sub(c, e);
  const real d1 = dot(ab, ap), d2 = dot(ae, ap), d3 = dot(ab, bp), d4 = dot(ae, bp), d5 = dot(ab, ep), d6 = dot(ae, ep);
  const real ve = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
  const mask at_a = (d1 <= zero) & (d2 <= zero);
  mask taken = at_a;
  const mask at_b = ~taken & (d3 >= zero) & (d4 <= d3);
  taken |= at_b;
  const mask on_ab = ~taken & (ve <= zero) & (d1 >= zero) & (d3 <= zero);
  taken |= on_ab;
  const mask at_e = ~taken & (d6 >= zero) & (d5 <= d6);
  taken |= at_e;
  const mask on_ae = ~taken & (vb <= zero) & (d2 >= zero) & (d6 <= zero);
  taken |= on_ae;
  const real d43 = d4 - d3, d56 = d5 - d6;
  const mask on_be = ~taken & (va <= zero) & (d43 >= zero) & (d56 >= zero);
  const mask inner = ~taken & ~on_be;
  // One division for the three edges: t = num / den on edge from + t dir.
  const real num = select(on_ab, d1, select(on_ae, d2, d43));
  const real den = select(on_ab, d1 - d3, select(on_ae, d2 - d6, d43 + d56));
  const real u = num / den;
  const V3 from = pick(on_be, b, a), dir = pick(on_ab, ab, pick(on_ae, ae, sub(e, b)));
  const V3 edge_point = add(from, scale(u, dir));
  const real inv = splat(T(1)) / ((va + vb) + ve);
  const real v = vb * inv, w = ve * inv;
  const V3 inner_point = add(add(a, scale(v, ab)), scale(w, ae));
  V3 q = pick(inner, inner_point, edge_point);
  q = pick(at_e, e, q);
  q = pick(at_b, b, q);
  return pick(at_a, a, q);
}

/// The candidate of the lanes of `lanes` (the hull lanes of a point_hull_pair() run; hull: each lane's view): pa,
/// pb on A and B (A's frame). Returns the lanes whose candidate is finite.
AI static mask point_hull_candidate(const real* R, const real* t, bool sphere_a, const HullView* const* hull,
                                    std::uint32_t lanes, V3& pa, V3& pb) {
  const real zero = splat(T(0));
  // The sphere's centre in the hull's frame: -R^T t (B's hull), t (A's).
  const V3 c = sphere_a ? V3{-((R[0] * t[0] + R[3] * t[1]) + R[6] * t[2]), -((R[1] * t[0] + R[4] * t[1]) + R[7] * t[2]),
                             -((R[2] * t[0] + R[5] * t[1]) + R[8] * t[2])}
                        : V3{t[0], t[1], t[2]};
  HullAddr h;
  hull_addresses(hull, lanes, h);
  std::int64_t faces = 1;
  for (int l = 0; l < W; ++l) faces = std::max(faces, h.last[l] + 1);
  constexpr std::int64_t face_bytes = 3 * sizeof(std::uint32_t), normal_bytes = 3 * sizeof(double);
  real best = zero;
  Addr best_face = h.last - h.last;
  for (std::int64_t f = 0; f < faces; ++f) {
    // Lanes past their last face read it again (never strictly better).
    const Addr fl = h.last < f ? h.last : Addr{} + f;
    Addr first{};
    gather_words(h.faces + fl * face_bytes, first);
    const V3 v = hull_vertex(h, first & 0xffffffffLL);
    const Addr np = h.normals + fl * normal_bytes;
    const V3 n = {gather_t(np), gather_t(np + std::int64_t(sizeof(double))), gather_t(np + std::int64_t(2 * sizeof(double)))};
    const real s = (n.x * (c.x - v.x) + n.y * (c.y - v.y)) + n.z * (c.z - v.z);
    const mask take = f == 0 ? splat_mask(-1) : s > best;
    best = select(take, s, best);
    Addr wide_take;  // take as 64-bit lanes
    if constexpr (sizeof(T) == 8) wide_take = take;
    else wide_take = __builtin_convertvector(take, Addr);
    best_face = wide_take ? fl : best_face;
  }
  // The best face's vertex indices: the words at its first and second index (both inside the face array).
  const Addr fp = h.faces + best_face * face_bytes;
  Addr w01{}, w12{};
  gather_words(fp, w01);
  gather_words(fp + std::int64_t(sizeof(std::uint32_t)), w12);
  const V3 a = hull_vertex(h, w01 & 0xffffffffLL), b = hull_vertex(h, (w01 >> 32) & 0xffffffffLL),
           e = hull_vertex(h, (w12 >> 32) & 0xffffffffLL);
  const V3 q = triangle_point(c, a, b, e);
  if (sphere_a) {
    pa = {zero, zero, zero};
    pb = {((R[0] * q.x + R[1] * q.y) + R[2] * q.z) + t[0], ((R[3] * q.x + R[4] * q.y) + R[5] * q.z) + t[1],
          ((R[6] * q.x + R[7] * q.y) + R[8] * q.z) + t[2]};
  } else {
    pa = q;
    pb = {t[0], t[1], t[2]};
  }
  return lanes_of(lanes) & (norm2(sub(pa, pb)) < splat(std::numeric_limits<T>::infinity()));
}
/// start()'s candidates for the fresh lanes `fresh` of a point_hull_pair() run: where a lane's is finite it
/// replaces the first support point (take_start()'s writes, unconditionally). Returns those lanes.
AI static mask point_hull_start(Lanes& L, std::uint32_t fresh) {
  const bool sphere_a = L.A.type == ShapeType::sphere;
  const Side& s = sphere_a ? L.B : L.A;
  std::uint32_t lanes = 0;
  for (std::uint32_t bits = fresh & s.small; bits != 0; bits &= bits - 1) {
    const int l = __builtin_ctz(bits);
    if (point_hull_takes(*s.hull[l])) lanes |= 1u << l;
  }
  if (lanes == 0) return splat_mask(0);
  V3 pa, pb;
  const mask ok = point_hull_candidate(L.R, L.t, sphere_a, s.hull, lanes, pa, pb);
  if (!any(ok)) return ok;
  const V3 x = sub(pa, pb);
  L.w[0] = pick(ok, x, L.w[0]);
  L.a[0] = pick(ok, pa, L.a[0]);  // slot[0] = 0 (reset_search())
  L.b[0] = pick(ok, pb, L.b[0]);
  L.x = pick(ok, x, L.x);
  L.last_s = pick(ok, x, L.last_s);
  L.momentum &= ~ok;
  return ok;
}
