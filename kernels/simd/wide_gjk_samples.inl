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
    std::uint32_t sample[W] = {};
    GjkCompletion<T> completion[W];

    Source(const PairView& shapes_, const SampleBatch& in_, const QueryOptions& options_, const SampleResults& out_,
           std::uint32_t* fallback_, ShapeType a, ShapeType b)
        : shapes(shapes_), in(in_), options(options_), out(out_), fallback(fallback_),
          normalize(!(a == ShapeType::ellipsoid && b == ShapeType::ellipsoid)),
          witness_level(options_.level >= QueryLevel::witness) {}

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
