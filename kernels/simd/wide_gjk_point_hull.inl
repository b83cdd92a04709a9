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

/// Whether a lane's hull takes a candidate: a small hull (linear-scan supports) with at most kPointHullMaxFaces
/// faces, and its faces and normals present.
static bool point_hull_takes(const HullView& h) {
  return h.vertex_count < kHillClimbMinVertices && h.face_count >= 1 && h.face_count <= kPointHullMaxFaces &&
         h.faces != nullptr && h.face_normals != nullptr;
}
/// Whether the sphere centre c (hull frame) is within kPointHullNearRadii hull radii of the hull's centroid: far
/// centres keep the first support point, which is then nearly as good (see kPointHullNearRadii).
static bool point_hull_near(const HullView& h, T cx, T cy, T cz) {
  const T dx = cx - T(h.centroid[0]), dy = cy - T(h.centroid[1]), dz = cz - T(h.centroid[2]);
  const T reach = T(kPointHullNearRadii) * T(h.radius);
  return (dx * dx + dy * dy) + dz * dz <= reach * reach;
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

/// The candidate of the lanes of `lanes` (the near hull lanes of a point_hull_pair() run; hull: each lane's view): pa,
/// pb on A and B (A's frame). Returns the lanes whose candidate is finite.
AI static mask point_hull_candidate(const real* R, const real* t, bool sphere_a, const HullView* const* hull,
                                    std::uint32_t lanes, V3& pa, V3& pb) {
  const real zero = splat(T(0));
  // The sphere's centre in the hull's frame: -R^T t (B's hull), t (A's).
  const V3 c = sphere_a ? V3{-((R[0] * t[0] + R[3] * t[1]) + R[6] * t[2]), -((R[1] * t[0] + R[4] * t[1]) + R[7] * t[2]),
                             -((R[2] * t[0] + R[5] * t[1]) + R[8] * t[2])}
                        : V3{t[0], t[1], t[2]};
  // Each lane's face loop runs in scalar code over its own hull's rows (contiguous loads): the vector form read
  // every face through hardware gathers (7 per face and native register), which cost ~43% wall on distant pairs on
  // this Xeon (the Gather Data Sampling microcode, an inference). Same operations in the same order as the
  // reference, each lane an IEEE scalar computation, so bit for bit the same values in every ISA. Lanes outside
  // `lanes` keep a zero triangle (their result is masked off below).
  alignas(64) T cx[W], cy[W], cz[W];
  std::memcpy(cx, &c.x, sizeof cx);
  std::memcpy(cy, &c.y, sizeof cy);
  std::memcpy(cz, &c.z, sizeof cz);
  alignas(64) T tri[9][W] = {};  // a, b, e: x, y, z
  for (std::uint32_t bits = lanes; bits != 0; bits &= bits - 1) {
    const int l = __builtin_ctz(bits);
    const HullView& h = *hull[l];
    T best = T(0);
    std::uint32_t best_face = 0;
    for (std::uint32_t f = 0; f < h.face_count; ++f) {
      const double* v = h.vertices + 3 * std::size_t(h.faces[3 * f]);
      const double* n = h.face_normals + 3 * std::size_t(f);
      const T s = (T(n[0]) * (cx[l] - T(v[0])) + T(n[1]) * (cy[l] - T(v[1]))) + T(n[2]) * (cz[l] - T(v[2]));
      if (f == 0 || s > best) best = s, best_face = f;
    }
    const std::uint32_t* face = h.faces + 3 * std::size_t(best_face);
    for (int k = 0; k < 3; ++k) {
      const double* p = h.vertices + 3 * std::size_t(face[k]);
      tri[3 * k][l] = T(p[0]);
      tri[3 * k + 1][l] = T(p[1]);
      tri[3 * k + 2][l] = T(p[2]);
    }
  }
  real m[9];
  std::memcpy(m, tri, sizeof m);
  const V3 a = {m[0], m[1], m[2]}, b = {m[3], m[4], m[5]}, e = {m[6], m[7], m[8]};
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
    const HullView& h = *s.hull[l];
    if (!point_hull_takes(h)) continue;
    // The centre as point_hull_candidate() computes it, lane l's IEEE scalar operations (the same bits): refills
    // of far lanes only (most distant pairs) then cost no vector work.
    const real* R = L.R;
    const real* t = L.t;
    const T cx = sphere_a ? -((R[0][l] * t[0][l] + R[3][l] * t[1][l]) + R[6][l] * t[2][l]) : t[0][l];
    const T cy = sphere_a ? -((R[1][l] * t[0][l] + R[4][l] * t[1][l]) + R[7][l] * t[2][l]) : t[1][l];
    const T cz = sphere_a ? -((R[2][l] * t[0][l] + R[5][l] * t[1][l]) + R[8][l] * t[2][l]) : t[2][l];
    if (point_hull_near(h, cx, cy, cz)) lanes |= 1u << l;
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
