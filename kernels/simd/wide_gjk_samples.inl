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
  static constexpr int W = G::W;

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
    GjkCompletion<T> completion[W];

    Source(const PairView& shapes_, const SampleBatch& in_, const QueryOptions& options_, const SampleResults& out_,
           std::uint32_t* fallback_, ShapeType a, ShapeType b)
        : shapes(shapes_), in(in_), options(options_), out(out_), fallback(fallback_),
          normalize(!(a == ShapeType::ellipsoid && b == ShapeType::ellipsoid)),
          witness_level(options_.level >= QueryLevel::witness),
          hulls(a == ShapeType::convex && b == ShapeType::convex && in_.warm != nullptr) {}

    void share(std::uint32_t ia, std::uint32_t ib) {
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
      completion[l] = {shared.core_a.radius, shared.core_b.radius, g.radii, g.scale, g.floor, g.tolerance, g.core_margin};
      return true;
    }

    /// complete_from_gjk() for lane l's sample, written in A's frame; what it cannot finish goes to the fallback.
    __attribute__((always_inline)) void done(const Lanes& L, int l, GjkStatus status) {
      if (status == GjkStatus::converged && witness_level) [[likely]] {
        // complete_from_gjk()'s converged case straight from the lane, in its operations and order (|x| as
        // g.x.norm(), n = -x / |x|, the cores' witness points as GjkResult::witness_a() combines them, the same
        // steps as wide_gjk_pairs.inl's converged()): the GjkResult copy (four simplex vertices), the call and the
        // PairOutput cost ~70 instructions per sample.
        const GjkCompletion<T>& c = completion[l];
        const Vec3<T> x = G::get_lane(L.x, l);
        const T xn = x.norm();  // Eigen's reduction order, which differs between float and double (converged())
        const Vec3<T> n = -x / xn;
        Vec3<T> pa, pb;
        G::lane_witnesses(L, l, pa, pb);
        const std::uint32_t s = sample[l];
        out.status[s] = Status::converged;
        const std::size_t k = s * out.stride;
        out.distance[k] = double(xn - c.radii);
        for (int i = 0; i < 3; ++i) {
          out.witness_a[i][k] = double(pa[i] + c.radius_a * n[i]);
          out.witness_b[i][k] = double(pb[i] - c.radius_b * n[i]);
          out.normal[i][k] = double(n[i]);
        }
        return;
      }
      GjkResult<T> g;
      G::finish(L, l, status, g, true);
      PairOutput<T> r;
      const std::uint32_t s = sample[l];
      if (!complete_from_gjk(completion[l], g, options, r)) {
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
    return source.fallbacks;
  }
};
