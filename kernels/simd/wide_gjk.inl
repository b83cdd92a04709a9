// GJK / Nesterov / Polyak across SIMD lanes: one pair per lane, W pairs at once, lanes refilled with the next pair
// as soon as theirs finishes (iteration counts differ from pair to pair).
//   Gilbert, Johnson, Keerthi 1988 (GJK); Montanari, Petrinic, Barbieri 2017 (signed-volume projection);
//   Montaut et al., RSS 2022 (Nesterov-accelerated GJK). This is batchcol's only production GJK (the scalar
//   instruction set runs it at width 1). tests/support/reference_gjk.hpp is a plain scalar transcription of it:
//   every branch there is a lane mask here, every arithmetic operation is in the same order, so each lane's result
//   is bitwise the reference's (tested lane by lane in tests/kernels/wide_gjk_test.cpp).
//
// No include guard: included once per instruction set by isa_*.cpp after wide.hpp, inside the ISA namespace.

// AI: always inline. The loop's small helpers must stay inside it; GCC's own heuristics outline some of them
// depending on how many callers the loop has (a second instantiation of drive() once made a cylinder pair a third
// more expensive).
#define AI __attribute__((always_inline))

template <class T> struct WideGjk {
  using real = wreal<T>;
  using mask = wmask<T>;
  using Int = typename Wide<T>::Int;
  static constexpr int W = Wide<T>::W;

  struct V3 {
    real x, y, z;
  };
  static V3 add(const V3& a, const V3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  static V3 sub(const V3& a, const V3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  static V3 neg(const V3& a) { return {-a.x, -a.y, -a.z}; }
  static V3 scale(real s, const V3& a) { return {s * a.x, s * a.y, s * a.z}; }
  static V3 divide(const V3& a, real s) { return {a.x / s, a.y / s, a.z / s}; }
  static real dot(const V3& a, const V3& b) { return (a.x * b.x + a.y * b.y) + a.z * b.z; }
  static real norm2(const V3& a) { return dot(a, a); }
  static real norm(const V3& a) { return wsqrt<T>(norm2(a)); }
  static V3 cross(const V3& a, const V3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  }
  /// select() for this file's masks, whose lanes are all 0 or -1 (comparisons, their and / or / not, lanes_of(),
  /// splat_mask(0 / -1) and lane fields set to 0 / -1), so their sign bit is their truth: on AVX2 one vblendvps /
  /// vblendvpd on the mask itself, where GCC's vector a ? b : c first compares the mask with zero (often twice, to
  /// swap the operands back).
  /// (V: real or mask.)
  template <class V> AI static V blend(mask m, V a, V b) {
    if constexpr (BATCHCOL_SIMD_BYTES == 32 && sizeof(T) == 4)
      return V(_mm256_blendv_ps(__m256(b), __m256(a), __m256(m)));
    else if constexpr (BATCHCOL_SIMD_BYTES == 32 && sizeof(T) == 8)
      return V(_mm256_blendv_pd(__m256d(b), __m256d(a), __m256d(m)));
    else return select(m, a, b);
  }
  static V3 pick(mask m, const V3& a, const V3& b) { return {blend(m, a.x, b.x), blend(m, a.y, b.y), blend(m, a.z, b.z)}; }
  static mask equal(const V3& a, const V3& b) { return (a.x == b.x) & (a.y == b.y) & (a.z == b.z); }
  static real splat(T v) { return real{} + v; }
  static mask splat_mask(Int v) { return mask{} + v; }
  static mask truth(bool b) { return splat_mask(b ? Int(-1) : Int(0)); }
  /// The lanes whose bit is set in `bits`, as a mask: a broadcast, an and and a compare against the constant
  /// lane bits, where a loop of W lane inserts cost 12-28 instructions per call (measured in drive(), AVX2).
  static mask lanes_of(std::uint32_t bits) {
    mask lane_bit;
    for (int l = 0; l < W; ++l) lane_bit[l] = Int(Int(1) << l);  // folded to a constant
    return (splat_mask(Int(bits)) & lane_bit) != splat_mask(0);
  }
  static mask opposite_sign(real a, real b) {
    const real zero = splat(T(0));
    return ((a > zero) & (b < zero)) | ((a < zero) & (b > zero));
  }

  // ---- Support functions of the cores, W lanes of one shape type (kernels/support.hpp) ----
  /// Rows of the small-hull table: hulls below kHillClimbMinVertices fit.
  static constexpr int kSmallRows = int(kHillClimbMinVertices) - 1;
  struct SmallHulls;
  struct Side {
    ShapeType type = ShapeType::sphere;
    real s0{}, s1{}, s2{};                 // ShapeCore::size
    real tri[9]{};                         // triangle vertices
    const HullView* hull[W] = {};
    SupportHint hint[W] = {};
    std::uint32_t small = 0;  // lanes whose hull has fewer than kHillClimbMinVertices vertices (linear scan)
    // Small hulls, lane-interleaved: row i holds vertex i of every lane's hull (as T), so a support scans its
    // rows with one wide load per coordinate instead of W gathers. A lane's rows past its own vertex count
    // repeat its last vertex (never a strict improvement: the reference's first-maximum rule is kept). `rows`
    // only grows within a run; lanes are padded up to it when it grows.
    int rows = 0;
    std::uint32_t lane_vertices[W] = {};  // vertex count of the lane's current hull (0: never loaded a hull)
    SmallHulls* table = nullptr;  // the rows; set (by Rows) only when the side is convex
  };
  /// The rows live outside Side and Lanes: 3 KB per side, written before read (rows [0, rows) of loaded lanes),
  /// so they are neither zeroed with the lane state at every run() (the run of one type-pair group, a few dozen
  /// pairs in a mixed batch) nor interleaved with the loop's hot fields.
  struct SmallHulls {
    real vx[kSmallRows], vy[kSmallRows], vz[kSmallRows];
  };
  /// Storage for both sides' rows, left unwritten; attach() points the convex sides of L at it.
  struct Rows {
    SmallHulls a, b;
    Rows() {}
    void attach(Side& A, Side& B) {
      A.table = A.type == ShapeType::convex ? &a : nullptr;
      B.table = B.type == ShapeType::convex ? &b : nullptr;
    }
  };

  // Always inlined (AI above): left to itself GCC outlined one of its two inlined copies (the one in start()),
  // a call and a type switch per support, when the batch-array refill changed (and when the Newton code grew
  // drive()).
  AI static V3 support(Side& s, const V3& d, std::uint32_t live) {
    const real zero = splat(T(0));
    switch (s.type) {
      case ShapeType::sphere: return {zero, zero, zero};
      case ShapeType::capsule: return {zero, zero, blend(d.z < zero, -s.s1, s.s1)};
      case ShapeType::box: return {blend(d.x < zero, -s.s0, s.s0), blend(d.y < zero, -s.s1, s.s1), blend(d.z < zero, -s.s2, s.s2)};
      case ShapeType::cylinder: {
        const real rho = wsqrt<T>(d.x * d.x + d.y * d.y);
        const real z = blend(d.z < zero, -s.s1, s.s1);
        const real k = s.s0 / rho;
        const mask axis = rho == zero;
        return {blend(axis, zero, d.x * k), blend(axis, zero, d.y * k), z};
      }
      case ShapeType::cone: {
        const real rho = wsqrt<T>(d.x * d.x + d.y * d.y);
        const real h = s.s1;
        const mask apex = h * d.z >= (-h) * d.z + s.s0 * rho;
        const real k = s.s0 / rho;
        const mask axis = rho == zero;
        const V3 rim = {blend(axis, zero, d.x * k), blend(axis, zero, d.y * k), -h};
        return pick(apex, V3{zero, zero, h}, rim);
      }
      case ShapeType::ellipsoid: {
        const V3 rd = {s.s0 * d.x, s.s1 * d.y, s.s2 * d.z};
        const real n = norm(rd);
        const mask flat = n == zero;
        return pick(flat, V3{zero, zero, zero}, V3{(s.s0 * rd.x) / n, (s.s1 * rd.y) / n, (s.s2 * rd.z) / n});
      }
      case ShapeType::triangle: {
        const V3 t0{s.tri[0], s.tri[1], s.tri[2]}, t1{s.tri[3], s.tri[4], s.tri[5]}, t2{s.tri[6], s.tri[7], s.tri[8]};
        const real d0 = dot(t0, d), d1 = dot(t1, d), d2 = dot(t2, d);
        return pick((d0 >= d1) & (d0 >= d2), t0, pick(d1 >= d2, t1, t2));
      }
      case ShapeType::convex: return hull_support_lanes(s, d, live);
      case ShapeType::halfspace: break;
    }
    return {zero, zero, zero};
  }

  /// Hull support for W lanes. When every live lane's hull is small, the lanes scan the lane-interleaved rows
  /// together (dot products and the running argmax in SIMD, no gathers); otherwise each lane runs the scalar
  /// hull_support (hill climbing with its hint). Both keep the reference's rule: the first vertex with the
  /// largest dot product wins, with the reference's dot product (dot3's association, in T).
  static V3 hull_support_lanes(Side& s, const V3& d, std::uint32_t live) {
    const real zero = splat(T(0));
    V3 r{zero, zero, zero};
    if (live == 0) return r;
    if (live & ~s.small) return large_hull_lanes(s, d, live);
    const SmallHulls& t = *s.table;
    r = {t.vx[0], t.vy[0], t.vz[0]};
    real best = (r.x * d.x + r.y * d.y) + r.z * d.z;
    for (int i = 1; i < s.rows; ++i) {
      const real x = t.vx[i], y = t.vy[i], z = t.vz[i];
      const real di = (x * d.x + y * d.y) + z * d.z;
      const mask better = di > best;
      best = blend(better, di, best);
      r = pick(better, V3{x, y, z}, r);
    }
    return r;
  }
  /// The lanes of hull_support_lanes() with a large hull. Out of line: inlined, its cell computation and climb
  /// calls made GCC stop inlining hull_support_lanes() into the loop, which cost the small hulls' scan a call
  /// (convex8 witness double 3712 -> 3875 instructions per pair, callgrind AVX2).
  __attribute__((noinline)) static V3 large_hull_lanes(Side& s, const V3& d, std::uint32_t live) {
    // The direction table's cells of all lanes at once; a lane whose cell has an entry in the candidate table
    // (pure: the vertex; else a short list) takes its vertex from it (cell_vertex()), the others climb
    // (hull_support_in_cell, this set's build, not ADL's kernels:: one). The lanes go through arrays: element
    // access on the vector types cost a store and reload per lane and coordinate.
    std::uint32_t cell[W];
    start_cells(d, cell);
    alignas(sizeof(real)) T dx[W], dy[W], dz[W], rx[W] = {}, ry[W] = {}, rz[W] = {};
    std::memcpy(dx, &d.x, sizeof dx);
    std::memcpy(dy, &d.y, sizeof dy);
    std::memcpy(dz, &d.z, sizeof dz);
    // Only lanes 0..W-1 exist: a mask bit above them must not index s.hull (UBSan found index W here under the
    // sanitizer build; the loop over l < W this replaced ignored such bits the same way). No caller builds such a
    // mask: in that build (GCC 12.2, -O2 -fsanitize=address,undefined) the AVX-512 loop spills lane_bits()'s
    // 8-bit k-mask with a one-byte store (kmovb %k5, slot) and reloads it as 32 bits (mov slot, %ecx) for the
    // call from minkowski(), so bits 8-31 are the stale bytes of the pointer the slot held before (gdb: live =
    // 0xfffec9ff with the slot's old value 0x7ffffffec9c0; 16-bit masks alike for float). Release builds (-O3)
    // pass W bits (the bitwise tests against the reference would fault or differ otherwise).
    static_assert(W < 32, "lane mask");
    for (std::uint32_t bits = live & ((1u << W) - 1u); bits != 0; bits &= bits - 1) {
      const int l = __builtin_ctz(bits);
      const HullView& h = *s.hull[l];
      const bool climbs = hull_climbs(h);
      const Vec3<T> dl(dx[l], dy[l], dz[l]);
      const std::uint32_t v = climbs ? cell_vertex(h, cell[l], dl) : kNoHullVertex;
      if (v != kNoHullVertex) {
        s.hint[l].vertex = v;
        const Vec3<T> p = list_point<T>(h, v);  // (float: the hull's float copies, no conversion)
        rx[l] = p.x(), ry[l] = p.y(), rz[l] = p.z();
        continue;
      }
      const Vec3<T> p = BATCHCOL_SIMD_NS::hull_support_in_cell(h, dl, s.hint[l], climbs ? cell[l] : kNoHullVertex);
      rx[l] = p.x(), ry[l] = p.y(), rz[l] = p.z();
    }
    V3 r;
    std::memcpy(&r.x, rx, sizeof rx);
    std::memcpy(&r.y, ry, sizeof ry);
    std::memcpy(&r.z, rz, sizeof rz);
    return r;
  }
  /// start_cell() (kernels/hull_support.inl) of every lane's direction, with its operations lane by lane, so each
  /// lane gets the cell the reference's scalar call computes.
  static void start_cells(const V3& d, std::uint32_t* cell) {
    // The cell's arithmetic in T and 32-bit lanes: the indices are integers below 2^13, exact in either, and every
    // conversion here is one instruction on AVX2 (64-bit integer lanes had no conversion or multiply there and
    // were done lane by lane).
    typedef std::int32_t I32 __attribute__((vector_size(4 * W)));
    const real zero = splat(T(0)), one = splat(T(1));
    const real ax = blend(d.x < zero, -d.x, d.x), ay = blend(d.y < zero, -d.y, d.y), az = blend(d.z < zero, -d.z, d.z);
    const mask yx = ay > ax;
    real major = blend(yx, ay, ax), u = blend(yx, d.z, d.y), v = blend(yx, d.x, d.z);
    const mask zx = az > major;
    major = blend(zx, az, major);
    u = blend(zx, d.x, u);
    v = blend(zx, d.y, v);
    const real along = blend(zx, d.z, blend(yx, d.y, d.x));
    const real face = blend(zx, splat(T(4)), blend(yx, splat(T(2)), zero)) + blend(along < zero, one, zero);
    const real grid = splat(T(kHullStartGrid)), half = splat(T(0.5 * kHullStartGrid));
    const real k = half / major;
    const mask ok = (major > zero) & (k <= splat(std::numeric_limits<T>::max()));
    // [0, grid) -> its integer part, [grid, inf) -> grid - 1, below 1 and NaN -> 0: in range before converting
    const real fu = u * k + half, fv = v * k + half;
    const real cu = blend(fu >= one, blend(fu < grid, fu, grid - one), zero);
    const real cv = blend(fv >= one, blend(fv < grid, fv, grid - one), zero);
    const real iu = __builtin_convertvector(__builtin_convertvector(cu, I32), real);  // truncated, as uint32_t(f)
    const real iv = __builtin_convertvector(__builtin_convertvector(cv, I32), real);
    const real c = blend(ok, (face * grid + iu) * grid + iv, splat(T(-1)));  // -1: kNoHullVertex as uint32_t
    const I32 ci = __builtin_convertvector(c, I32);
    std::memcpy(cell, &ci, sizeof ci);
  }
  /// start_cells() on directions xyz[3 i ..], W at a time (the last register padded with zero directions).
  static void start_cells_of(const T* xyz, std::size_t n, std::uint32_t* out) {
    for (std::size_t i = 0; i < n; i += W) {
      V3 d{splat(T(0)), splat(T(0)), splat(T(0))};
      for (int l = 0; l < W && i + l < n; ++l) d.x[l] = xyz[3 * (i + l)], d.y[l] = xyz[3 * (i + l) + 1], d.z[l] = xyz[3 * (i + l) + 2];
      std::uint32_t cell[W];
      start_cells(d, cell);
      for (int l = 0; l < W && i + l < n; ++l) out[i + l] = cell[l];
    }
  }

  // ---- Newton search direction (see the drive() loop; tests/support/reference_gjk.hpp, same operations) ----
  /// Symmetric 3x3 matrix: the Hessian of a support function.
  struct Sym {
    real xx, yy, zz, xy, xz, yz;
  };
  /// Core types whose support function has a non-zero Hessian somewhere (a curved boundary): the others (points,
  /// segments, boxes, triangles, hulls) have support maps that are piecewise constant in the direction.
  static constexpr bool curved(ShapeType t) {
    return t == ShapeType::ellipsoid || t == ShapeType::cylinder || t == ShapeType::cone;
  }
  /// Hessian of the support function h(u) = max <p, u> of a cylinder or cone at the unit direction u (its own
  /// frame): the Jacobian of the support map, which moves the support point along the boundary as u turns. It has u
  /// in its null space (h is 1-homogeneous). Rim of radius r, rho = |u_xy|: (r / rho^3) [uy^2, -ux uy; -ux uy, ux^2]
  /// in the xy block (r times the projector orthogonal to the axis and to the radial direction, over rho); zero on
  /// a cone's apex and where rho = 0 (the support map jumps there). A's side only: B's is rim_hessian(), and an
  /// ellipsoid's is ellipsoid_hessian().
  static Sym support_hessian(const Side& s, const V3& u) {
    const real zero = splat(T(0));
    Sym h{zero, zero, zero, zero, zero, zero};
    const real rho2 = u.x * u.x + u.y * u.y;
    const real k = s.s0 / (rho2 * wsqrt<T>(rho2));
    mask ok = rho2 > zero;
    if (s.type == ShapeType::cone) ok &= ~(s.s1 * u.z >= (-s.s1) * u.z + s.s0 * wsqrt<T>(rho2));  // support()'s apex test
    h.xx = blend(ok, (k * u.y) * u.y, zero);
    h.yy = blend(ok, (k * u.x) * u.x, zero);
    h.xy = blend(ok, -((k * u.x) * u.y), zero);
    return h;
  }
  /// An ellipsoid's support Hessian in A's frame from its support point: g = the support point's offset from the
  /// centre (A's frame), u the unit direction, M = R diag(r^2) R^T (R the ellipsoid's rotation in A's frame):
  /// (M - g g^T) / m, m = <g, u> = |diag(r) R^T u|. The same matrix as R (diag(r^2) - g_B g_B^T) R^T / m in exact
  /// arithmetic (g = R g_B, g_B the support point in the ellipsoid's frame), without the two 3x3 products and the
  /// ellipsoid's own norm and divisions: the support point is already there.
  AI static Sym ellipsoid_hessian(const Sym& M, const V3& g, const V3& u) {
    const real zero = splat(T(0));
    const real m = dot(g, u);
    const mask ok = m > zero;
    const real im = splat(T(1)) / m;
    return {blend(ok, (M.xx - g.x * g.x) * im, zero), blend(ok, (M.yy - g.y * g.y) * im, zero),
            blend(ok, (M.zz - g.z * g.z) * im, zero), blend(ok, (M.xy - g.x * g.y) * im, zero),
            blend(ok, (M.xz - g.x * g.z) * im, zero), blend(ok, (M.yz - g.y * g.z) * im, zero)};
  }
  /// R diag(r^2) R^T (R row-major): an ellipsoid's metric in A's frame.
  AI static Sym ellipsoid_metric(const Side& s, const real* R) {
    const real q[3] = {s.s0 * s.s0, s.s1 * s.s1, s.s2 * s.s2};
    real P[9];
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) P[3 * i + k] = R[3 * i + k] * q[k];
    const auto e = [&](int i, int j) { return (P[3 * i] * R[3 * j] + P[3 * i + 1] * R[3 * j + 1]) + P[3 * i + 2] * R[3 * j + 2]; };
    return {e(0, 0), e(1, 1), e(2, 2), e(0, 1), e(0, 2), e(1, 2)};
  }
  /// A cylinder's or cone's rim Hessian in A's frame at the unit direction n (B's side, rotation R): with the axis
  /// a = R e_z and c = a x n (= R (e_z x R^T n), |c| = rho), support_hessian()'s (r / rho^3) [uy^2, -ux uy; ..]
  /// rotated is (r / rho^3) c c^T: a cross product and an outer product instead of R H R^T's two 3x3 products.
  AI static Sym rim_hessian(const Side& s, const real* R, const V3& n) {
    const real zero = splat(T(0));
    const V3 axis = {R[2], R[5], R[8]};
    const V3 c = cross(axis, n);
    const real rho2 = norm2(c);
    const real rho = wsqrt<T>(rho2);
    mask ok = rho2 > zero;
    if (s.type == ShapeType::cone) {
      const real uz = dot(axis, n);
      ok &= ~(s.s1 * uz >= (-s.s1) * uz + s.s0 * rho);  // support()'s apex test
    }
    const real k = s.s0 / (rho2 * rho);
    const V3 kc = scale(k, c);
    return {blend(ok, kc.x * c.x, zero), blend(ok, kc.y * c.y, zero), blend(ok, kc.z * c.z, zero),
            blend(ok, kc.x * c.y, zero), blend(ok, kc.x * c.z, zero), blend(ok, kc.y * c.z, zero)};
  }

  /// Vertex i of `v` (packed xyz triples, `count` of them) into row i of one lane's column of the table, from
  /// `to` = the lane's element of row 0 of vx (vy and vz follow vx in SmallHulls: fixed offsets from it). One
  /// pointer walk, unrolled, with no aliasing between the hull and the table: written with three indexed
  /// arrays, GCC versioned the loop for vectorisation (alias and length checks) and ran it scalar anyway at 8
  /// vertices (~120 instructions per small hull copied; convex8-convex8 witness copies two per pair).
  static void copy_rows(T* __restrict to, const double* __restrict v, int count) {
    static_assert(sizeof(SmallHulls) == 3 * sizeof(real) * kSmallRows, "vx, vy, vz contiguous");
    constexpr int Y = kSmallRows * W, Z = 2 * kSmallRows * W;
    int i = 0;
    for (; i + 4 <= count; i += 4, v += 12, to += 4 * W) {
      for (int r = 0; r < 4; ++r) {
        to[r * W] = T(v[3 * r]);
        to[r * W + Y] = T(v[3 * r + 1]);
        to[r * W + Z] = T(v[3 * r + 2]);
      }
    }
    for (; i < count; ++i, v += 3, to += W) to[0] = T(v[0]), to[Y] = T(v[1]), to[Z] = T(v[2]);
  }

  /// Puts lane l's small hull into the table: its vertices, then its last vertex up to `rows`; when the hull has
  /// more vertices than `rows`, the other lanes are padded up to the new row count first.
  static void load_small_hull(Side& s, int l, const HullView& hull) {
    const int count = int(hull.vertex_count);
    // Lane l of row i is element i * W + l of each coordinate array (rows are W contiguous lanes).
    T* x = reinterpret_cast<T*>(s.table->vx);
    T* y = reinterpret_cast<T*>(s.table->vy);
    T* z = reinterpret_cast<T*>(s.table->vz);
    if (count > s.rows) {
      for (int o = 0; o < W; ++o) {
        if (o == l) continue;
        const int last = int(s.lane_vertices[o]) - 1;
        const int from = last >= 0 ? s.rows : 0;  // a never-loaded lane gets zero rows
        const T px = last >= 0 ? x[last * W + o] : T(0), py = last >= 0 ? y[last * W + o] : T(0),
                pz = last >= 0 ? z[last * W + o] : T(0);
        for (int i = from; i < count; ++i) x[i * W + o] = px, y[i * W + o] = py, z[i * W + o] = pz;
      }
      s.rows = count;
    }
    copy_rows(reinterpret_cast<T*>(s.table) + l, hull.vertices, count);
    const int last = count - 1;
    for (int i = count; i < s.rows; ++i)
      x[i * W + l] = x[last * W + l], y[i * W + l] = y[last * W + l], z[i * W + l] = z[last * W + l];
    s.lane_vertices[l] = std::uint32_t(count);
  }

  // ---- Projection of the origin on a simplex (tests/support/reference_simplex_projection.hpp) ----
  struct Proj {
    V3 x;
    mask count;
    mask index[4];
    real lambda[4];
    mask contains;
  };
  AI static Proj pick(mask m, const Proj& a, const Proj& b) {
    Proj r;
    r.x = pick(m, a.x, b.x);
    r.count = blend(m, a.count, b.count);
    for (int i = 0; i < 4; ++i) {
      r.index[i] = blend(m, a.index[i], b.index[i]);
      r.lambda[i] = blend(m, a.lambda[i], b.lambda[i]);
    }
    r.contains = blend(m, a.contains, b.contains);
    return r;
  }
  static Proj empty() {
    Proj r;
    r.x = {splat(T(0)), splat(T(0)), splat(T(0))};
    r.count = splat_mask(0);
    for (int i = 0; i < 4; ++i) { r.index[i] = splat_mask(0); r.lambda[i] = splat(T(0)); }
    r.contains = splat_mask(0);
    return r;
  }
  /// Closest point of a segment, kept small while candidates are compared (7 registers instead of a Proj's 13):
  /// kind 0 = vertex i, 1 = vertex j, 2 = interior point (1 - u) qi + u qj.
  struct Edge {
    V3 x;
    real u;
    mask kind, i, j;
  };
  AI static Edge pick(mask m, const Edge& a, const Edge& b) {
    return {pick(m, a.x, b.x), blend(m, a.u, b.u), blend(m, a.kind, b.kind), blend(m, a.i, b.i), blend(m, a.j, b.j)};
  }
  /// The segment from qi to qj (input indices i, j in each lane): the reference's segment(), same operations.
  AI static Edge edge(const V3& qi, const V3& qj, mask i, mask j) {
    const V3 t = sub(qj, qi);
    const real tt = norm2(t);
    const real u = (-dot(qi, t)) / tt;
    const real zero = splat(T(0)), one = splat(T(1));
    const mask at_i = (tt == zero) | (u <= zero), at_j = ~at_i & (u >= one);
    const V3 inner = add(scale(one - u, qi), scale(u, qj));
    return {pick(at_i, qi, pick(at_j, qj, inner)), u, blend(at_i, splat_mask(0), blend(at_j, splat_mask(1), splat_mask(2))), i, j};
  }
  AI static Proj to_proj(const Edge& e) {
    const mask inner = e.kind == splat_mask(2), at_j = e.kind == splat_mask(1);
    const real zero = splat(T(0)), one = splat(T(1));
    Proj r = empty();
    r.x = e.x;
    r.count = blend(inner, splat_mask(2), splat_mask(1));
    r.index[0] = blend(at_j, e.j, e.i);
    r.index[1] = blend(inner, e.j, splat_mask(0));
    r.lambda[0] = blend(inner, one - e.u, one);
    r.lambda[1] = blend(inner, e.u, zero);
    return r;
  }
  /// Triangle qi, qj, qk (qk newest), the reference's triangle() up to the choice of edge: the interior point and
  /// its weights, whether it is the answer (`use`), else which of the edges i-k, j-k are candidates.
  struct Face {
    V3 x;
    real lambda[3];
    mask use, via_i, via_j;
  };
  /// The face's normal comes from the caller: n = (qi - qk) x (qj - qk), nn = |n|^2, sn = <qk, n>, t = sn / nn
  /// (the origin's projection on the plane is t n; the tetrahedron's farthest-face rule reads sn t). project()
  /// computes them for every face keeping s anyway (the tetrahedron's visibility rule and its signed volumes), so
  /// the face does not compute them again.
  struct Plane {
    V3 n;
    real nn, sn, t;
  };
  static Plane plane(const V3& qi, const V3& qj, const V3& qk) {
    Plane h;
    h.n = cross(sub(qi, qk), sub(qj, qk));
    h.nn = norm2(h.n);
    h.sn = dot(qk, h.n);
    h.t = h.sn / h.nn;
    return h;
  }
  AI static Plane pick(mask m, const Plane& a, const Plane& b) {
    return {pick(m, a.n, b.n), blend(m, a.nn, b.nn), blend(m, a.sn, b.sn), blend(m, a.t, b.t)};
  }
  AI static Face face(const V3& qi, const V3& qj, const V3& qk, const Plane& h) {
    const real zero = splat(T(0));
    const V3& n = h.n;
    // The weights as the reference's triangle() computes them: triple products with r = qk - t n and the edges at
    // qk, C_k = |n|^2 - C_i - C_j; the total is |n|^2 > 0, so a weight is of the wrong sign when negative.
    const V3 r = sub(qk, scale(h.t, n));
    const real Ci = dot(r, cross(n, sub(qj, qk))), Cj = dot(r, cross(sub(qi, qk), n));
    const real C[3] = {Ci, Cj, (h.nn - Ci) - Cj};
    const mask neg_i = C[0] < zero, neg_j = C[1] < zero;
    const mask inside = ~neg_i & ~neg_j & ~(C[2] < zero);
    Face f;
    // One division and three products instead of three divisions (tests/support/reference_simplex_projection.hpp
    // alike): the loop is bound by its divisions and square roots on AVX-512 double (face_direction() says why);
    // the weights move by at most an ulp or so, well inside the rounding of the triple products themselves.
    const real inv = splat(T(1)) / ((C[0] + C[1]) + C[2]);
    for (int m = 0; m < 3; ++m) f.lambda[m] = C[m] * inv;
    f.x = add(add(scale(f.lambda[0], qi), scale(f.lambda[1], qj)), scale(f.lambda[2], qk));
    const mask degenerate = h.nn == zero;
    // Inside, the weights' sum is positive (triangle() says why): no test of it.
    f.use = ~degenerate & inside;
    // Edge i-k is opposite j (weight C[1]), edge j-k opposite i (C[0]); neither or both: both are candidates.
    const mask wrong_i = ~degenerate & neg_j, wrong_j = ~degenerate & neg_i;
    f.via_i = wrong_i | ~wrong_j;
    f.via_j = wrong_j | ~wrong_i;
    return f;
  }
  /// Lanes where the face's answer is edge j-k rather than edge i-k (the reference's closer(i-k, j-k) when both
  /// are candidates: j-k only if strictly closer), given the two edges' squared norms.
  static mask takes_j(const Face& f, real ni, real nj) { return f.via_j & (~f.via_i | (nj < ni)); }

  AI static Proj face_proj(const Face& f, mask i, mask j, mask k) {
    Proj r = empty();
    r.x = f.x;
    r.count = splat_mask(3);
    r.index[0] = i, r.index[1] = j, r.index[2] = k;
    for (int m = 0; m < 3; ++m) r.lambda[m] = f.lambda[m];
    return r;
  }

  static real det3(const V3& a, const V3& b, const V3& c) { return dot(a, cross(b, c)); }

  /// GJK's projection step on every live lane at once: the reference's project_origin(p, count + 1) with p[count]
  /// = s the new support point (segment(), triangle() or tetrahedron() by the lane's size), the same operations
  /// per lane. The three sizes share their work, since a register's lanes are usually at different sizes (they
  /// start pairs at different times): every candidate edge keeps the newest vertex, so edge k is edge(p[k], s)
  /// whatever the lane's size (the segment lanes' segment, the triangle lanes' two edges, the tetrahedron lanes'
  /// three), computed once; the triangle lanes' face and the tetrahedron lanes' first face are one face() call; and
  /// one Proj (13 registers) is assembled at the end instead of one per size.
  /// p[0 .. count) are the old vertices, s the new one; s has index 3 in the answer whatever the lane's size
  /// (input index `count` in the reference's terms: the caller maps 3 to it), so no step writes s into slot
  /// `count` first, and the caller's compaction reads it from a fixed place.
  AI static Proj project(const V3* p, const V3& s, mask count, mask live) {
    const real zero = splat(T(0));
    const mask three = live & (count == splat_mask(2)), four = live & (count == splat_mask(3));
    const mask newest = splat_mask(3);  // s's index (see above)
    // Only segment lanes (the first iterations of a run, short pairs): the segment alone, as segment() did.
    if (!any(three | four)) return to_proj(edge(p[0], s, splat_mask(0), newest));
    // Tetrahedron lanes (tetrahedron()): the origin inside, else the faces keeping vertex 3 that it sees (cand[m]:
    // face m omits vertex m), and the visible face whose plane is farthest from the origin (the reference's rule,
    // same arithmetic): where the origin's projection lies inside that face, it is the answer; else an edge to s is
    // (below), so one face() serves every lane (on smooth shapes the origin sees all three new faces of a flat tent).
    // The planes of the faces keeping s (face m omits old vertex m): n_m = (p_I - s) x (p_J - s). Face 2 (p0 p1 s)
    // is also the triangle lanes' face; the tetrahedron lanes need all three. Their <s, n_m> are the signed
    // volumes V[0], -V[1], V[2] (the triple product <s, (p_I - s) x (p_J - s)> = <s, p_I x p_J>), so three of the
    // four determinants are not computed again, and the face() call takes its plane from here.
    Plane h[3];
    h[2] = plane(p[0], p[1], s);
    h[0] = h[1] = h[2];
    real V[4] = {zero, zero, zero, zero}, total = zero;
    mask inside = splat_mask(0), have_first = splat_mask(0), first_0 = splat_mask(0), first_2 = splat_mask(0);
    mask cand[3] = {splat_mask(0), splat_mask(0), splat_mask(0)};
    if (any(four)) {
      h[0] = plane(p[1], p[2], s), h[1] = plane(p[0], p[2], s);
      V[0] = h[0].sn, V[1] = -h[1].sn, V[2] = h[2].sn, V[3] = -det3(p[0], p[1], p[2]);
      total = ((V[0] + V[1]) + V[2]) + V[3];
      inside = four & (total != zero);
      for (int m = 0; m < 4; ++m) inside &= ~opposite_sign(V[m], total);
      for (int m = 0; m < 3; ++m) cand[m] = four & ~inside & ((total == zero) | opposite_sign(V[m], total));
      real far = zero;
      mask choice = splat_mask(0);
      for (int m = 0; m < 3; ++m) {
        const real q = blend(h[m].nn > zero, h[m].sn * h[m].t, splat(T(-1)));
        const mask take = cand[m] & (~have_first | (q > far));
        far = blend(take, q, far);
        choice = blend(take, splat_mask(m), choice);
        have_first |= cand[m];
      }
      first_0 = have_first & (choice == splat_mask(0)), first_2 = have_first & (choice == splat_mask(2));
    }
    // One face: the triangle lanes' p0 p1 s (triangle()), the tetrahedron lanes' first face (face m holds old
    // vertices 1 2, 0 2 or 0 1 for m = 0, 1, 2).
    const mask fi = blend(first_0, splat_mask(1), splat_mask(0));
    const mask fj = blend(three, splat_mask(1), blend(first_2, splat_mask(1), splat_mask(2)));
    // Computed whatever the lanes (only segment lanes is rare): no branch, and no default value to write first.
    const mask first_1 = have_first & ~first_0 & ~first_2;
    const Face f = face(pick(first_0, p[1], p[0]), pick(three, p[1], pick(first_2, p[1], p[2])), s,
                        pick(first_0, h[0], pick(first_1, h[1], h[2])));
    const mask first_ok = have_first & f.use;
    // Edges to the new vertex (input indices k and 3), where some lane's answer may be one.
    const mask tri_edges = three & ~f.use, rest = four & ~inside & ~first_ok;
    // Edge 0 is computed whatever the lanes (segment lanes nearly always need it); edges 1 and 2 start as copies of
    // it where no lane needs them (registers, not zeroed memory).
    Edge E[3];
    real En[3];
    E[0] = edge(p[0], s, splat_mask(0), newest), En[0] = norm2(E[0].x);
    E[1] = E[0], En[1] = En[0], E[2] = E[0], En[2] = En[0];
    if (any(tri_edges | rest)) E[1] = edge(p[1], s, splat_mask(1), newest), En[1] = norm2(E[1].x);
    // The tetrahedron lanes whose first face was not the answer: their answer is an edge to s, the closest of the
    // edges k-3 of the visible faces (the reference's tetrahedron() says why no other face's interior can be
    // closer). Those are the edges the faces' own triangle() calls chose between, so no other face() is computed.
    real best_n2 = splat(std::numeric_limits<T>::infinity());
    mask best_edge = splat_mask(0), have = splat_mask(0);
    if (any(rest)) {
      E[2] = edge(p[2], s, splat_mask(2), newest), En[2] = norm2(E[2].x);
      // Edge k belongs to the visible faces that hold old vertex k: face m holds every old vertex but m. Visited
      // in order, the first of equal ones kept.
      const mask holds[3] = {cand[1] | cand[2], cand[0] | cand[2], cand[0] | cand[1]};
      for (int k = 0; k < 3; ++k) {
        const mask on = rest & holds[k];
        const mask take = on & (~have | (En[k] < best_n2));
        best_n2 = blend(take, En[k], best_n2);
        best_edge = blend(take, splat_mask(k), best_edge);
        have |= on;
      }
    }
    // The answer: a face (the triangle lanes' face, the first face) or an edge (the segment, the triangle lanes'
    // closer edge, the tetrahedron lanes' closest visible edge).
    const mask from_best = rest;
    Edge e = pick(three & takes_j(f, En[0], En[1]), E[1], E[0]);
    for (int k = 1; k < 3; ++k) e = pick(from_best & (best_edge == splat_mask(k)), E[k], e);
    const mask use_face = (three & f.use) | first_ok;
    Proj r = pick(use_face, face_proj(f, fi, fj, newest), to_proj(e));
    if (any(four)) {
      // No visible face: no candidate (x infinite, count 0); the origin inside: the whole tetrahedron.
      const mask none = from_best & ~have;
      const real inf = splat(std::numeric_limits<T>::infinity());
      r.x = pick(none, V3{inf, inf, inf}, r.x);
      r.count = blend(none, splat_mask(0), r.count);
      if (any(inside)) {
        r.x = pick(inside, V3{zero, zero, zero}, r.x);
        r.count = blend(inside, splat_mask(4), r.count);
        r.contains = inside;
        for (int m = 0; m < 4; ++m) {
          r.index[m] = blend(inside, splat_mask(m), r.index[m]);
          r.lambda[m] = blend(inside, V[m] / total, r.lambda[m]);
        }
      }
    }
    return r;
  }

  // ---- The lanes ----
  struct Lanes {
    Side A, B;
    real R[9]{}, t[3]{};
    V3 w[4]{};  // zeroed: slots past a lane's count are stale, and project() reads them in lanes that ignore them
    // The points of A and B behind the simplex (witness levels) stay in the fixed slot where they were written;
    // slot[m] says which slot holds those of simplex vertex m. Only w is compacted after each projection (the
    // projection reads it in order); a slot index per vertex is cheaper to move than six coordinates.
    V3 a[4], b[4];
    mask slot[4]{};
    real lambda[4]{};
    mask count{}, k{}, stale{}, max_iterations{};
    V3 x, d_prev, last_s, direction;
    real lower{};
    mask momentum{}, normalize{}, boolean_only{};
    // Newton directions: `newton` = lanes that may take them (witness / distance lanes of a curved pair type,
    // until a Newton step fails to progress), `newton_next` = the next iteration steps along newton_dir.
    mask newton{}, newton_next{}, newton_steps{};
    V3 newton_dir;
    real newton_step2{};  // |delta|^2 of the Newton step that chose newton_dir
    real newton_gap{};    // flat pairs: the certified gap when newton_dir was chosen
    real tolerance{}, relative{}, touch{}, core_margin{};
    std::int64_t pair[W];      // pair index of each lane, -1 when empty
    std::uint32_t fresh = 0;  // lanes refilled since the last start(): their first support point is pending
    int newton_pair = -1;     // newton_pair_type(A.type, B.type), set by the first refill of the run; -1: not yet
    // start_candidate_pair() runs of double: each refilled lane's rim_candidate(), box_round_candidate() or
    // box_ellipsoid_candidate() (NaN: none), which start() takes as the first point where it is closer than the first support point (and
    // side_start()'s). `rim_given`: the source wrote them at refill (WideGjkPairs, from its W-pair set-up); else
    // start() computes them.
    bool rim_given = false;
    V3 rim_a, rim_b;
    // Sources that give first points (GivesFirst): each refilled lane's first support point D.support(-d_prev).
    V3 first_w;
  };

  /// The reference's first support point, D.support(-initial direction), for the freshly refilled lanes (their
  /// d_prev holds the initial direction): one SIMD Minkowski support instead of one scalar per refill.
  /// `side`: the run may have distance / witness lanes (side_start(); boolean runs never do).
  /// `dirs` (drive_boolean_directions()): a[0] keeps the search direction d_prev instead of the point of A.
  /// `nesterov`: the run's solver reads last_s (Nesterov's momentum point, the only reader).
  /// A boolean run without `dirs` never reads a[] and b[] (no points, no Newton tracking: loop()'s `track`), and a
  /// run of another solver never reads last_s: they are not written (measured in loop()'s comment).
  /// `given` (boolean runs of a GivesFirst source): the source wrote each fresh lane's first support point into
  /// L.first_w, so no support is computed here.
  AI static void start(Lanes& L, bool side, bool dirs = false, bool nesterov = true, bool given = false) {
    if (L.fresh == 0) return;
    std::uint32_t first = L.fresh;  // the lanes that start from the first support point
    // Sphere-hull runs in double, distance and witness lanes: the candidate replaces the first support point
    // wherever it is finite, so that point is computed only for the fresh lanes without one
    // (wide_gjk_point_hull.inl). No other start below applies to sphere-hull pairs.
    if (std::is_same_v<T, double> && side && point_hull_pair(L.A.type, L.B.type)) {
      first &= ~lane_bits(point_hull_start(L, first & ~lane_bits(L.boolean_only)));
      if (first == 0) {
        L.fresh = 0;
        return;
      }
    }
    V3 sw, sa, sb;
    if (!side && given) sw = sa = sb = L.first_w;  // sa, sb: read by no boolean run (b[0] of `dirs` unused)
    else minkowski(L, neg(L.d_prev), first, sw, sa, sb);
    const mask m = lanes_of(first);
    L.w[0] = pick(m, sw, L.w[0]);
    if (side || dirs) {
      L.a[0] = pick(m, dirs ? L.d_prev : sa, L.a[0]);  // start_lane() set slot[0] = 0
      L.b[0] = pick(m, sb, L.b[0]);
    }
    L.x = pick(m, sw, L.x);
    if (nesterov) L.last_s = pick(m, sw, L.last_s);
    if (side && side_start_pair(L.A.type, L.B.type)) side_start(L, m & ~L.boolean_only);
    if constexpr (std::is_same_v<T, double>) {
      if (side && (L.rim_given || start_candidate_pair(L.A.type, L.B.type))) {
        mask want = m & ~L.boolean_only;
        if (!L.rim_given) {
          // Lanes whose cores overlap cannot keep a candidate (wide_gjk_start_gate.inl): computed only when a
          // fresh lane may (overlap-regime penetration runs mostly skip it).
          want &= ~cores_overlap(L, sa, sb);
          if (!any(want)) {
            L.fresh = 0;
            return;
          }
          start_candidate(box_ellipsoid_pair(L.A.type, L.B.type), L.A.type, L.B.type, L.R, L.t,
                          {L.A.s0, L.A.s1, L.A.s2}, {L.B.s0, L.B.s1, L.B.s2}, L.rim_a, L.rim_b);
        }
        take_start(L, want, L.rim_a, L.rim_b);
      }
    }
    L.fresh = 0;
  }

  /// The start point of a cylinder / capsule pair's distance and witness lanes (`m`) in closed form, where it is
  /// a side contact. A cylinder of radius r lies inside the capsule of its axis segment and radius r, and the two
  /// share the side; so when the closest points of the axis segments (a capsule core's own segment) are interior
  /// to every cylinder's axis segment, their offset is orthogonal to those axes, the capsules' witness points lie
  /// on the cylinders' sides, and they are the cylinders' witness points. Replaces the first support point by
  /// that point of D (and its points of A and B) where it is closer to the origin; the lane's first iteration is
  /// then a plain step (momentum off) whose duality gap certifies it, as any GJK answer, or GJK goes on from there.
  /// Why: on a side line GJK's support points flip between the two rims at angles that converge only linearly
  /// (cylinder-cylinder: 55% of close pairs, ~20 iterations; bench/results/history/narrowphase-sessions.md).
  /// A's axis is (0, 0, z), |z| <= A.s1; B's is t + z b, b = R e_z, |z| <= B.s1 (Ericson's segment-segment
  /// order: B's parameter from the lines' closest points, clamped; A's from it, clamped; B's again if A's was).
  /// tests/support/reference_gjk.hpp's side_start() has the same operations.
  __attribute__((noinline)) static void side_start(Lanes& L, mask m) {
    if (!any(m)) return;
    const real zero = splat(T(0));
    const real ha = L.A.s1, hb = L.B.s1;
    const real ra = L.A.type == ShapeType::cylinder ? L.A.s0 : zero;
    const real rb = L.B.type == ShapeType::cylinder ? L.B.s0 : zero;
    const V3 c = {L.t[0], L.t[1], L.t[2]};
    const V3 b = {L.R[2], L.R[5], L.R[8]};
    const real beta = b.z, cb = dot(c, b), bb = norm2(b);
    const real denom = bb - beta * beta;
    const real zb1 = blend(denom > zero, (beta * c.z - cb) / denom, zero);
    const mask out_b1 = (zb1 > hb) | (zb1 < -hb);
    const real zb1c = blend(zb1 > hb, hb, blend(zb1 < -hb, -hb, zb1));
    const real za = c.z + zb1c * beta;
    const mask out_a = (za > ha) | (za < -ha);
    const real zac = blend(za > ha, ha, blend(za < -ha, -ha, za));
    const real zb2 = (zac * beta - cb) / bb;
    const mask out_b2 = (zb2 > hb) | (zb2 < -hb);
    const real zb = blend(out_a, blend(zb2 > hb, hb, blend(zb2 < -hb, -hb, zb2)), zb1c);
    mask ok = m;
    if (L.A.type == ShapeType::cylinder) ok &= ~out_a;
    if (L.B.type == ShapeType::cylinder) ok &= ~blend(out_a, out_b2, out_b1);
    const V3 qa = {zero, zero, zac}, qb = add(c, scale(zb, b));
    const V3 v = sub(qa, qb);
    const real vn = norm(v);
    ok &= vn > ra + rb;
    const V3 u = divide(v, vn);
    const V3 pa = sub(qa, scale(ra, u)), pb = add(qb, scale(rb, u));
    const V3 x = sub(pa, pb);
    ok &= norm2(x) < norm2(L.x);
    if (!any(ok)) return;
    L.w[0] = pick(ok, x, L.w[0]);
    L.a[0] = pick(ok, pa, L.a[0]);  // slot[0] = 0 (start_lane())
    L.b[0] = pick(ok, pb, L.b[0]);
    L.x = pick(ok, x, L.x);
    L.last_s = pick(ok, x, L.last_s);
    L.momentum &= ~ok;
  }

  /// The point pa - pb of D (pa on A, pb on B, A's frame) replaces lane's first point in `ok` where it is closer
  /// to the origin (side_start()'s rule; NaN points never are), and the lane's first step is a plain one.
  AI static void take_start(Lanes& L, mask ok, const V3& pa, const V3& pb) {
    const V3 x = sub(pa, pb);
    ok &= norm2(x) < norm2(L.x);
    if (!any(ok)) return;
    L.w[0] = pick(ok, x, L.w[0]);
    L.a[0] = pick(ok, pa, L.a[0]);  // slot[0] = 0 (start_lane())
    L.b[0] = pick(ok, pb, L.b[0]);
    L.x = pick(ok, x, L.x);
    L.last_s = pick(ok, x, L.last_s);
    L.momentum &= ~ok;
  }

  /// A rim of core X against the lateral surface of core Y, in X's frame: the rim is the circle of radius r at
  /// height zr on X's axis (0, 0, 1); Y has its centre at c, its unit axis b, radius ry (0: a capsule's segment)
  /// and half-height hy, and is a cone (apex at c + hy b, base rim at c - hy b) or else a cylinder. The rim point
  /// px(theta) = (r cos theta, r sin theta, zr) nearest to Y's lateral surface, by kRimNewtonSteps Newton steps on
  /// theta, and its foot py on that surface; `ok` keeps the lanes whose foot lies on the surface (inside the side
  /// or the slant) with px outside it. Then px - py is a point of D, and where the pair's optimum is this
  /// rim-lateral contact it is the optimum (up to the Newton steps' error): GJK's first plain step certifies it.
  /// Minimised: a cylinder's squared distance to its axis line, phi = |v|^2 - <v, b>^2 (v = px - c); a cone's
  /// signed distance to the slant's line in the (rho, z) half-plane times its length, 2 hy rho + ry <v, b> (rho
  /// = sqrt(phi)). With (C, S) = (cos, sin) theta, v' = r (-S, C, 0), v'' = r (-C, -S, 0); phi' / 2 = g = <v, v'>
  /// - <v, b> <v', b>, phi'' / 2 = h = |v'|^2 + <v, v''> - <v', b>^2 - <v, b> <v'', b>, rho' = g / rho, rho'' =
  /// (h - rho'^2) / rho. A step turns (C, S) by dt to (C - dt S, S + dt C) / sqrt(1 + dt^2) (angle atan(dt): an
  /// O(dt^3) error, below Newton's quadratic one); where the second derivative is not positive it does not move.
  /// A cone's step is Newton's on the root of F = 2 rho f' (f = 2 hy rho + ry <v, b>), dt = -f' / (f'' + f' rho' /
  /// rho): near a contact close to the apex rho(theta) is a sharp hyperbola, k sqrt(a^2 + x^2), on which Newton's
  /// step on f itself is -x (a^2 + x^2) / a^2 (it jumped from the best sample to where f'' < 0 and stayed there) and
  /// this one is -x, exact. Close witness double cylinder-cone rim-slant contacts (7243 of 20000 pairs), from the
  /// sampled start: plain steps 3.95 mean iterations (5992 in one), this step 1.18 (7115 in one).
  /// Start: the best of kEdgeRimSamples angles (lateral_start(), wide_gjk_rim_rim.inl; from the direction of Y's
  /// axis point nearest to the rim's centre, the start before, Newton found the far one of the two minima: the same
  /// rim-slant contacts took 5.29 mean iterations with this step).
  /// Why: GJK's support points on a rim bisect the rim angle (on a circle against a point the chord's normal, so
  /// the next support, is at the mean of its ends' angles), a linear rate of 1/2: cylinder-cylinder rim vs side
  /// took 20.4 iterations, cone-cone rim vs slant 19.2 (bench/results/history/narrowphase-sessions.md).
  AI static void rim_lateral(real r, real zr, const V3& c, const V3& b, real ry, real hy, bool cone, V3& px, V3& py,
                             mask& ok) {
    const real zero = splat(T(0)), one = splat(T(1));
    real C, S;
    lateral_start(r, zr, c, b, ry, hy, cone, C, S);
    const real kr = T(2) * hy;
    for (int it = 0; it < kRimNewtonSteps; ++it) {
      const V3 v = {r * C - c.x, r * S - c.y, zr - c.z};
      const V3 v1 = {-(r * S), r * C, zero}, v2 = {-(r * C), -(r * S), zero};
      const real vb = dot(v, b), v1b = dot(v1, b), v2b = dot(v2, b);
      const real g = dot(v, v1) - vb * v1b;
      const real h = (dot(v1, v1) + dot(v, v2)) - (v1b * v1b + vb * v2b);
      real dt;
      if (cone) {
        const real ir = one / wsqrt<T>(dot(v, v) - vb * vb);
        const real r1 = g * ir, r2 = (h - r1 * r1) * ir;
        const real f1 = kr * r1 + ry * v1b, f2 = kr * r2 + ry * v2b;
        const real den = f2 + (f1 * r1) * ir;
        dt = blend(den > zero, -f1 / den, zero);
      } else {
        dt = blend(h > zero, -g / h, zero);
      }
      const real C1 = C - dt * S, S1 = S + dt * C;
      const real inv = one / wsqrt<T>(C1 * C1 + S1 * S1);
      C = C1 * inv;
      S = S1 * inv;
    }
    px = {r * C, r * S, zr};
    const V3 v = sub(px, c);
    const real vb = dot(v, b);
    const V3 e = sub(v, scale(vb, b));
    const real rho = norm(e);
    if (cone) {  // the foot on the slant from (rho, z) = (0, hy) to (ry, -hy), at sg of its length
      const real sg = (rho * ry - kr * (vb - hy)) / (ry * ry + kr * kr);
      ok &= (sg >= zero) & (sg <= one) & (kr * rho + ry * (vb - hy) > zero) & (rho > zero);
      py = add(add(c, scale(hy - kr * sg, b)), scale((sg * ry) / rho, e));
    } else {
      ok &= (vb <= hy) & (vb >= -hy) & (rho > ry);
      py = add(add(c, scale(vb, b)), scale(ry / rho, e));
    }
  }

  /// The closed-form start candidate of a start_candidate_pair() run (`box_ell`: box_ellipsoid_pair(ta, tb), decided
  /// once per run by the caller), in A's frame: pa, pb (NaN where there is none). One place for the choice, which the
  /// lanes' start() and WideGjkPairs' chunk set-up both make.
  AI static void start_candidate(bool box_ell, ShapeType ta, ShapeType tb, const real* R, const real* t,
                                 const real (&a)[3], const real (&b)[3], V3& pa, V3& pb) {
    if (box_ell) box_ellipsoid_candidate(ta, tb, R, t, a[0], a[1], a[2], b[0], b[1], b[2], pa, pb);
    else if (box_round_pair(ta, tb)) box_round_candidate(ta, tb, R, t, a[0], a[1], a[2], b[0], b[1], b[2], pa, pb);
    else if (round_ellipsoid_pair(ta, tb)) round_ellipsoid_candidate(ta, tb, R, t, a[0], a[1], a[2], b[0], b[1], b[2], pa, pb);
    else rim_candidate(ta, tb, R, t, a[0], a[1], b[0], b[1], pa, pb);
  }

  /// The closest start candidate of W pairs of a rim_start_pair() type (A's frame; a later candidate only where
  /// strictly closer). Cylinder / cone pairs: the rim-lateral points of D (rim_lateral()): A's rims against B's
  /// lateral surface, then B's against A's (B's frame: A's centre -R^T t, axis R^T e_z; mapped back by R and t), a
  /// cylinder's rim at +h before -h; then round_round() (wide_gjk_rim_rim.inl) in A's frame (rim vs rim, A's rim vs
  /// B's cap, A's apex) and in B's (B's rim vs A's cap, B's apex), and a cylinder's side against a cone's slant
  /// (side_slant(), in the cone's frame), or a cone's slant against a cone's (slant_slant()). A capsule against a
  /// cylinder / cone: round_segment() in the round core's frame (the segment's ends, the rim and a cone's slant and
  /// apex against the segment; its rim against the segment replaces rim_lateral()'s, whose start (before
  /// lateral_start()) found the far one of the line distance's two minima). Kept only where the candidate's
  /// direction separates the cores (round_apart()). R (row-major), t: B's pose in A's frame; a0, a1 / b0, b1: the
  /// cores' radius and half-height (a capsule's half-length). pa, pb: A's and B's points in A's frame, NaN where no
  /// candidate is valid.
  /// Computed where the pairs are set up, W at a time (WideGjkPairs' fill_slots()): per refilled lane its ~50
  /// divisions and square roots made cylinder-cylinder slower in wall time although 34% fewer instructions.
  __attribute__((noinline)) static void rim_candidate(ShapeType ta, ShapeType tb, const real* R, const real* t,
                                                      real a0, real a1, real b0, real b1, V3& pa, V3& pb) {
    const real zero = splat(T(0)), nan = splat(std::numeric_limits<T>::quiet_NaN());
    pa = pb = {nan, nan, nan};
    mask has = splat_mask(0);
    real best{};
    const auto keep = [&](mask ok, const V3& qa, const V3& qb) {
      const real n2 = norm2(sub(qa, qb));
      const mask take = ok & (~has | (n2 < best));
      pa = pick(take, qa, pa);
      pb = pick(take, qb, pb);
      best = blend(take, n2, best);
      has |= take;
    };
    const V3 c = {t[0], t[1], t[2]}, b = {R[2], R[5], R[8]};
    // B's frame: A's centre and axis.
    const V3 ca = {-((R[0] * t[0] + R[3] * t[1]) + R[6] * t[2]), -((R[1] * t[0] + R[4] * t[1]) + R[7] * t[2]),
                   -((R[2] * t[0] + R[5] * t[1]) + R[8] * t[2])};
    const V3 a = {R[6], R[7], R[8]};
    const auto back = [&](const V3& q) {
      return V3{((R[0] * q.x + R[1] * q.y) + R[2] * q.z) + t[0], ((R[3] * q.x + R[4] * q.y) + R[5] * q.z) + t[1],
                ((R[6] * q.x + R[7] * q.y) + R[8] * q.z) + t[2]};
    };
    if (ta == ShapeType::capsule || tb == ShapeType::capsule) {
      if (tb == ShapeType::capsule) {  // A round: the segment t + z b in A's frame; its points R (0, 0, z) + t
        round_segment(a0, a1, ta == ShapeType::cone, c, b, b1,
                      [&](mask ok, const V3& px, const real& z) { keep(ok, px, back(V3{zero, zero, z})); });
      } else {  // B round: the segment in B's frame; its points (0, 0, z) in A's frame
        round_segment(b0, b1, tb == ShapeType::cone, ca, a, a1,
                      [&](mask ok, const V3& px, const real& z) { keep(ok, V3{zero, zero, z}, back(px)); });
      }
    } else {
      for (int sg = ta == ShapeType::cone ? -1 : 1; sg >= -1; sg -= 2) {
        V3 qa, qb;
        mask ok = splat_mask(-1);
        rim_lateral(a0, T(sg) * a1, c, b, b0, b1, tb == ShapeType::cone, qa, qb, ok);
        keep(ok, qa, qb);
      }
      for (int sg = tb == ShapeType::cone ? -1 : 1; sg >= -1; sg -= 2) {
        V3 qb, qa;
        mask ok = splat_mask(-1);
        rim_lateral(b0, T(sg) * b1, ca, a, a0, a1, ta == ShapeType::cone, qb, qa, ok);
        keep(ok, back(qa), back(qb));
      }
      round_round(a0, a1, ta == ShapeType::cone, c, b, b0, b1, tb == ShapeType::cone, true,
                  [&](mask ok, const V3& px, const V3& py) { keep(ok, px, py); });
      round_round(b0, b1, tb == ShapeType::cone, ca, a, a0, a1, ta == ShapeType::cone, false,
                  [&](mask ok, const V3& px, const V3& py) { keep(ok, back(py), back(px)); });
      if (ta == ShapeType::cone && tb == ShapeType::cylinder) {
        V3 px, py;
        mask ok = splat_mask(-1);
        side_slant(b0, b1, a0, a1, c, b, px, py, ok);
        keep(ok, px, py);
      } else if (ta == ShapeType::cylinder && tb == ShapeType::cone) {
        V3 px, py;
        mask ok = splat_mask(-1);
        side_slant(a0, a1, b0, b1, ca, a, px, py, ok);
        keep(ok, back(py), back(px));
      } else if (ta == ShapeType::cone && tb == ShapeType::cone) {
        V3 px, py;
        mask ok = splat_mask(-1);
        slant_slant(a0, a1, c, b, b0, b1, px, py, ok);
        keep(ok, px, py);
      }
    }
    const mask apart = round_apart(ta, tb, R, t, a0, a1, b0, b1, pa, pb);
    pa = pick(apart, pa, V3{nan, nan, nan});
    pb = pick(apart, pb, V3{nan, nan, nan});
  }

#include "kernels/simd/wide_gjk_point_hull.inl"
#include "kernels/simd/wide_gjk_box_ellipsoid.inl"
#include "kernels/simd/wide_gjk_box_round.inl"
#include "kernels/simd/wide_gjk_rim_rim.inl"
#include "kernels/simd/wide_gjk_round_ellipsoid.inl"
#include "kernels/simd/wide_gjk_start_gate.inl"

  /// One side of a lane's pair: what the support functions read (ShapeCore's size, triangle, hull).
  struct SideStart {
    T size[3];
    const std::array<Vec3<T>, 3>* triangle;  // triangle cores only
    const HullView* hull;                    // convex cores only
  };
  static SideStart side_start(const ShapeCore<T>& c) {
    return {{c.size.x(), c.size.y(), c.size.z()}, &c.triangle, c.hull};
  }

  static void load_side(Side& s, const SideStart& c, int l) {
    s.s0[l] = c.size[0];
    s.s1[l] = c.size[1];
    s.s2[l] = c.size[2];
    if (s.type == ShapeType::triangle)
      for (int v = 0; v < 3; ++v)
        for (int i = 0; i < 3; ++i) s.tri[3 * v + i][l] = (*c.triangle)[v][i];
    if (s.type == ShapeType::convex) load_hull(s, c.hull, l);
  }
  /// A convex side's hull in lane l: the view, a fresh hill-climbing hint, the rows of a small hull.
  static void load_hull(Side& s, const HullView* hull, int l) {
    // The same small hull as the lane's previous pair (consecutive samples of one pair, a batch's repeated
    // shapes): its rows are still the lane's (rows only grow, and growing pads every lane with its last vertex).
    const bool same = s.hull[l] == hull && s.lane_vertices[l] == hull->vertex_count && (s.small >> l & 1u);
    s.hull[l] = hull;
    s.hint[l] = SupportHint{};
    if (same) return;
    const std::uint32_t bit = 1u << l;
    // A run of hulls of one vertex count (a batch of convex8 pairs): the table has exactly its rows, so no lane
    // is padded and the copy is all (load_small_hull()'s general case cost ~25 more instructions per hull).
    if (int(hull->vertex_count) == s.rows) [[likely]] {
      s.small |= bit;
      copy_rows(reinterpret_cast<T*>(s.table) + l, hull->vertices, s.rows);
      s.lane_vertices[l] = hull->vertex_count;
      return;
    }
    const bool small = hull->vertex_count < kHillClimbMinVertices;
    s.small = small ? s.small | bit : s.small & ~bit;
    if (small) load_small_hull(s, l, *hull);
  }

  template <class V> static void set_lane(V3& v, int l, const V& p) {
    v.x[l] = p.x();
    v.y[l] = p.y();
    v.z[l] = p.z();
  }
  static Vec3<T> get_lane(const V3& v, int l) { return Vec3<T>(v.x[l], v.y[l], v.z[l]); }

  /// Everything a lane reads of its pair's setup. PairSetup's refill() and the batch-array GJK's lean setup
  /// (wide_gjk_pairs.inl, no PairSetup per pair) both start lanes through start_lane().
  struct LaneStart {
    T R[9], t[3];  // B's pose in A's frame, row-major
    SideStart A, B;
    Vec3<T> initial_direction;
    int max_iterations;
    bool momentum, normalize, boolean_only;
    T tolerance, relative, touch, core_margin;
  };

  /// Starts pair `p` in lane l: the reference's initialisation up to the first support point, which start()
  /// computes for all freshly refilled lanes at once.
  static void start_lane(Lanes& L, int l, const LaneStart& s, std::int64_t p) {
    start_pose(L, l, s.R, s.t, s.A, s.B, p);
    start_search(L, l, s.initial_direction, s, s.momentum, s.normalize);
  }

  /// start_lane() in two halves, also called by the smoothing samples' refill (wide_gjk_samples.inl), which has no
  /// LaneStart to build: the pair, B's pose in A's frame and both sides; then the search from `init` (the x axis
  /// when it is zero) with the pair's limits, `g` a LaneStart or a GjkLimits<T> (the same field names).
  AI static void start_pose(Lanes& L, int l, const T* R, const T* t, const SideStart& A, const SideStart& B,
                            std::int64_t p) {
    L.pair[l] = p;
    for (int e = 0; e < 9; ++e) L.R[e][l] = R[e];
    for (int i = 0; i < 3; ++i) L.t[i][l] = t[i];
    load_side(L.A, A, l);
    load_side(L.B, B, l);
  }
  template <class Limits>
  AI static void start_search(Lanes& L, int l, Vec3<T> init, const Limits& g, bool momentum, bool normalize) {
    if (!(kernels::norm2(init) > T(0))) init = Vec3<T>::UnitX();
    reset_search(L, l, init);
    L.max_iterations[l] = g.max_iterations;
    L.momentum[l] = momentum ? -1 : 0;
    L.normalize[l] = normalize ? -1 : 0;
    L.boolean_only[l] = g.boolean_only ? -1 : 0;
    L.tolerance[l] = g.tolerance;
    L.relative[l] = g.relative;
    L.touch[l] = g.touch;
    L.core_margin[l] = g.core_margin;
  }

  /// The search state a lane starts every pair with, whatever the pair: the one-vertex simplex whose support
  /// point start() computes, d_prev = the (non-zero) initial direction `init`, no lower bound, no iteration.
  /// start_lane() and the batch-array GJK's refill (wide_gjk_pairs.inl, which sets the pair's values itself) both
  /// call it, so a field added to the search state is reset in one place.
  AI static void reset_search(Lanes& L, int l, const Vec3<T>& init) {
    L.fresh |= 1u << l;
    L.lambda[0][l] = T(1);
    L.count[l] = 1;
    L.slot[0][l] = 0;
    set_lane(L.d_prev, l, init);
    set_lane(L.direction, l, Vec3<T>::Zero());
    L.lower[l] = -std::numeric_limits<T>::infinity();
    L.k[l] = 0;
    L.stale[l] = 0;
    // Newton directions: every lane of a newton_pair_type() run may take them (boolean lanes are left out where
    // the steps are chosen, by L.boolean_only, which the batch-array refill sets per run).
    // The run's types are set before its first refill: their type tests once per run, not per refill (~10
    // instructions).
    if (L.newton_pair < 0) [[unlikely]] L.newton_pair = newton_pair_type(L.A.type, L.B.type) ? 1 : 0;
    L.newton[l] = -Int(L.newton_pair);
    L.newton_next[l] = 0;
    L.newton_steps[l] = 0;
  }

  /// reset_search() for the lanes of `bits` at once, `init` their (non-zero) initial directions: the same values,
  /// one masked blend per field (the batch-array boolean refill, WideGjkPairs' load_lanes()); the same values as
  /// reset_search() for every field but the Newton ones. Its only callers are boolean loops (loop()'s `batch`),
  /// which never read the Newton fields (no Newton step; finish()'s newton_steps stays the zero a Lanes starts
  /// with): they are left as they are (three blends and a test per refill). (reset_search() keeps them: skipping them there by a run flag cost the witness rows the
  /// flag's test, +4-5 instructions per pair, callgrind AVX2.)
  AI static void reset_search_lanes(Lanes& L, std::uint32_t bits, const V3& init) {
    const mask m = lanes_of(bits), none = splat_mask(0);
    const real zero = splat(T(0));
    L.fresh |= bits;
    L.lambda[0] = blend(m, splat(T(1)), L.lambda[0]);
    L.count = blend(m, splat_mask(1), L.count);
    L.slot[0] = blend(m, none, L.slot[0]);
    L.d_prev = pick(m, init, L.d_prev);
    L.direction = pick(m, V3{zero, zero, zero}, L.direction);
    L.lower = blend(m, splat(-std::numeric_limits<T>::infinity()), L.lower);
    L.k = blend(m, none, L.k);
    L.stale = blend(m, none, L.stale);
  }

  static void refill(Lanes& L, int l, const PairSetup<T>& s, std::int64_t p, Solver solver) {
    LaneStart q;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) q.R[3 * i + j] = s.X.R(i, j);
      q.t[i] = s.X.t[i];
    }
    q.A = side_start(s.A);
    q.B = side_start(s.B);
    q.initial_direction = s.initial_direction;
    q.max_iterations = s.params.max_iterations;
    q.momentum = solver != Solver::gjk;
    q.normalize = s.params.normalize_momentum;
    q.boolean_only = s.params.boolean_only;
    q.tolerance = s.params.tolerance;
    q.relative = s.params.relative_tolerance;
    q.touch = s.params.touch_tolerance;
    q.core_margin = s.params.core_margin;
    start_lane(L, l, q, p);
  }

  /// Writes lane l's result as the reference's GjkResult.
  static void finish(const Lanes& L, int l, GjkStatus status, GjkResult<T>& r, bool points) {
    r.status = status;
    r.iterations = int(L.k[l]);
    r.newton_steps = int(L.newton_steps[l]);
    r.simplex.count = int(L.count[l]);
    for (int m = 0; m < 4; ++m) {
      r.simplex.v[m].w = get_lane(L.w[m], l);
      const int q = int(L.slot[m][l]) & 3;  // slots past count are stale but in range
      r.simplex.v[m].a = points ? get_lane(L.a[q], l) : Vec3<T>::Constant(quiet_nan<T>());
      r.simplex.v[m].b = points ? get_lane(L.b[q], l) : Vec3<T>::Constant(quiet_nan<T>());
      r.simplex.lambda[m] = L.lambda[m][l];
    }
    r.x = status == GjkStatus::overlap ? Vec3<T>::Zero() : get_lane(L.x, l);
    r.direction = get_lane(L.direction, l);
    r.lower_bound = L.lower[l];
  }

  /// GjkResult::witness_a() / witness_b() of lane l without building the GjkResult: the sum of lambda[m] times
  /// the vertex's points, from zero, in m order (the cores' witness points; the lane must track its points). The
  /// completions straight from the lane (wide_gjk_pairs.inl's converged(), the smoothing samples' done()) share it.
  AI static void lane_witnesses(const Lanes& L, int l, Vec3<T>& pa, Vec3<T>& pb) {
    pa = Vec3<T>::Zero(), pb = Vec3<T>::Zero();
    const int count = int(L.count[l]);
    for (int m = 0; m < count; ++m) {
      const int q = int(L.slot[m][l]) & 3;
      const T lambda = L.lambda[m][l];
      pa += lambda * get_lane(L.a[q], l);
      pb += lambda * get_lane(L.b[q], l);
    }
  }

  /// Support point of D = A - B in direction dir, all lanes (kernels/minkowski.hpp's MinkowskiDifference::support).
  AI static void minkowski(Lanes& L, const V3& dir, std::uint32_t live, V3& w, V3& a, V3& b) {
    minkowski(L.A, L.B, L.R, L.t, dir, live, w, a, b);
  }
  /// The same for sides and a pose held elsewhere (the batch-array set-up's first support points, computed W pairs
  /// per register before their lanes are refilled: wide_gjk_pairs.inl).
  AI static void minkowski(Side& A, Side& B, const real (&R)[9], const real (&t)[3], const V3& dir, std::uint32_t live,
                           V3& w, V3& a, V3& b) {
    a = support(A, dir, live);
    const V3 m = neg(dir);
    const V3 d_in_b = {(R[0] * m.x + R[3] * m.y) + R[6] * m.z, (R[1] * m.x + R[4] * m.y) + R[7] * m.z,
                       (R[2] * m.x + R[5] * m.y) + R[8] * m.z};
    const V3 sb = support(B, d_in_b, live);
    b = {((R[0] * sb.x + R[1] * sb.y) + R[2] * sb.z) + t[0], ((R[3] * sb.x + R[4] * sb.y) + R[5] * sb.z) + t[1],
         ((R[6] * sb.x + R[7] * sb.y) + R[8] * sb.z) + t[2]};
    w = sub(a, b);
  }

  /// The reference's face_direction() given xn = norm(x) (the loop's), with its operations' results: the largest
  /// of the three vertex norms is the square root of the largest squared norm (a correctly rounded square root is
  /// monotone, so max and sqrt commute bit for bit, NaN included), one square root instead of three. `turned`:
  /// the lanes whose direction is the normal rather than x.
  /// Why: square roots and divisions are the witness loop's bottleneck on AVX-512 double (one 8-lane vsqrtpd or
  /// vdivpd issues every ~16 cycles on this Xeon, the same per lane as 4-lane AVX2), not its instruction count.
  static V3 face_direction(const Lanes& L, const V3& x, const real& xn, mask& turned) {
    const V3 n = cross(sub(L.w[1], L.w[0]), sub(L.w[2], L.w[0]));
    const real w = wsqrt<T>(wmax(wmax(norm2(L.w[0]), norm2(L.w[1])), norm2(L.w[2])));
    const real nn = norm(n);
    const mask keep = ~(nn > xn * w);
    turned = ~keep;
    const V3 signed_n = pick(dot(n, x) < splat(T(0)), neg(n), n);
    return pick(keep, x, scale(xn / nn, signed_n));
  }

  /// Newton's direction after the support point w of D in direction -d (n = d / |d|, lb = <w, n> > 0, and
  /// r = w - lb n its tangential residual), and step2 = |delta|^2.
  /// The support point w(n) = s_A(-n) - s_B(n) minimises <w, n> over D; n is optimal when w(n) is parallel to n,
  /// i.e. when the tangential residual P w = w - lb n (P = I - n n^T) vanishes. w(n) moves with n by -H delta,
  /// H = H_A(-n) + R H_B(R^T n) R^T the support functions' Hessian (null on n), and the residual along the turned
  /// direction n + delta is, to first order, P w - H delta - lb delta: Newton's step on the sphere of directions
  /// solves (P H P + lb I) delta = P w. P H P = H since H n = 0, so the 3x3 system is H + lb I, positive definite
  /// for lb > 0 (H is PSD) and mapping the tangent plane to itself (delta stays orthogonal to n up to rounding).
  /// With H = 0 the step is n + P w / lb = w / lb: GJK's own fixed point n <- w / |w|. |delta| <= |P w| / lb.
  /// step2 is NaN or infinite where a Hessian overflowed (rho^3 underflow): the caller's comparisons refuse the step.
  /// Why: GJK is Frank-Wolfe on the minimum-norm-point problem (the seed talk "Collision Detection for Rigid-Body
  /// Physics Simulation"; Montaut et al. 2022), a first-order method, linear on curved sets; this is a
  /// second-order step on the dual variable n, with the support functions' Hessians as curvature.
  /// Out of line: taken in a few iterations of some pairs; inlined, it grew drive() enough for GCC to outline
  /// support() (measured: +3% instructions on boolean ellipsoid pairs, which never take Newton steps).
  __attribute__((noinline)) static V3 newton_direction(const Lanes& L, const V3& n, const V3& sa, const V3& sb,
                                                       const V3& r, real lb, real& step2) {
    const V3 delta = solve(pair_hessian(L, n, sa, sb), lb, r);
    step2 = norm2(delta);
    return add(n, delta);
  }
  /// H = H_A(-n) + R H_B(R^T n) R^T, the curved sides' support Hessians at the unit direction n (A's frame), from
  /// the support points sa = s_A(-n), sb = s_B(n) (A's frame). An ellipsoid's and a B rim's are formed in A's
  /// frame directly (ellipsoid_hessian(), rim_hessian()); A's rim is support_hessian()'s (no rotation).
  AI static Sym pair_hessian(const Lanes& L, const V3& n, const V3& sa, const V3& sb) {
    Sym h{};
    const bool ca = curved(L.A.type), cb = curved(L.B.type);
    if (ca) {
      if (L.A.type == ShapeType::ellipsoid) {
        const real zero = splat(T(0));
        const Sym M{L.A.s0 * L.A.s0, L.A.s1 * L.A.s1, L.A.s2 * L.A.s2, zero, zero, zero};
        h = ellipsoid_hessian(M, sa, neg(n));
      } else {
        h = support_hessian(L.A, neg(n));
      }
    }
    if (cb) {
      const real* R = L.R;
      const Sym hb = L.B.type == ShapeType::ellipsoid
                         ? ellipsoid_hessian(ellipsoid_metric(L.B, R), sub(sb, V3{L.t[0], L.t[1], L.t[2]}), n)
                         : rim_hessian(L.B, R, n);
      if (ca) h = {h.xx + hb.xx, h.yy + hb.yy, h.zz + hb.zz, h.xy + hb.xy, h.xz + hb.xz, h.yz + hb.yz};
      else h = hb;
    }
    return h;
  }
  /// (H + lb I)^-1 r: cofactors of the symmetric M = H + lb I, then adj(M) r / det(M).
  AI static V3 solve(const Sym& h, real lb, const V3& r) {
    const real a = h.xx + lb, b = h.yy + lb, c = h.zz + lb, p = h.xy, q = h.xz, t = h.yz;
    const real c00 = b * c - t * t, c01 = q * t - p * c, c02 = p * t - b * q;
    const real c11 = a * c - q * q, c12 = p * q - a * t, c22 = a * b - p * p;
    const real det = (a * c00 + p * c01) + q * c02;
    const real inv = splat(T(1)) / det;  // one division (face()'s weights say why)
    return {((c00 * r.x + c01 * r.y) + c02 * r.z) * inv, ((c01 * r.x + c11 * r.y) + c12 * r.z) * inv,
            ((c02 * r.x + c12 * r.y) + c22 * r.z) * inv};
  }

  /// Newton's direction for a polytope against a curved core (flat_newton_side()), after the support point
  /// (sa, sb) in direction -n. At the optimum the polytope's witness lies inside a feature F (vertex, edge or face)
  /// whose vertices the simplex holds (their polytope points: the flat side's slots), while its support jumps
  /// between F's vertices as n turns: the residual of the raw support point does not vanish there, so the
  /// unknowns are n and the weights on F, y(n, t) = (p0 + E t) - s_B(n) (or s_A(-n) - (p0 + E t)), and the
  /// equations are P y = 0 (y parallel to n) and n orthogonal to F's edges E. Linearised at n (the curved
  /// side moves by -H delta, H its support Hessian, lb = <y, n>):
  ///   vertex: (H + lb I) delta = P y, as newton_direction();
  ///   edge e: delta = alpha v + beta u (v = P e / |P e|, u = n x e / |n x e|): alpha turns n orthogonal to e,
  ///     beta = (<u, y> - alpha u^T H v) / (u^T H u + lb), the u component of the first equation (E t has none);
  ///   face: n is the face's normal (the two constraints fix it).
  /// The curvature of the curved side turns n across F; the simplex (GJK's own projection) settles the point
  /// along F. step2 = |delta|^2; NaN where F is degenerate (refused by the caller's comparisons). Lanes outside
  /// `use` (those that cannot take the step) get an unspecified direction.
  __attribute__((noinline)) static V3 feature_direction(const Lanes& L, const V3& n, const V3& sa, const V3& sb,
                                                        mask use, real& step2) {
    const real zero = splat(T(0));
    const bool fa = flat_newton_side(L.A.type, L.B.type) == 1;
    V3 p[3];
    for (int m = 0; m < 3; ++m) {
      const V3* v = fa ? L.a : L.b;
      V3 q = v[0];
      for (int o = 1; o < 4; ++o) q = pick(L.slot[m] == splat_mask(o), v[o], q);
      p[m] = q;
    }
    // F from the simplex's distinct polytope points (exact copies of vertices: compared bitwise).
    const mask has1 = (L.count > splat_mask(1)) & ~equal(p[1], p[0]);
    const mask has2 = (L.count > splat_mask(2)) & ~equal(p[2], p[0]) & ~equal(p[2], p[1]);
    const V3 e1 = sub(p[1], p[0]), e2 = sub(p[2], p[0]);
    const V3 m = cross(e1, e2);
    const real mm = norm2(m);
    const mask is_face = has1 & has2 & (mm > T(1e-12) * (norm2(e1) * norm2(e2)));
    const mask is_edge = ~is_face & (has1 | has2);
    // Only the branches the lanes in `use` need (the others' results are not read): a face needs no curvature.
    V3 delta = {zero, zero, zero};
    if (any(use & ~is_face)) {
      const V3 y = fa ? sub(p[0], sb) : sub(sa, p[0]);
      const real lb = dot(y, n);
      const Sym h = pair_hessian(L, n, sa, sb);
      if (any(use & ~is_face & ~is_edge)) delta = solve(h, lb, sub(y, scale(lb, n)));  // vertex
      if (any(use & is_edge)) {
        const V3 e = pick(has1, e1, e2);
        const V3 c = cross(n, e);
        const real cn = norm(c);  // |P e|
        const V3 u = divide(c, cn);
        const V3 v = divide(sub(e, scale(dot(e, n), n)), cn);
        const real alpha = -dot(n, e) / cn;
        const V3 hu = {(h.xx * u.x + h.xy * u.y) + h.xz * u.z, (h.xy * u.x + h.yy * u.y) + h.yz * u.z,
                       (h.xz * u.x + h.yz * u.y) + h.zz * u.z};
        const real beta = (dot(u, y) - alpha * dot(v, hu)) / (dot(u, hu) + lb);
        delta = pick(is_edge, add(scale(alpha, v), scale(beta, u)), delta);
      }
    }
    if (any(use & is_face)) {
      const real s = wsqrt<T>(mm);
      const V3 f = divide(m, blend(dot(m, n) < zero, -s, s));
      delta = pick(is_face, sub(f, n), delta);
    }
    step2 = norm2(delta);
    return add(n, delta);
  }

  /// Runs GJK on setups[0 .. n): every pair must have the same (A type, B type) and need GJK (setup.done false).
  /// `points`: keep the points of A and B behind each simplex vertex (witness points, EPA); without it the
  /// simplex carries only w = a - b and its a, b come back NaN.
  static void run(const PairSetup<T>* setups, std::size_t n, GjkResult<T>* out, Solver solver, bool points) {
    if (n == 0) return;
    Lanes L;
    L.A.type = setups[0].A.type;
    L.B.type = setups[0].B.type;
    Rows rows;
    rows.attach(L.A, L.B);
    SetupSource source{setups, n, out, solver, points};
    drive(L, source, solver, points);
  }

  /// Feeds the lanes from an array of setups; each lane's GjkResult goes to out[its index].
  struct SetupSource {
    const PairSetup<T>* setups;
    std::size_t n;
    GjkResult<T>* out;
    Solver solver;
    bool points;
    std::size_t next = 0;
    bool load(Lanes& L, int l) {
      if (next >= n) return false;
      refill(L, l, setups[next], std::int64_t(next), solver);
      ++next;
      return true;
    }
    void done(const Lanes& L, int l, GjkStatus status) { finish(L, l, status, out[L.pair[l]], points); }
  };

  /// The lanes' loop. `source.load(L, l)` starts the next pair in lane l (false when none is left);
  /// `source.done(L, l, status)` takes lane l's finished pair. L's shape types must be set.
  template <class Source> static void drive(Lanes& L, Source& source, Solver solver, bool points) {
    loop<false>(L, source, solver, points);
  }
  /// drive() for a run whose lanes are all boolean (L.boolean_only in every lane, a boolean batch query): the
  /// same operations on every value the query reads, without what only the other levels use (points, Newton
  /// directions, the simplex weights), known at compile time instead of tested per iteration.
  template <class Source> static void drive_boolean(Lanes& L, Source& source, Solver solver) {
    loop<true>(L, source, solver, false);
  }
  /// drive_boolean() that also keeps, for every simplex vertex, the direction d whose support point -d it is
  /// (D.support(-d)): in L.a[L.slot[m]] for vertex m (L.b unused), so that the vertices can be computed again in
  /// another precision (the float pass of a certified boolean double query, wide_gjk_pairs.inl). The same
  /// operations as drive_boolean() on every other value: the same answers, iterations and directions.
  template <class Source> static void drive_boolean_directions(Lanes& L, Source& source, Solver solver) {
    loop<true, true>(L, source, solver, false);
  }

  /// Sources that start several lanes at once: `std::uint32_t load_lanes(Lanes&, std::uint32_t want)` starts the
  /// next pairs in free lanes (those of `want`, in lane order, as load() lane by lane would; a RefillsTogether
  /// source may start none of them while other lanes run, and later lanes it left empty) and returns the lanes it
  /// started.
  template <class S, class = void> struct LoadsLanes : std::false_type {};
  template <class S>
  struct LoadsLanes<S, std::void_t<decltype(std::declval<S&>().load_lanes(std::declval<Lanes&>(), 0u))>>
      : std::true_type {};

  /// Sources that write each refilled lane's first support point into L.first_w (`static constexpr bool
  /// gives_first = true`, boolean runs only: no points of A and B), computed at their set-up W pairs per register
  /// with minkowski()'s operations on the values the lane gets (the same bits): start() then computes none, where
  /// it computed one W-wide support per pass for the ~1-2 lanes refilled since the last pass (WideGjkPairs).
  template <class S, class = void> struct GivesFirst : std::false_type {};
  /// Sources whose load_lanes() is worth batching in every run, not only boolean float ones on AVX-512
  /// (`static constexpr bool refills_together = true`: the smoothing samples, which load W samples with vector
  /// loads when all lanes end together, wide_gjk_samples.inl).
  template <class S, class = void> struct RefillsTogether : std::false_type {};
  template <class S>
  struct RefillsTogether<S, std::void_t<decltype(S::refills_together)>> : std::bool_constant<S::refills_together> {};
  template <class S> struct GivesFirst<S, std::void_t<decltype(S::gives_first)>> : std::bool_constant<S::gives_first> {};

  // noinline: its callers stay small and the loop keeps its own register allocation whatever they are. Once
  // project() lost its face rounds, GCC inlined the boolean float loop into run_plain() and spilled more in it
  // (overlap box-cylinder boolean float 782 -> 799 loop instructions per pair, callgrind AVX2).
  template <bool Boolean, bool Dirs = false, class Source>
  __attribute__((noinline)) static void loop(Lanes& L, Source& source, Solver solver, bool points_) {
    // Boolean runs of a source with load_lanes(): the lanes that end in one iteration are answered first, then
    // refilled together (done() reads and load() writes only its own lane, so the answers are the same).
    // Only where expand loads make that a row of single instructions (has_expand_load, AVX-512), or for sources
    // that ask for it in every run (RefillsTogether: the smoothing samples, which may also leave ended lanes empty
    // until their whole register can be loaded at once, and start them later).
    constexpr bool batch = LoadsLanes<Source>::value && (RefillsTogether<Source>::value ||
                                                          (Boolean && has_expand_load && std::is_same_v<T, float>));
    // Lanes holding a pair, kept as bits beside L.pair (rebuilding them from L.pair and the live mask from them
    // lane by lane cost ~55 instructions per demo pair, AVX2).
    std::uint32_t active = 0;
    if constexpr (batch) {
      active = source.load_lanes(L, W == 32 ? ~0u : (1u << W) - 1);
      for (int l = 0; l < W; ++l)
        if (!(active >> l & 1u)) L.pair[l] = -1;
    } else {
      for (int l = 0; l < W; ++l) {
        if (source.load(L, l)) active |= 1u << l;
        else L.pair[l] = -1;
      }
    }
    const real zero = splat(T(0)), one = splat(T(1));
    const bool points = !Boolean && points_;
    // Else no lane ever has L.newton; boolean lanes never take Newton steps (newton_lanes below).
    const bool newton_run = !Boolean && newton_pair_type(L.A.type, L.B.type);
    const bool flat_run = !Boolean && flat_newton_side(L.A.type, L.B.type) != 0;  // feature_direction()
    const bool nesterov = solver == Solver::nesterov;  // last_s's only reader (start())
    // Finishes lane l with `status` and refills it (or empties it).
    const auto close = [&](int l, GjkStatus status) {
      source.done(L, l, status);
      if constexpr (!batch)
        if (!source.load(L, l)) L.pair[l] = -1, active &= ~(1u << l);
    };
    // batch: refills the lanes of `ended` (answered by close()).
    const auto refill_ended = [&](std::uint32_t ended) {
      if constexpr (batch) {
        if (ended == 0) return;
        // A source may also start lanes it left empty before (the samples wait for a register's last lane).
        const std::uint32_t started = source.load_lanes(L, ended);
        for (std::uint32_t e = ended & ~started; e != 0; e &= e - 1) L.pair[__builtin_ctz(e)] = -1;
        active = (active & ~ended) | started;
      }
    };

    while (active != 0) {
      start(L, !Boolean, Dirs, nesterov, Boolean && GivesFirst<Source>::value);
      // Budget spent (the reference's loop ends): max_iterations, or overlap when x reached the origin.
      const mask at_budget = L.k >= L.max_iterations;
      if (const std::uint32_t bits = lane_bits(at_budget) & active) {
        const mask touching = norm(L.x) <= L.touch;
        for (std::uint32_t left = bits; left != 0; left &= left - 1) {
          const int l = __builtin_ctz(left);
          close(l, touching[l] ? GjkStatus::overlap : GjkStatus::max_iterations);
        }
        refill_ended(bits);
        continue;  // refilled lanes start with k = 0
      }
      mask live = lanes_of(active);
      L.k = blend(live, L.k + 1, L.k);  // the reference's r.iterations = k + 1

      const V3 x = L.x;
      const real xx = norm2(x);
      const real xn = wsqrt<T>(xx);
      const mask ends_overlap = live & (xn <= L.touch);
      const mask boolean_only = Boolean ? splat_mask(-1) : L.boolean_only;
      const mask ends_collision = live & ~ends_overlap & boolean_only & (xn <= L.core_margin);
      live &= ~ends_overlap & ~ends_collision;

      V3 d = x;
      const real kk = to_real<T>(L.k);  // k + 1 of the reference (k already incremented)
      // Each momentum branch ends with "momentum cancelled out: the gradient" (plain GJK's d is x already), tested
      // on |d|^2 > 0, which is |d| > 0 bit for bit (sqrt(a) > 0 exactly when a > 0, NaN false in both): no root.
      if (solver == Solver::nesterov && any(live & L.momentum)) {  // else every lane steps along x
        const real delta = kk / (kk + T(2));  // T(k + 1) / T(k + 3)
        const V3 y = add(scale(delta, x), scale(one - delta, L.last_s));
        const real yn = norm(y), dn = norm(L.d_prev);
        const mask normalized = L.momentum & L.normalize & (yn > zero) & (dn > zero);
        const mask unnormalized = L.momentum & ~L.normalize;
        const V3 dn_dir = add(divide(scale(delta, L.d_prev), dn), divide(scale(one - delta, y), yn));
        const V3 du_dir = add(scale(delta, L.d_prev), scale(one - delta, y));
        d = pick(normalized, dn_dir, pick(unnormalized, du_dir, d));
        d = pick(norm2(d) > zero, d, x);
      } else if (solver == Solver::polyak && any(live & L.momentum)) {
        const real beta = one / (kk + T(1));  // T(1) / T(k + 2)
        d = pick(L.momentum, add(scale(one - beta, x), scale(beta, L.d_prev)), d);
        d = pick(norm2(d) > zero, d, x);
      }
      // Newton's direction, where the last iteration set one up, replaces plain GJK's and momentum's (and ends
      // momentum for the lane: Newton converges quadratically where momentum's gain is linear).
      mask newton_step = splat_mask(0);
      // The other pair types, and boolean runs (no lane takes Newton steps), skip Newton's bookkeeping (~1% of
      // their instructions; measured, boolean close double AVX2: capsule-ellipsoid 1081 -> 1071, ellipsoid-ellipsoid
      // 1461 -> 1457 instructions per pair).
      const bool newton_live = newton_run && any(live & L.newton & ~boolean_only);
      if (newton_live) {
        newton_step = live & L.newton_next;
        if (any(newton_step)) {
          d = pick(newton_step, L.newton_dir, d);
          L.momentum &= ~newton_step;
          L.newton_steps = blend(newton_step, L.newton_steps + 1, L.newton_steps);
        }
        L.newton_next = splat_mask(0);  // set again below, only for lanes that take a step
      }
      const mask plain = equal(d, x);
      const mask face = live & plain & (L.count == splat_mask(3));
      mask turned = splat_mask(0);
      if (any(face)) {
        d = pick(face, face_direction(L, x, xn, turned), d);
        turned &= face;
      }

      const std::uint32_t live_bits = lane_bits(live);
      V3 sw, sa, sb;
      minkowski(L, neg(d), live_bits, sw, sa, sb);
      // |d|: where d is x (plain steps not turned to a face normal) it is xn bit for bit; one square root less
      // in the iterations where every live lane steps along x.
      const real dnorm = any(live & (~plain | turned)) ? norm(d) : xn;
      const real lb = dot(sw, d) / dnorm;
      const mask progress = lb > L.lower + T(0.1) * (xn - L.lower);
      L.stale = blend(live, blend(progress, splat_mask(0), L.stale + 1), L.stale);
      L.lower = blend(live, wmax(L.lower, lb), L.lower);
      L.direction = pick(live, d, L.direction);
      const mask ends_separated = live & boolean_only & (lb > L.core_margin);
      live &= ~ends_separated;

      const real tol = wmax(L.tolerance, L.relative * xn);
      const mask ends_converged = live & plain & (xn - lb <= tol);
      live &= ~ends_converged;
      // Momentum's point is skipped when the gap is closed or when it would not move x (plain GJK certifies
      // next). Newton's point is kept: it is the best point of D the lane has (Newton's error is quadratic), and
      // the plain step that certifies needs x itself accurate, not only |x|; Newton's sequence ends on its own
      // (below, and on no decrease).
      const mask momentum_step = live & ~plain & ~newton_step;
      const mask gap_closed = momentum_step & (xn - L.lower <= tol);
      const mask no_move = momentum_step & ~gap_closed & (xx - dot(x, sw) <= tol * xn);
      L.momentum &= ~(gap_closed | no_move);
      live &= ~(gap_closed | no_move);

      mask ends_contains = splat_mask(0), ends_stall = splat_mask(0), ends_stall_overlap = splat_mask(0);
      if (any(live)) {
        // Project the origin on the simplex plus s, keep the support set. The projection reads the old vertices
        // L.w[0 .. count) and s, and names s by index 3 whatever the lane's count, so s is never blended into slot
        // `count` first (a pick per slot per iteration); the compaction below reads it as vertex 3.
        mask pslot[4];
        // feature_direction() reads the flat side's points of the simplex: tracked for its lanes without `points`.
        const bool track = Dirs || points || (flat_run && newton_live);
        if (track) {
          // The new vertex's a and b go to the lowest slot no current vertex uses (count <= 3 here: one is free).
          mask used[4];
          for (int q = 0; q < 4; ++q) {
            used[q] = splat_mask(0);
            for (int m = 0; m < 3; ++m) used[q] |= (L.count > splat_mask(m)) & (L.slot[m] == splat_mask(q));
          }
          const mask free = blend(~used[0], splat_mask(0),
                                   blend(~used[1], splat_mask(1), blend(~used[2], splat_mask(2), splat_mask(3))));
          for (int q = 0; q < 4; ++q) {
            const mask here = live & (free == splat_mask(q));
            L.a[q] = pick(here, Dirs ? d : sa, L.a[q]);
            if (!Dirs) L.b[q] = pick(here, sb, L.b[q]);
          }
          for (int m = 0; m < 3; ++m) pslot[m] = L.slot[m];
          pslot[3] = free;  // s's slot, at s's index
        }
        const Proj proj = project(L.w, sw, L.count, live);
        const real next_xx = norm2(proj.x);

        ends_contains = live & proj.contains;
        const mask no_decrease = live & ~ends_contains & ~(next_xx < xx);
        L.momentum &= ~(no_decrease & ~plain);
        if (newton_live) L.newton &= ~(no_decrease & ~plain);
        const mask stall = no_decrease & plain;
        ends_stall_overlap = stall & (xn <= T(2) * L.touch);
        ends_stall = stall & ~ends_stall_overlap;
        const mask moves = live & ~no_decrease;  // includes ends_contains: S = next, x = proj.x
        // |next x| only where read: momentum lanes that stepped (lagging) and Newton's bookkeeping. Plain GJK (the
        // witness and distance solver) skips its square root.
        const mask momentum_moved = moves & ~ends_contains & ~plain & L.momentum;
        real next_xn{};
        if (newton_live || any(momentum_moved)) next_xn = wsqrt<T>(next_xx);
        if (any(momentum_moved)) {
          const mask lagging = (xn - next_xn <= tol) | (L.stale >= splat_mask(kMaxStaleMomentumSteps));
          L.momentum &= ~(momentum_moved & lagging);
        }
        // Compaction in place, slot by slot: slot m takes vertex q = index[m] >= m (the indices of a support set
        // are increasing, so a kept vertex never moves up) and reads slots m .. 3 only, none written yet. Lanes
        // that do not move select nothing (from_q false) and keep their vertex m (m < 3; slot 3 gets s, stale:
        // their count is at most 3): a mask and instead of a pick of the whole vertex, and no copy of L.w.
        for (int m = 0; m < 4; ++m) {
          mask from_q[4];
          for (int q = m + 1; q < 4; ++q) from_q[q] = moves & (proj.index[m] == splat_mask(q));
          V3 r = m < 3 ? L.w[m] : sw;
          for (int q = m + 1; q < 4; ++q) r = pick(from_q[q], q < 3 ? L.w[q] : sw, r);
          L.w[m] = r;
          if (track) {
            mask q = pslot[m];
            for (int o = m + 1; o < 4; ++o) q = blend(from_q[o], pslot[o], q);
            L.slot[m] = q;
          }
          if (!Boolean) L.lambda[m] = blend(moves, proj.lambda[m], L.lambda[m]);  // a boolean output has no weights
        }
        L.count = blend(moves, proj.count, L.count);
        L.x = pick(moves, proj.x, L.x);
        const mask steps = moves & ~ends_contains;
        L.d_prev = pick(steps, d, L.d_prev);
        if (nesterov) L.last_s = pick(steps, sw, L.last_s);
        // Newton's direction for the next iteration (newton_direction()), where this support point gives one:
        //  - lb > 0 (separated cores: H + lb I is positive definite); not on polytope pairs (flat_newton_side());
        //  - the step turns the direction by at most kNewtonSwitch (|delta| estimates the angle to the optimal
        //    direction; beyond it the linearisation is not trusted and GJK's own steps bring the lane closer);
        //  - a lane that just took a Newton step keeps them only if this step is at most half the last one
        //    (Newton's steps shrink quadratically; one that does not left Newton's region: a support jumping over
        //    a flat face or a rim, where the Hessian says nothing, or the end of the arithmetic's resolution);
        //  - the certified gap after this step is still above kNewtonPlainGap x tol: below it, a plain step at x
        //    certifies the witness (the duality gap along x itself, which the termination test needs).
        const mask newton_lanes = steps & L.newton & ~boolean_only;
        // The direction is computed only when some lane reads it: a lane that may choose it (the gap still open
        // and, curved pairs, lb > 0: `want` below; polytope pairs whatever lb (flat_newton_side()), but not while
        // skipping after a step that did not halve the gap) or
        // one whose last step was Newton's (the shrink test that ends the sequence, curved pairs). The others'
        // results were never read: skipping them changes no bit. About half of the calls of the curved pairs
        // (lb <= 0 in the first iterations, the gap closed in the last; scalar reference, close ellipsoid pairs:
        // 3.6 of 7.3 calls per pair, cylinder-ellipsoid 4.2 of 11.0) read nothing in any lane.
        // Only in Newton runs: computed unconditionally, the masks cost the other pair types ~0.5% (box-cylinder
        // witness double 6134 -> 6168 instructions per pair, AVX2).
        real newton_gap{};
        mask gap_open{}, read = splat_mask(0);
        if (newton_live) {
          newton_gap = next_xn - L.lower;
          gap_open = newton_gap > T(kNewtonPlainGap) * tol;
          // Polytope pairs take feature steps whatever the sign of lb (flat_newton_side() says why).
          read = flat_run ? newton_lanes & gap_open & ~(newton_step & ~(newton_gap <= T(0.5) * L.newton_gap))
                          : newton_lanes & (newton_step | ((lb > zero) & gap_open));
          if (flat_run && !any(read) && any(newton_lanes))
            L.newton_gap = blend(newton_lanes, newton_gap, L.newton_gap);  // the bookkeeping of the block below
        }
        if (newton_live && any(read)) {
          const V3 n = scale(one / dnorm, d);  // one division (face()'s weights say why)
          real step2;
          V3 nd;
          real shrunk;  // the step2 a lane that just took a Newton step must reach to keep them
          if (flat_run) {
            nd = feature_direction(L, n, sa, sb, newton_lanes, step2);
            // Tilted by eps towards x's offset from the line along nd: on a polytope's face or edge (the tie the
            // Newton direction lands on) the support then takes the vertex plain GJK would (the one opposite x's
            // offset), which the simplex needs to settle x along F, while the curved side's support moves by
            // only ~ R eps^2 / 2 <= 0.1 tol along n (R ~ |w|, the scale of the shapes).
            const V3 t = sub(L.x, scale(dot(L.x, nd) / norm2(nd), nd));
            const real tn = norm(t);
            const real eps = wsqrt<T>((T(0.2) * tol) / norm(sw));
            nd = pick(tn > zero, add(nd, scale(eps / tn, t)), nd);
            shrunk = T(0.25) * L.newton_step2 + T(4) * (eps * eps);  // the tilt is no step of Newton's
          } else {
            const V3 r = sub(sw, scale(lb, n));
            nd = newton_direction(L, n, sa, sb, r, lb, step2);
            shrunk = T(0.25) * L.newton_step2;
          }
          const mask valid = flat_run ? splat_mask(-1) : lb > zero;
          const mask failed = newton_lanes & newton_step & ~(valid & (step2 <= shrunk));
          mask skip = splat_mask(0);  // lanes that take a plain (or momentum) step before the next Newton one
          if (flat_run) {
            // A failed step ends Newton's sequence on the polytope pairs only for one iteration: there the
            // simplex's feature F is often not yet the optimum's (a triangle of a box face's four vertices that
            // does not hold the witness, an edge next to it), and the next feature gives a good step again
            // (measured, mean iterations: box-ellipsoid 13.0 -> 12.2, ellipsoid-convex8 14.7 -> 13.3). Near the
            // optimum (step2 ~ eps^2, the tilt) only the certified gap tells progress: it must halve per Newton step.
            skip = failed | (newton_lanes & newton_step & ~(newton_gap <= T(0.5) * L.newton_gap));
            L.newton_gap = blend(newton_lanes, newton_gap, L.newton_gap);
          } else {
            L.newton &= ~failed;
          }
          const mask want = newton_lanes & L.newton & ~skip & valid & (step2 <= T(kNewtonSwitch * kNewtonSwitch)) &
                             gap_open;
          L.newton_dir = pick(want, nd, L.newton_dir);
          L.newton_step2 = blend(want, step2, L.newton_step2);
          L.newton_next = want;
        }
      }

      const std::uint32_t b_overlap = lane_bits(ends_overlap | ends_contains | ends_stall_overlap);
      const std::uint32_t b_collision = lane_bits(ends_collision), b_separated = lane_bits(ends_separated);
      const std::uint32_t b_converged = lane_bits(ends_converged), b_stall = lane_bits(ends_stall);
      // Only the lanes that end, in lane order (a pass over all W lanes cost ~40 instructions per demo pair).
      for (std::uint32_t left = b_overlap | b_collision | b_separated | b_converged | b_stall; left != 0;
           left &= left - 1) {
        const int l = __builtin_ctz(left);
        const std::uint32_t bit = 1u << l;
        if (b_overlap & bit) close(l, GjkStatus::overlap);
        else if (b_collision & bit) close(l, GjkStatus::collision_proven);
        else if (b_separated & bit) close(l, GjkStatus::separated_proven);
        else if (b_converged & bit) close(l, GjkStatus::converged);
        else if (b_stall & bit) close(l, GjkStatus::stalled);
      }
      refill_ended(b_overlap | b_collision | b_separated | b_converged | b_stall);
    }
  }
};

#undef AI
