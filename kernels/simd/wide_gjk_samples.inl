// Perturbed copies of pairs ("samples": the smoothed0 derivatives' M copies of a pair with B's pose perturbed,
// engine/src/derivative_smoothed0.cpp) straight from per-sample arrays into per-sample answers in A's frame. The M
// samples of a pair share its shapes, so a lane refill reads the pair's cores once per pair (not per sample) and
// only the sample's relative pose and first direction per sample; no batch validation, type grouping, world pose
// or world output is done per sample. Each lane runs WideGjk's loop, so a sample's answer is bitwise the answer of
// the scalar setup + GJK + complete_pair() on the same relative pose, tolerance and first direction (tested in
// tests/kernels/wide_gjk_samples_test.cpp); a sample that needs more than GJK (overlap at the penetration level,
// a float stall redone in double, a double stall above the certified floor) goes back to the caller.
//
// No include guard: included once per instruction set by isa_body.inl, after wide_gjk.inl.

template <class T> struct WideGjkSamples {
  using G = WideGjk<T>;
  using Lanes = typename G::Lanes;
  using real = typename G::real;
  using mask = typename G::mask;
  using V3 = typename G::V3;
  static constexpr int W = G::W;
  static constexpr std::uint32_t kAllLanes = W == 32 ? ~0u : (1u << W) - 1;

  /// What every sample of one pair shares: the cores (their swept radii and centres), the bounding radii.
  struct Shared {
    ShapeCore<T> core_a, core_b;
    double bounding_a, bounding_b;
    Vec3<T> center_a, center_b;
  };

  /// Shape `shape`'s core by make_core()'s rules, read from the ShapeTable's per-shape arrays once per run of a
  /// pair's samples.
  static ShapeCore<T> core_of(const PairView& in, std::uint32_t shape) {
    ShapeView v;
    v.type = in.shape_type[shape];
    for (int i = 0; i < 3; ++i) v.size[i] = in.shape_size[i][shape];
    v.inflation = in.shape_inflation[shape];
    if (v.type == ShapeType::convex) v.hull = &in.shape_hull[shape];
    return make_core<T>(v);
  }

  /// The closest point to the origin of the segment or triangle p[0 .. count) (count 1-3): its support set (the
  /// input indices idx[0 .. returned count), ascending) and their weights. A full projection, every region tested,
  /// since a warm simplex has no newest vertex (GJK's project() assumes the newest one is kept). The interior of a
  /// triangle by its signed sub-areas along the normal (positive: the origin's projection is inside), else the
  /// best of its edges; a segment by the clamped parameter. Degenerate simplices (zero length or area) fall to
  /// their edges and vertices, so the answer is always a point of the simplex's hull, GJK's only invariant.
  static int project_warm(const Vec3<T>* p, int count, int* idx, T* lambda) {
    const auto segment = [&](int i, int j, int* si, T* sl) {
      const Vec3<T> e = p[j] - p[i];
      const T ee = e.dot(e);
      const T u = ee > T(0) ? -p[i].dot(e) / ee : T(0);
      if (!(u > T(0))) return si[0] = i, sl[0] = T(1), 1;
      if (!(u < T(1))) return si[0] = j, sl[0] = T(1), 1;
      si[0] = i, si[1] = j, sl[0] = T(1) - u, sl[1] = u;
      return 2;
    };
    const auto point = [&](const int* si, const T* sl, int n) {
      Vec3<T> x = Vec3<T>::Zero();
      for (int m = 0; m < n; ++m) x += sl[m] * p[si[m]];
      return x;
    };
    if (count == 1) return idx[0] = 0, lambda[0] = T(1), 1;
    if (count == 2) return segment(0, 1, idx, lambda);
    const Vec3<T> n = (p[1] - p[0]).cross(p[2] - p[0]);
    const T nn = n.dot(n);
    const T l0 = p[1].cross(p[2]).dot(n), l1 = p[2].cross(p[0]).dot(n), l2 = p[0].cross(p[1]).dot(n);
    if (nn > T(0) && l0 > T(0) && l1 > T(0) && l2 > T(0)) {
      idx[0] = 0, idx[1] = 1, idx[2] = 2;
      lambda[0] = l0 / nn, lambda[1] = l1 / nn, lambda[2] = l2 / nn;
      return 3;
    }
    int best = 0;
    T best_xx = std::numeric_limits<T>::infinity();
    const int edges[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    for (const auto& e : edges) {
      int si[2];
      T sl[2];
      const int c = segment(e[0], e[1], si, sl);
      const T xx = point(si, sl, c).squaredNorm();
      if (xx < best_xx) {
        best_xx = xx, best = c;
        for (int m = 0; m < c; ++m) idx[m] = si[m], lambda[m] = sl[m];
      }
    }
    return best;
  }

  /// Starts lane l (start_pose() and start_search() done) from the pair's warm simplex instead of start()'s
  /// support point: its vertex pairs under the sample's pose (B's vertex as minkowski() maps a support point of
  /// B), projected (project_warm()); the lane's first iteration then takes the support point at -x, whose duality
  /// gap certifies the answer when the simplex's feature is still the optimum's (most samples: the perturbation
  /// is small), else GJK goes on from there. Momentum is off for the lane (its first step is a plain one).
  /// Why: hull samples needed 1.75 iterations after the first support point from the predicted direction (each a
  /// support scan of both hulls and a projection), ~58x a witness query at M = 64 against a budget of 32x.
  static void warm_start(Lanes& L, int l, const WarmSimplex& ws, const HullView& ha, const HullView& hb,
                         const T* R, const T* t) {
    const int count = int(ws.count);
    Vec3<T> w[3], a[3], b[3];
    for (int m = 0; m < count; ++m) {
      a[m] = list_point<T>(ha, ws.a[m]);
      const Vec3<T> q = list_point<T>(hb, ws.b[m]);
      b[m] = Vec3<T>(((R[0] * q.x() + R[1] * q.y()) + R[2] * q.z()) + t[0],
                     ((R[3] * q.x() + R[4] * q.y()) + R[5] * q.z()) + t[1],
                     ((R[6] * q.x() + R[7] * q.y()) + R[8] * q.z()) + t[2]);
      w[m] = a[m] - b[m];
    }
    int idx[3];
    T lambda[3];
    const int c = project_warm(w, count, idx, lambda);
    Vec3<T> x = Vec3<T>::Zero();
    for (int m = 0; m < c; ++m) {
      const int q = idx[m];
      x += lambda[m] * w[q];
      G::set_lane(L.w[m], l, w[q]);
      G::set_lane(L.a[m], l, a[q]);
      G::set_lane(L.b[m], l, b[q]);
      L.slot[m][l] = m;
      L.lambda[m][l] = lambda[m];
    }
    L.count[l] = c;
    G::set_lane(L.x, l, x);
    G::set_lane(L.last_s, l, x);
    L.momentum[l] = 0;
    L.fresh &= ~(1u << l);
  }

  /// project_warm() in every lane at once, for simplices of one vertex count (a pair's warm simplex under W
  /// sample poses): every region computed, each lane's chosen by its own tests, in project_warm()'s operations
  /// and order (Eigen's dot products and squared norms of 3-vectors sum in index order, as G::dot()), so each lane
  /// gets the support set, weights and point of project_warm() on its own simplex. c: the support set's size,
  /// idx[m] / lambda[m]: its vertices and weights for m < c (lanes past c keep 0 / 1, unread).
  struct WarmLanes {
    mask c, idx[3];
    real lambda[3];
  };
  /// segment() of project_warm() between vertices i and j in every lane.
  static void segment_lanes(const V3* p, int i, int j, mask& c, mask* idx, real* lambda) {
    const real zero = G::splat(T(0)), one = G::splat(T(1));
    const V3 e = G::sub(p[j], p[i]);
    const real ee = G::dot(e, e);
    const real u = G::blend(ee > zero, -G::dot(p[i], e) / ee, zero);
    const mask at_i = ~(u > zero), at_j = ~at_i & ~(u < one), both = ~at_i & ~at_j;
    c = G::blend(both, G::splat_mask(2), G::splat_mask(1));
    idx[0] = G::blend(at_j, G::splat_mask(j), G::splat_mask(i));
    idx[1] = G::splat_mask(j);
    lambda[0] = G::blend(both, one - u, one);
    lambda[1] = u;
  }
  static V3 vertex_of(const V3* p, mask q) {
    return G::pick(q == G::splat_mask(2), p[2], G::pick(q == G::splat_mask(1), p[1], p[0]));
  }
  static WarmLanes project_warm_lanes(const V3* p, int count) {
    WarmLanes r;
    const real zero = G::splat(T(0)), one = G::splat(T(1));
    r.c = G::splat_mask(1);
    for (int m = 0; m < 3; ++m) r.idx[m] = G::splat_mask(m), r.lambda[m] = one;
    if (count == 1) return r;
    if (count == 2) {
      segment_lanes(p, 0, 1, r.c, r.idx, r.lambda);
      return r;
    }
    const V3 n = G::cross(G::sub(p[1], p[0]), G::sub(p[2], p[0]));
    const real nn = G::dot(n, n);
    const real l0 = G::dot(G::cross(p[1], p[2]), n), l1 = G::dot(G::cross(p[2], p[0]), n),
               l2 = G::dot(G::cross(p[0], p[1]), n);
    const mask inside = (nn > zero) & (l0 > zero) & (l1 > zero) & (l2 > zero);
    if (lane_bits(inside) == kAllLanes) {  // the usual case: the perturbation keeps the origin over the face
      r.c = G::splat_mask(3);
      r.lambda[0] = l0 / nn, r.lambda[1] = l1 / nn, r.lambda[2] = l2 / nn;
      return r;
    }
    // The best edge (first strict minimum of the squared norm, edges in project_warm()'s order).
    real best_xx = G::splat(std::numeric_limits<T>::infinity());
    // bc starts at 0: with no edge below +inf no vertex is kept, as in project_warm().
    mask bc = G::splat_mask(0), bi[2] = {G::splat_mask(0), G::splat_mask(0)};
    real bl[2] = {one, one};
    const int edges[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    for (const auto& e : edges) {
      mask c, idx[2];
      real lambda[2];
      segment_lanes(p, e[0], e[1], c, idx, lambda);
      V3 x = G::scale(lambda[0], vertex_of(p, idx[0]));
      x = {zero + x.x, zero + x.y, zero + x.z};  // project_warm()'s point() sums from zero
      x = G::pick(c == G::splat_mask(2), G::add(x, G::scale(lambda[1], p[e[1]])), x);
      const real xx = G::norm2(x);
      const mask better = xx < best_xx;
      best_xx = G::blend(better, xx, best_xx);
      bc = G::blend(better, c, bc);
      for (int m = 0; m < 2; ++m) bi[m] = G::blend(better, idx[m], bi[m]), bl[m] = G::blend(better, lambda[m], bl[m]);
    }
    r.c = G::blend(inside, G::splat_mask(3), bc);
    r.idx[0] = G::blend(inside, G::splat_mask(0), bi[0]);
    r.idx[1] = G::blend(inside, G::splat_mask(1), bi[1]);
    r.lambda[0] = G::blend(inside, l0 / nn, bl[0]);
    r.lambda[1] = G::blend(inside, l1 / nn, bl[1]);
    r.lambda[2] = G::blend(inside, l2 / nn, one);
    return r;
  }

  /// warm_start() of every lane from one warm simplex (the samples of one pair, each lane's pose in L.R, L.t):
  /// the same points, projection and lane state, W lanes a register. A's points are the same in every lane.
  static void warm_start_lanes(Lanes& L, const WarmSimplex& ws, const HullView& ha, const HullView& hb) {
    const int count = int(ws.count);
    const real zero = G::splat(T(0));
    V3 w[3], a[3], b[3];
    for (int m = 0; m < 3; ++m) w[m] = a[m] = b[m] = {zero, zero, zero};  // vertex_of() reads all three
    for (int m = 0; m < count; ++m) {
      const Vec3<T> pa = list_point<T>(ha, ws.a[m]), q = list_point<T>(hb, ws.b[m]);
      a[m] = {G::splat(pa.x()), G::splat(pa.y()), G::splat(pa.z())};
      const real qx = G::splat(q.x()), qy = G::splat(q.y()), qz = G::splat(q.z());
      b[m] = {((L.R[0] * qx + L.R[1] * qy) + L.R[2] * qz) + L.t[0], ((L.R[3] * qx + L.R[4] * qy) + L.R[5] * qz) + L.t[1],
              ((L.R[6] * qx + L.R[7] * qy) + L.R[8] * qz) + L.t[2]};
      w[m] = G::sub(a[m], b[m]);
    }
    const WarmLanes r = project_warm_lanes(w, count);
    V3 x{zero, zero, zero};
    // Every lane keeps the whole simplex (a support set of `count` vertices is 0 .. count - 1 in order): the
    // vertices go straight to their slots, without the per-lane selections below (most registers).
    if (lane_bits(r.c == G::splat_mask(count)) == kAllLanes) {
      for (int m = 0; m < count; ++m) {
        x = G::add(x, G::scale(r.lambda[m], w[m]));
        L.w[m] = w[m], L.a[m] = a[m], L.b[m] = b[m];
        L.slot[m] = G::splat_mask(m);
        L.lambda[m] = r.lambda[m];
      }
    } else {
      for (int m = 0; m < count; ++m) {
        const mask kept = r.c > G::splat_mask(m);
        const V3 wm = vertex_of(w, r.idx[m]);
        x = G::pick(kept, G::add(x, G::scale(r.lambda[m], wm)), x);
        L.w[m] = G::pick(kept, wm, L.w[m]);
        L.a[m] = G::pick(kept, vertex_of(a, r.idx[m]), L.a[m]);
        L.b[m] = G::pick(kept, vertex_of(b, r.idx[m]), L.b[m]);
        L.slot[m] = G::blend(kept, G::splat_mask(m), L.slot[m]);
        L.lambda[m] = G::blend(kept, r.lambda[m], L.lambda[m]);
      }
    }
    L.count = r.c;
    L.x = x;
    L.last_s = x;
    L.momentum = G::splat_mask(0);
    L.fresh = 0;
  }

  struct Source {
    const PairView& shapes;
    const SampleBatch& in;
    const QueryOptions& options;
    const SampleResults& out;
    std::uint32_t* fallback;
    std::size_t fallbacks = 0;
    std::size_t next = 0;  // the next sample to load
    std::uint32_t shape_a = ~0u, shape_b = ~0u;  // the shapes `shared` was made of
    Shared shared;
    bool normalize;
    bool witness_level;  // finish() keeps every value (below the witness level it writes NaNs)
    // A convex-convex run with warm simplices (in.warm read). A run-time flag: a second instantiation of the loop
    // for warm runs (a template parameter) cost more than the flag on every run (GCC's inlining in the unit):
    // ellipsoids M = 16 20510 -> 20721 instructions per pair, hulls 22499 -> 23067 (callgrind AVX2).
    bool hulls;
    std::uint32_t sample[W] = {};
    // Each lane's GjkCompletion in three values (the rest is the options'): the swept radii and the scale, from
    // which completion() computes the rest with gjk_limits()'s operations. Vectors, so that a register's refill
    // writes them at once.
    real radius_a{}, radius_b{}, scale{};

    Source(const PairView& shapes_, const SampleBatch& in_, const QueryOptions& options_, const SampleResults& out_,
           std::uint32_t* fallback_, ShapeType a, ShapeType b)
        : shapes(shapes_), in(in_), options(options_), out(out_), fallback(fallback_),
          normalize(!(a == ShapeType::ellipsoid && b == ShapeType::ellipsoid)),
          witness_level(options_.level >= QueryLevel::witness),
          hulls(a == ShapeType::convex && b == ShapeType::convex && in_.warm != nullptr) {}

    void share(std::uint32_t ia, std::uint32_t ib) {
      sides_ready = false;
      shape_a = ia;
      shape_b = ib;
      shared.core_a = core_of(shapes, ia);
      shared.core_b = core_of(shapes, ib);
      shared.bounding_a = shapes.bounding_radii[ia];
      shared.bounding_b = shapes.bounding_radii[ib];
      shared.center_a = shared.core_a.center();
      shared.center_b = shared.core_b.center();
    }

    /// setup_pair_into() and set_gjk_parameters() for the next sample (gjk_limits() from its own |t|, the warm
    /// direction when finite and non-zero, else the centres' difference), then WideGjk::start_lane()'s two halves
    /// straight into lane l: building a LaneStart and copying it in cost ~60 instructions per sample, a twentieth
    /// of a warm-started sample.
    // Inlined into the loop's refill (one call site per sample): the out-of-line calls saved and restored the
    // registers of both functions, ~25 instructions per sample.
    __attribute__((always_inline)) bool load(Lanes& L, int l) {
      if (next == in.samples) return false;
      const std::size_t s = next++;
      sides_ready = false;  // start_pose() loads lane l's sides alone
      if (in.shape_a[s] != shape_a || in.shape_b[s] != shape_b) share(in.shape_a[s], in.shape_b[s]);
      T R[9];
      for (int e = 0; e < 9; ++e) R[e] = T(in.R[e][s]);
      const double tx = in.t[0][s], ty = in.t[1][s], tz = in.t[2][s];
      const T t[3] = {T(tx), T(ty), T(tz)};
      G::start_pose(L, l, R, t, G::side_start(shared.core_a), G::side_start(shared.core_b), std::int64_t(s));
      const GjkLimits<T> g = gjk_limits<T>(shared.core_a.radius, shared.core_b.radius, shared.bounding_a, shared.bounding_b,
                                           std::sqrt((tx * tx + ty * ty) + tz * tz), options);
      Vec3<T> init(T(in.direction[0][s]), T(in.direction[1][s]), T(in.direction[2][s]));
      if (!(init.allFinite() && init.squaredNorm() > T(0))) {  // MinkowskiDifference::center(): A's centre minus B's
        const Vec3<T>& cb = shared.center_b;                   // mapped into A's frame
        const Vec3<T> b_center((R[0] * cb.x() + R[1] * cb.y()) + R[2] * cb.z() + t[0],
                               (R[3] * cb.x() + R[4] * cb.y()) + R[5] * cb.z() + t[1],
                               (R[6] * cb.x() + R[7] * cb.y()) + R[8] * cb.z() + t[2]);
        init = shared.center_a - b_center;
      }
      G::start_search(L, l, init, g, options.solver != Solver::gjk, normalize);
      if (hulls)
        if (const WarmSimplex* ws = in.warm[s]; ws != nullptr && ws->count > 0)
          warm_start(L, l, *ws, *shared.core_a.hull, *shared.core_b.hull, R, t);
      sample[l] = std::uint32_t(s);
      running |= 1u << l;
      radius_a[l] = shared.core_a.radius, radius_b[l] = shared.core_b.radius, scale[l] = g.scale;
      return true;
    }

    /// Lane l's GjkCompletion: gjk_limits()'s radii, floor, tolerance and margin from the lane's radii and scale.
    GjkCompletion<T> completion(int l) const {
      GjkCompletion<T> c;
      c.radius_a = radius_a[l], c.radius_b = radius_b[l], c.radii = c.radius_a + c.radius_b, c.scale = scale[l];
      c.floor = tolerance_floor(c.scale);
      c.tolerance = std::max(T(options.tolerance), c.floor);
      c.core_margin = T(options.margin) + c.radii;
      return c;
    }

    static constexpr bool refills_together = true;
    std::uint32_t running = 0;  // lanes holding a sample (load() sets, done() clears)
    // Every lane's sides hold `shared`'s cores (side_lanes() done since the last share() or lane-by-lane load()):
    // a support changes only the lanes' hints. side_lanes() again cost ~75 instructions a register a side.
    bool sides_ready = false;
    /// Starts the next samples in the lanes of `want` (lane order) and returns the lanes started. In double, lanes
    /// that end while others run are left empty until the register's last lane ends, and then every lane is
    /// loaded, W consecutive samples of one pair at a time where they are (load_all()), else lane by lane
    /// (load()). Why: lane by lane, the refill was ~585 of a hull sample's ~760 GJK instructions (M = 64, AVX2);
    /// 98% of hull samples end in their first iteration, so a register's lanes mostly end together and the wait
    /// is rare. Which lane runs a sample changes no bit of its answer (lanes are independent).
    std::uint32_t load_lanes(Lanes& L, std::uint32_t want) {
      if constexpr (std::is_same_v<T, double>) {
        flush(L);
        if (running != 0) return 0;
        want = kAllLanes;
        if (in.samples - next >= std::size_t(W) && one_pair(next)) {
          load_all(L);
          return kAllLanes;
        }
      }
      std::uint32_t started = 0;
      for (std::uint32_t left = want; left != 0; left &= left - 1) {
        const int l = __builtin_ctz(left);
        if (!load(L, l)) break;
        started |= 1u << l;
      }
      return started;
    }
    /// Samples s0 .. s0 + W share their shapes (made `shared`) and warm simplex.
    bool one_pair(std::size_t s0) {
      if (in.shape_a[s0] != shape_a || in.shape_b[s0] != shape_b) share(in.shape_a[s0], in.shape_b[s0]);
      bool same = true;
      for (int l = 1; l < W; ++l) same &= (in.shape_a[s0 + l] == shape_a) & (in.shape_b[s0 + l] == shape_b);
      if (hulls)
        for (int l = 1; l < W; ++l) same &= in.warm[s0 + l] == in.warm[s0];
      return same;
    }
    /// load() of samples next .. next + W into lanes 0 .. W (one pair's: one_pair()), each value a register:
    /// the poses and first directions are W consecutive doubles of their arrays; the same values and operations
    /// per lane as load(), so the same lane state.
    // GCC 12's false -Wuninitialized inside _mm512_sqrt_pd (GCC bug 105593; wide_samples.inl's poses() says more).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
    void load_all(Lanes& L) {
      const std::size_t s0 = next;
      next += std::size_t(W);
      running = kAllLanes;
      const auto row = [s0](const double* a) {
        real v;
        std::memcpy(&v, a + s0, sizeof v);
        return v;
      };
      for (int l = 0; l < W; ++l) L.pair[l] = std::int64_t(s0) + l, sample[l] = std::uint32_t(s0 + std::size_t(l));
      for (int e = 0; e < 9; ++e) L.R[e] = row(in.R[e]);
      for (int i = 0; i < 3; ++i) L.t[i] = row(in.t[i]);
      if (sides_ready) {  // the pair's later registers: only the hints are fresh per sample
        for (int l = 0; l < W; ++l) L.A.hint[l] = SupportHint{}, L.B.hint[l] = SupportHint{};
      } else {
        side_lanes(L.A, shared.core_a);
        side_lanes(L.B, shared.core_b);
        sides_ready = true;
      }
      // gjk_limits() per lane: |t| and the scale in double, as load() computes them.
      const real tx = L.t[0], ty = L.t[1], tz = L.t[2];
      const real lane_scale = G::splat(T(shared.bounding_a + shared.bounding_b)) + wsqrt<T>((tx * tx + ty * ty) + tz * tz);
      const real floor = G::splat(T(16) * machine_epsilon<T>()) * lane_scale;  // tolerance_floor()
      const real asked = G::splat(T(options.tolerance));
      const real tolerance = G::blend(asked < floor, floor, asked);  // std::max(asked, floor)
      const T radii = shared.core_a.radius + shared.core_b.radius;
      radius_a = G::splat(shared.core_a.radius), radius_b = G::splat(shared.core_b.radius), scale = lane_scale;
      // The first direction: the sample's where finite and non-zero, else A's centre minus B's (in A's frame),
      // else the x axis (start_search()).
      V3 init{row(in.direction[0]), row(in.direction[1]), row(in.direction[2])};
      const real zero = G::splat(T(0));
      const mask given = (init.x - init.x == zero) & (init.y - init.y == zero) & (init.z - init.z == zero) &
                         (G::norm2(init) > zero);
      if (lane_bits(given) != kAllLanes) {
        const Vec3<T>& cb = shared.center_b;
        const real bx = G::splat(cb.x()), by = G::splat(cb.y()), bz = G::splat(cb.z());
        const V3 b_center{((L.R[0] * bx + L.R[1] * by) + L.R[2] * bz) + L.t[0],
                          ((L.R[3] * bx + L.R[4] * by) + L.R[5] * bz) + L.t[1],
                          ((L.R[6] * bx + L.R[7] * by) + L.R[8] * bz) + L.t[2]};
        const Vec3<T>& ca = shared.center_a;
        init = G::pick(given, init, G::sub(V3{G::splat(ca.x()), G::splat(ca.y()), G::splat(ca.z())}, b_center));
        init = G::pick(G::norm2(init) > zero, init, V3{G::splat(T(1)), zero, zero});
      }
      // reset_search() and start_search() in every lane.
      L.fresh |= kAllLanes;
      L.lambda[0] = G::splat(T(1));
      L.count = G::splat_mask(1);
      L.slot[0] = G::splat_mask(0);
      L.d_prev = init;
      L.direction = V3{zero, zero, zero};
      L.lower = G::splat(-std::numeric_limits<T>::infinity());
      L.k = G::splat_mask(0);
      L.stale = G::splat_mask(0);
      if (L.newton_pair < 0) [[unlikely]] L.newton_pair = newton_pair_type(L.A.type, L.B.type) ? 1 : 0;
      L.newton = G::splat_mask(-typename G::Int(L.newton_pair));
      L.newton_next = G::splat_mask(0);
      L.newton_steps = G::splat_mask(0);
      L.max_iterations = G::splat_mask(typename G::Int(options.max_iterations));
      L.momentum = G::truth(options.solver != Solver::gjk);
      L.normalize = G::truth(normalize);
      L.boolean_only = G::truth(options.level == QueryLevel::boolean);
      L.tolerance = tolerance;
      L.relative = G::splat(T(options.relative_tolerance));
      L.touch = floor;
      L.core_margin = G::splat(T(options.margin) + radii);
      if (hulls)
        if (const WarmSimplex* ws = in.warm[s0]; ws != nullptr && ws->count > 0)
          warm_start_lanes(L, *ws, *shared.core_a.hull, *shared.core_b.hull);
    }
#pragma GCC diagnostic pop
    /// load_side() of one core into every lane. A hull's rows are the same in every lane: where every lane
    /// already holds it (the pair's later registers) only the hints are reset, and where it fills the table's
    /// rows (load_hull()'s usual case) each row is one broadcast instead of W lane copies.
    static void side_lanes(typename G::Side& side, const ShapeCore<T>& core) {
      side.s0 = G::splat(core.size.x()), side.s1 = G::splat(core.size.y()), side.s2 = G::splat(core.size.z());
      if (side.type == ShapeType::triangle) {
        for (int l = 0; l < W; ++l) G::load_side(side, G::side_start(core), l);
      } else if (side.type == ShapeType::convex) {
        const HullView* hull = core.hull;
        const std::uint32_t count = hull->vertex_count;
        bool same = (side.small & kAllLanes) == kAllLanes;
        for (int l = 0; l < W; ++l) same &= (side.hull[l] == hull) & (side.lane_vertices[l] == count);
        if (!same && int(count) != side.rows) {
          for (int l = 0; l < W; ++l) G::load_hull(side, hull, l);
          return;
        }
        for (int l = 0; l < W; ++l) side.hint[l] = SupportHint{};
        if (same) return;
        for (int i = 0; i < int(count); ++i) {
          side.table->vx[i] = G::splat(T(hull->vertices[3 * i]));
          side.table->vy[i] = G::splat(T(hull->vertices[3 * i + 1]));
          side.table->vz[i] = G::splat(T(hull->vertices[3 * i + 2]));
        }
        for (int l = 0; l < W; ++l) side.hull[l] = hull, side.lane_vertices[l] = count;
        side.small |= kAllLanes;
      }
    }

    std::uint32_t pending = 0;  // converged lanes (double) whose answers flush() has not written yet
    /// done()'s converged answers of the lanes in `pending`, computed in every lane at once (a lane's values are
    /// only written where it is pending) with done()'s operations: |x| as Eigen's x.norm() of a Vector3d (squares
    /// summed in index order, G::norm2()), n = -x / |x|, the witness points as G::lane_witnesses() sums them (from
    /// zero, vertex m's lambda times its point, m < count). Called before the lanes are loaded again (the loop
    /// refills right after its done() calls) and at the end of the run. Lane by lane, the completion cost ~100
    /// instructions a sample.
    void flush(const Lanes& L) {
      if (pending == 0) return;
      const real zero = G::splat(T(0));
      const real xn = G::norm(L.x);
      const V3 n = G::divide(G::neg(L.x), xn);
      V3 pa{zero, zero, zero}, pb{zero, zero, zero};
      for (int m = 0; m < 4; ++m) {
        const mask kept = L.count > G::splat_mask(m);
        if (!any(kept)) break;
        const mask q = L.slot[m] & G::splat_mask(3);
        const mask q1 = q == G::splat_mask(1), q2 = q == G::splat_mask(2), q3 = q == G::splat_mask(3);
        const V3 a = G::pick(q3, L.a[3], G::pick(q2, L.a[2], G::pick(q1, L.a[1], L.a[0])));
        const V3 b = G::pick(q3, L.b[3], G::pick(q2, L.b[2], G::pick(q1, L.b[1], L.b[0])));
        pa = G::pick(kept, G::add(pa, G::scale(L.lambda[m], a)), pa);
        pb = G::pick(kept, G::add(pb, G::scale(L.lambda[m], b)), pb);
      }
      const V3 wa = G::add(pa, G::scale(radius_a, n)), wb = G::sub(pb, G::scale(radius_b, n));
      const real v[10] = {xn - (radius_a + radius_b), wa.x, wa.y, wa.z, wb.x, wb.y, wb.z, n.x, n.y, n.z};
      for (std::uint32_t left = pending; left != 0; left &= left - 1) {
        const int l = __builtin_ctz(left);
        const std::uint32_t s = sample[l];
        out.status[s] = Status::converged;
        const std::size_t k = s * out.stride;
        out.distance[k] = double(v[0][l]);
        for (int i = 0; i < 3; ++i) {
          out.witness_a[i][k] = double(v[1 + i][l]);
          out.witness_b[i][k] = double(v[4 + i][l]);
          out.normal[i][k] = double(v[7 + i][l]);
        }
      }
      pending = 0;
    }

    /// complete_from_gjk() for lane l's sample, written in A's frame; what it cannot finish goes to the fallback.
    __attribute__((always_inline)) void done(const Lanes& L, int l, GjkStatus status) {
      running &= ~(1u << l);
      if (status == GjkStatus::converged && witness_level) [[likely]] {
        if constexpr (std::is_same_v<T, double>) {
          pending |= 1u << l;  // written by flush(), with the register's other converged lanes
          return;
        }
        // complete_from_gjk()'s converged case straight from the lane, in its operations and order (|x| as
        // g.x.norm(), n = -x / |x|, the cores' witness points as GjkResult::witness_a() combines them, the same
        // steps as wide_gjk_pairs.inl's converged()): the GjkResult copy (four simplex vertices), the call and the
        // PairOutput cost ~70 instructions per sample.
        const T ra = radius_a[l], rb = radius_b[l];
        const Vec3<T> x = G::get_lane(L.x, l);
        const T xn = x.norm();  // Eigen's reduction order, which differs between float and double (converged())
        const Vec3<T> n = -x / xn;
        Vec3<T> pa, pb;
        G::lane_witnesses(L, l, pa, pb);
        const std::uint32_t s = sample[l];
        out.status[s] = Status::converged;
        const std::size_t k = s * out.stride;
        out.distance[k] = double(xn - (ra + rb));  // gjk_limits()'s radii
        for (int i = 0; i < 3; ++i) {
          out.witness_a[i][k] = double(pa[i] + ra * n[i]);
          out.witness_b[i][k] = double(pb[i] - rb * n[i]);
          out.normal[i][k] = double(n[i]);
        }
        return;
      }
      GjkResult<T> g;
      G::finish(L, l, status, g, true);
      PairOutput<T> r;
      const std::uint32_t s = sample[l];
      if (!complete_from_gjk(completion(l), g, options, r)) {
        fallback[fallbacks++] = s;
        return;
      }
      out.status[s] = r.status;
      const std::size_t k = s * out.stride;
      out.distance[k] = double(r.distance);
      for (int c = 0; c < 3; ++c) {
        out.witness_a[c][k] = double(r.witness_a[c]);
        out.witness_b[c][k] = double(r.witness_b[c]);
        out.normal[c][k] = double(r.normal[c]);
      }
    }
  };

  static std::size_t run(const PairView& shapes, ShapeType type_a, ShapeType type_b, const SampleBatch& in,
                         const QueryOptions& options, const SampleResults& out, std::uint32_t* fallback) {
    if (in.samples == 0) return 0;
    Lanes L;
    L.A.type = type_a;
    L.B.type = type_b;
    typename G::Rows rows;
    rows.attach(L.A, L.B);
    Source source(shapes, in, options, out, fallback, type_a, type_b);
    G::drive(L, source, options.solver, true);
    if constexpr (std::is_same_v<T, double>) source.flush(L);
    return source.fallbacks;
  }
};
