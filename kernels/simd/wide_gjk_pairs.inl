// GJK pairs straight from the batch arrays: the executor's per-pair work (pose validation, B's pose in A's frame,
// the setup, completion, the world-frame output) done without a PairSetup per pair. Poses are validated and the
// relative poses computed W pairs per register in double (PairLanes), a chunk at a time, then the shapes' parameters,
// GJK's limits and first direction for the whole chunk; a lane refilled with the next pair copies them from the
// chunk's arrays, runs WideGjk's loop, and writes its answer into the result arrays. Every operation is the executor's scalar path's (prepare_pair's arithmetic, make_core,
// set_gjk_parameters, complete_from_gjk, write_pair_output), in the same order, so the results are the same bits
// (tested in tests/engine/executor_gjk_pairs_test.cpp); pairs that need more (invalid input, a float stall redone
// in double) go back to that path.
//
// No include guard: included once per instruction set by isa_body.inl, after wide_gjk.inl and wide_pairs.inl.

/// A boolean double query's float pass (WideGjkPairs<double>::run_certified()): what the float GJK answered for
/// the pair at one position of the run's pair list, and what its double certificate needs. kind 0: no answer to
/// certify (not run: invalid input; or ended otherwise than separated / overlapping: budget, convergence, stall),
/// 1: separated along `direction` (the last search direction d, whose support point -d proved it), 2: the
/// cores overlap or are within the margin, with the `count` simplex vertices being D's support points in the
/// directions -vertex[m] (in simplex order).
struct FloatAnswer {
  std::uint8_t kind = 0;
  std::uint8_t count = 0;
  std::int32_t iterations = 0;
  float direction[3] = {};
  float vertex[4][3] = {};
};

template <class T> struct WideGjkPairs {
  using G = WideGjk<T>;
  using Lanes = typename G::Lanes;
  using Int = typename G::Int;
  using P = PairLanes;
  static constexpr int W = G::W;
  static constexpr int Wd = P::W;
  /// Pairs whose relative poses are computed ahead of the lanes: a few KB, in L1.
  static constexpr std::size_t kChunk = 64;

  /// The current chunk's pairs, slot s = pair `read - count + s` of the run, as separate arrays (one per value):
  /// everything a lane's refill copies and its completion needs, computed W pairs per register from the batch and
  /// ShapeTable arrays (poses, the cores' parameters, gjk_limits(), the first direction), so that a refill is a
  /// row of copies instead of per-pair scalar arithmetic (the setup was a third of a boolean ellipsoid pair's
  /// instructions). Slots of invalid pairs are computed too (their lanes read shape 0) but never loaded: `left`
  /// holds the valid slots not yet loaded. Written before read: fill_chunk() writes slots [0, count).
  struct Chunk {
    static_assert(kChunk % std::size_t(Wd) == 0 && kChunk <= 64, "whole registers per chunk, one bit per slot");
    // B's pose in A's frame (R row-major, rounded to T as start_lane() took them), A's world pose for the output.
    T R[9][kChunk], t[3][kChunk];
    double Ra[9][kChunk], ta[3][kChunk];
    std::uint32_t pair[kChunk];
    std::int64_t shape_a[kChunk], shape_b[kChunk];  // for the hull views
    // make_core()'s parameters, gjk_limits(), the first direction.
    T size_a[3][kChunk], size_b[3][kChunk], radius_a[kChunk], radius_b[kChunk];
    T radii[kChunk], scale[kChunk], floor[kChunk], tolerance[kChunk], core_margin[kChunk];
    T init[3][kChunk];
    std::uint64_t left = 0;
  };

  /// x, y, z and a zero in one 32-byte vector: the output's rotation column by column, so that A's frame to the
  /// world is three broadcasts, three products and two sums per vector instead of nine products and six sums
  /// (element i of (c0 x + c1 y) + c2 z is mul()'s (R(i, 0) x + R(i, 1) y) + R(i, 2) z: the same bits).
  typedef double d4 __attribute__((vector_size(4 * sizeof(double))));

  /// What a lane keeps of its pair until it finishes: where the answer goes and what completing it needs beyond
  /// the lane's own tolerance, touch (= the floor) and core margin.
  struct LanePair {
    std::uint32_t pair = 0;
    d4 Ra[3] = {};  // A's world rotation by columns (lane 3 stays 0)
    d4 ta = {};     // only at QueryLevel::witness (the only level that writes world points)
    T radius_a, radius_b, radii, scale;
    std::uint32_t position = 0;  // index in the run's pair list (certified runs: the float answer's slot)
    std::int32_t float_iterations = 0;  // certified runs: the float pass's iterations, added to the double's

    /// dst[c][i] = component c of R v (+ t with `translate`) for v in A's frame: write_pair_output()'s
    /// mul<double>(Ra, v) (+ ta). (No d4 by value: the scalar build has no AVX, and -Wpsabi warns of the ABI.)
    void put_world(double* const* dst, std::size_t i, const Vec3<T>& v, bool translate) const {
      d4 r = (Ra[0] * double(v.x()) + Ra[1] * double(v.y())) + Ra[2] * double(v.z());
      if (translate) r += ta;
      dst[0][i] = r[0];
      dst[1][i] = r[1];
      dst[2][i] = r[2];
    }
    Eigen::Matrix3d rotation() const {
      Eigen::Matrix3d R;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) R(i, j) = Ra[j][i];
      return R;
    }
  };

  /// W pairs' values of precision T in double-width registers (Wd lanes): the side stage's arithmetic is T's,
  /// lane by lane, so it gives the scalar setup's bits in either precision.
  typedef T tvec __attribute__((vector_size(sizeof(T) * Wd)));
  typedef T unaligned_tvec __attribute__((vector_size(sizeof(T) * Wd), aligned(alignof(T))));
  typedef typename P::mask unaligned_mask __attribute__((aligned(alignof(std::int64_t))));
  static tvec to_t(typename P::real v) { return __builtin_convertvector(v, tvec); }
  static tvec splat_t(T v) { return tvec{} + v; }
  static void put(T* to, tvec v) { *reinterpret_cast<unaligned_tvec*>(to) = v; }
  static void put_double(double* to, typename P::real v) { *reinterpret_cast<typename P::unaligned_real*>(to) = v; }

  /// One side's core for W pairs, as make_core() builds it from the ShapeTable's per-shape arrays (no ShapeCore,
  /// no PairSetup): the sizes the support reads, the swept radius with make_core's roundings (T(inflation), plus
  /// T(radius) for spheres and capsules) and the core's centre (the hull's centroid, else the origin).
  struct SideLanes {
    tvec size[3], radius, centre[3];
  };
  static SideLanes side_lanes(const PairView& in, ShapeType type, const typename P::Pose& p) {
    SideLanes r;
    const tvec zero = splat_t(T(0));
    for (int c = 0; c < 3; ++c) r.size[c] = zero, r.centre[c] = zero;
    r.radius = to_t(P::field(in.shape_inflation, p));
    switch (type) {
      case ShapeType::sphere: r.radius += to_t(P::field(in.shape_size[0], p)); break;  // a point: no size read
      case ShapeType::capsule:
        r.radius += to_t(P::field(in.shape_size[0], p));
        r.size[1] = to_t(P::field(in.shape_size[1], p));  // the half length
        break;
      case ShapeType::convex: {
        // HullView::centroid of each lane's view: the views are an array indexed by shape like the others, of
        // sizeof(HullView)-byte entries (p.shape is the index times sizeof(double)).
        static_assert(sizeof(HullView) % sizeof(double) == 0, "whole doubles per view");
        const typename P::mask offset = p.shape * typename P::Int(sizeof(HullView) / sizeof(double));
        const char* views = reinterpret_cast<const char*>(in.shape_hull);
        for (int c = 0; c < 3; ++c)
          r.centre[c] = to_t(gather_bytes<double>(
              reinterpret_cast<const double*>(views + offsetof(HullView, centroid) + sizeof(double) * c), offset));
        break;
      }
      default:
        for (int c = 0; c < 3; ++c) r.size[c] = to_t(P::field(in.shape_size[c], p));
        break;
    }
    return r;
  }

  struct Source {
    const PairView& in;
    const QueryOptions& options;
    ShapeType type_a, type_b;
    const std::uint32_t* pairs;
    std::size_t n;
    const ResultView& out;
    std::uint32_t* fallback;
    std::size_t fallbacks = 0;
    std::size_t read = 0;  // pairs[0 .. read) went into a chunk
    bool witness = options.level >= QueryLevel::witness;
    /// The same for every pair of the run (gjk_limits() and the solver): set once per run in every lane by
    /// start_run(); a refill sets only what differs per pair (momentum too: the loop clears it per lane).
    Int momentum = options.solver != Solver::gjk ? Int(-1) : Int(0);
    Chunk chunk;
    LanePair lane[W];  // written by load() before done() reads it
    std::size_t base = 0;  // the chunk's slot 0 is pairs[base]
    /// Certified boolean double runs (run_certified()): the float pass writes `record` (float Source), the double
    /// pass reads `answers` and certifies them in `check`'s lanes before any GJK (double Source).
    FloatAnswer* record = nullptr;
    const FloatAnswer* answers = nullptr;
    Lanes* check = nullptr;

    // A constructor, not aggregate initialisation: that value-initialises the members it is not given, which
    // would zero the chunk's ~25 KB at every run() (one run() per type-pair group of a tile, a few dozen pairs
    // in a mixed batch).
    Source(const PairView& in_, const QueryOptions& options_, ShapeType a, ShapeType b, const std::uint32_t* pairs_,
           std::size_t n_, const ResultView& out_, std::uint32_t* fallback_)
        : in(in_), options(options_), type_a(a), type_b(b), pairs(pairs_), n(n_), out(out_), fallback(fallback_) {}

    /// The lanes' fields that are the same for every pair of the run (set_gjk_parameters()'s values):
    /// max_iterations, the relative tolerance, boolean_only, and the momentum normalisation (normalised
    /// directions unless both cores are strictly convex, ShapeCore::strictly_convex()).
    void start_run(Lanes& L) const {
      const bool normalize = !(type_a == ShapeType::ellipsoid && type_b == ShapeType::ellipsoid);
      L.max_iterations = G::splat_mask(Int(options.max_iterations));
      L.relative = G::splat(T(options.relative_tolerance));
      L.normalize = G::truth(normalize);
      L.boolean_only = G::truth(options.level == QueryLevel::boolean);
    }

    /// The next kChunk pairs, W per register: poses validated and B's pose in A's frame (prepare_pair's rule and
    /// arithmetic; invalid pairs go to the fallback), then set_gjk_parameters()'s values with the same
    /// operations.
    void fill_chunk() {
      chunk.left = 0;
      base = read;
      const std::size_t end = std::min(n, read + kChunk);
      const T tolerance = T(options.tolerance), margin = T(options.margin);
      for (std::size_t k = read; k < end; k += Wd) {
        const std::size_t s = k - read;  // a multiple of Wd: whole registers stay inside the chunk
        const auto b = P::block(pairs + read, end - read, s);
        P::Pose pa = load(b, true), pb = load(b, false);
        P::normalize(pa);
        P::normalize(pb);
        const P::V3 ca[3] = {P::column(pa, 0), P::column(pa, 1), P::column(pa, 2)};
        const P::V3 cb[3] = {P::column(pb, 0), P::column(pb, 1), P::column(pb, 2)};
        const P::V3 d = P::sub(pb.t, pa.t);
        tvec R[9], t[3];
        typename P::real td[3];
        for (int i = 0; i < 3; ++i) {
          for (int j = 0; j < 3; ++j) put(chunk.R[3 * i + j] + s, R[3 * i + j] = to_t(P::dot(ca[i], cb[j])));
          td[i] = P::dot(ca[i], d);
          put(chunk.t[i] + s, t[i] = to_t(td[i]));
          // Column i of Ra: entries (0, i), (1, i), (2, i).
          put_double(chunk.Ra[i] + s, ca[i].x), put_double(chunk.Ra[3 + i] + s, ca[i].y),
              put_double(chunk.Ra[6 + i] + s, ca[i].z);
        }
        put_double(chunk.ta[0] + s, pa.t.x), put_double(chunk.ta[1] + s, pa.t.y), put_double(chunk.ta[2] + s, pa.t.z);
        __builtin_memcpy(chunk.pair + s, b.idx, sizeof b.idx);
        *reinterpret_cast<unaligned_mask*>(chunk.shape_a + s) = pa.shape >> 3;
        *reinterpret_cast<unaligned_mask*>(chunk.shape_b + s) = pb.shape >> 3;

        const SideLanes A = side_lanes(in, type_a, pa), B = side_lanes(in, type_b, pb);
        for (int c = 0; c < 3; ++c) put(chunk.size_a[c] + s, A.size[c]), put(chunk.size_b[c] + s, B.size[c]);
        put(chunk.radius_a + s, A.radius);
        put(chunk.radius_b + s, B.radius);
        // gjk_limits(): |t| as norm3() in setup_pair_into(), in double; the rest in T.
        const typename P::real t_norm = wsqrt<double>((td[0] * td[0] + td[1] * td[1]) + td[2] * td[2]);
        const typename P::real bounding = P::field(in.bounding_radii, pa) + P::field(in.bounding_radii, pb);
        const tvec radii = A.radius + B.radius, scale = to_t(bounding + t_norm);
        const tvec floor = splat_t(T(16) * machine_epsilon<T>()) * scale;  // tolerance_floor(scale)
        put(chunk.radii + s, radii);
        put(chunk.scale + s, scale);
        put(chunk.floor + s, floor);
        put(chunk.tolerance + s, wmax(splat_t(tolerance), floor));
        put(chunk.core_margin + s, splat_t(margin) + radii);
        // MinkowskiDifference::center(): A's centre minus B's centre mapped into A's frame (mul()'s association),
        // the x axis when that is zero (start_lane()'s rule).
        tvec init[3];
        for (int r = 0; r < 3; ++r)
          init[r] = A.centre[r] - (((R[3 * r] * B.centre[0] + R[3 * r + 1] * B.centre[1]) + R[3 * r + 2] * B.centre[2]) +
                                   t[r]);
        const auto nonzero = (init[0] * init[0] + init[1] * init[1]) + init[2] * init[2] > splat_t(T(0));
        put(chunk.init[0] + s, nonzero ? init[0] : splat_t(T(1)));
        put(chunk.init[1] + s, nonzero ? init[1] : splat_t(T(0)));
        put(chunk.init[2] + s, nonzero ? init[2] : splat_t(T(0)));

        const std::uint32_t valid = lane_bits(pa.valid & pb.valid) & b.live;
        chunk.left |= std::uint64_t(valid) << s;
        for (std::uint32_t bad = b.live & ~valid; bad != 0; bad &= bad - 1)
          fallback[fallbacks++] = b.idx[__builtin_ctz(bad)];
      }
      read = end;
    }
    P::Pose load(const typename P::Block& b, bool side_a) const {
      return P::load_pose(in, side_a ? in.shape_a : in.shape_b, side_a ? in.translation_a : in.translation_b,
                          side_a ? in.rotation_a : in.rotation_b, b.idx, b.consecutive);
    }

    /// Starts the next pair in lane l: copies of the chunk's values (start_lane()'s writes, the run's constants
    /// aside), the hull's rows for small hulls (load_side()), the search reset.
    bool load(Lanes& L, int l) {
      while (chunk.left == 0) {
        if (read == n) return false;
        fill_chunk();
        if (answers) certify_chunk();
      }
      const std::size_t s = std::size_t(__builtin_ctzll(chunk.left));
      chunk.left &= chunk.left - 1;
      const Chunk& c = chunk;
      L.pair[l] = std::int64_t(s);
      for (int e = 0; e < 9; ++e) L.R[e][l] = c.R[e][s];
      for (int i = 0; i < 3; ++i) L.t[i][l] = c.t[i][s];
      side(L.A, c.size_a, c.shape_a, s, l);
      side(L.B, c.size_b, c.shape_b, s, l);
      G::reset_search(L, l, Vec3<T>(c.init[0][s], c.init[1][s], c.init[2][s]));
      L.momentum[l] = momentum;
      L.tolerance[l] = c.tolerance[s];
      L.touch[l] = c.floor[s];  // gjk_limits(): touch = floor
      L.core_margin[l] = c.core_margin[s];

      LanePair& lp = lane[l];
      lp.pair = c.pair[s];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) lp.Ra[j][i] = c.Ra[3 * i + j][s];
      if (witness)
        for (int i = 0; i < 3; ++i) lp.ta[i] = c.ta[i][s];
      lp.radius_a = c.radius_a[s];
      lp.radius_b = c.radius_b[s];
      lp.radii = c.radii[s];
      lp.scale = c.scale[s];
      lp.position = std::uint32_t(base + s);
      if (answers) lp.float_iterations = answers[base + s].iterations;
      return true;
    }
    /// Slot s of one side into lane l, as load_side() takes it: the sizes of the types that have them (the
    /// support of the others reads none), the hull of a convex core. (No triangle: its pairs are not run here.)
    void side(typename G::Side& side, const T (&size)[3][kChunk], const std::int64_t* shape, std::size_t s,
              int l) const {
      switch (side.type) {
        case ShapeType::sphere: return;
        case ShapeType::capsule: side.s1[l] = size[1][s]; return;
        case ShapeType::convex: G::load_hull(side, &in.shape_hull[shape[s]], l); return;
        default:
          side.s0[l] = size[0][s];
          side.s1[l] = size[1][s];
          side.s2[l] = size[2][s];
          return;
      }
    }

    /// complete_pair() and write_pair_output() for lane l's pair; a pair complete_from_gjk() cannot finish goes to
    /// the fallback (computed again on the scalar path).
    void done(const Lanes& L, int l, GjkStatus status) {
      if (record) {
        keep(L, l, status);
        return;
      }
      // A certified run's double GJK (the certificate failed or there was none): its iterations plus the float
      // pass's, the work done for the pair. (A pair this path leaves to the scalar fallback reports the scalar
      // path's iterations alone.)
      if (finish_pair(L, l, status) && answers) out.iterations[lane[l].pair] += lane[l].float_iterations;
    }
    /// Lane l's answer into the result arrays; false when the pair went to the fallback instead.
    bool finish_pair(const Lanes& L, int l, GjkStatus status) {
      if (status == GjkStatus::separated_proven || status == GjkStatus::collision_proven) {
        // A boolean query's usual ending: complete_from_gjk() and write_pair_output() reduce to a converged pair
        // whose collide is decided, its world direction and its iterations (the same arithmetic), without a
        // GjkResult (the simplex, 40 values) and a PairOutput per pair.
        const LanePair& lp = lane[l];
        const std::uint32_t i = lp.pair;
        out.status[i] = Status::converged;
        out.collide[i] = status == GjkStatus::collision_proven ? 1 : 0;
        lp.put_world(out.direction, i, G::get_lane(L.direction, l), false);
        out.iterations[i] = int(L.k[l]);
        return true;
      }
      if (status == GjkStatus::converged || status == GjkStatus::max_iterations) {
        converged(L, l, status);
        return true;
      }
      if (status == GjkStatus::overlap && options.level != QueryLevel::penetration) {  // penetration: EPA below
        overlapping(L, l);
        return true;
      }
      GjkResult<T> g;
      G::finish(L, l, status, g, witness);
      const LanePair& lp = lane[l];
      // The setup's completion values: the floor is the lane's touch tolerance (gjk_limits()).
      const GjkCompletion<T> completion{lp.radius_a, lp.radius_b, lp.radii,          lp.scale,
                                        L.touch[l],  L.tolerance[l], L.core_margin[l]};
      PairOutput<T> r;
      if (!complete_from_gjk(completion, g, options, r)) {
        fallback[fallbacks++] = lp.pair;
        return false;
      }
      const Eigen::Vector3d ta(lp.ta[0], lp.ta[1], lp.ta[2]);
      write_pair_output(r, lp.rotation(), ta, lp.pair, options.level, out);
      return true;
    }

    /// The float pass of a certified run: lane l's answer into record[position] (drive_boolean_directions():
    /// vertex m's direction is in L.a[L.slot[m]]). Separated and overlapping answers are kept for the double
    /// certificate; any other ending (budget, convergence, stall) leaves kind 0: the double GJK decides.
    void keep(const Lanes& L, int l, GjkStatus status) {
      FloatAnswer& r = record[lane[l].position];
      r.iterations = std::int32_t(L.k[l]);
      const bool separated = status == GjkStatus::separated_proven;
      const bool overlapping = status == GjkStatus::collision_proven || status == GjkStatus::overlap;
      r.kind = separated ? 1 : overlapping ? 2 : 0;
      const Vec3<T> d = G::get_lane(L.direction, l);
      for (int c = 0; c < 3; ++c) r.direction[c] = float(d[c]);
      if (!overlapping) return;
      r.count = std::uint8_t(L.count[l]);
      for (int m = 0; m < int(r.count); ++m) {
        const Vec3<T> v = G::get_lane(L.a[int(L.slot[m][l]) & 3], l);
        for (int c = 0; c < 3; ++c) r.vertex[m][c] = float(v[c]);
      }
    }

    /// The certificates of the chunk's float answers, W pairs at a time in `check`'s lanes (double): a pair whose
    /// certificate holds gets its answer here and leaves chunk.left; the others stay for the double GJK.
    ///  - separated along d: w = D.support(-d) in double (d widened), accepted iff <w, d> / |d| > core margin,
    ///    the double GJK's own test that ends a separated boolean pair (ends_separated);
    ///  - overlapping: the simplex's vertices computed again in double (D.support(-v_m)), the origin projected on
    ///    their hull with project() (the double GJK's projection), accepted iff the tetrahedron contains the
    ///    origin or the projection's norm is <= max(core margin, touch): the double GJK's ends_contains,
    ///    ends_collision and ends_overlap tests.
    /// The certificate's support points are points of the double problem's Minkowski difference, so an accepted
    /// answer is proven in double exactly as the double GJK proves its own; a pair within float error of touching
    /// fails it and runs the double GJK. The answer's direction is the float direction (widened), its iterations
    /// the float pass's.
    void certify_chunk() {
      std::uint64_t todo = 0;
      for (std::uint64_t bits = chunk.left; bits != 0; bits &= bits - 1) {
        const int s = __builtin_ctzll(bits);
        if (answers[base + std::size_t(s)].kind != 0) todo |= std::uint64_t(1) << s;
      }
      while (todo != 0) {
        int slot[W];
        int lanes = 0;
        for (; lanes < W && todo != 0; todo &= todo - 1) slot[lanes++] = __builtin_ctzll(todo);
        certify_lanes(slot, lanes);
      }
    }
    /// The square root lane by lane (correctly rounded: wsqrt()'s bits). GCC 12 reports its own _mm512_sqrt_pd's
    /// `__m512d __Y = __Y` (bug 105593) as -Wuninitialized on the vectors built lane by lane here, which
    /// -Wno-maybe-uninitialized (kernels/CMakeLists.txt) does not cover.
    static typename G::real root(typename G::real a) {
      for (int l = 0; l < W; ++l) a[l] = std::sqrt(a[l]);
      return a;
    }
    void certify_lanes(const int* slot, int lanes) {
      Lanes& C = *check;
      using V3 = typename G::V3;
      const Chunk& c = chunk;
      std::uint32_t live = 0, sep_bits = 0;
      typename G::Int count[W] = {};
      V3 v[4];
      for (int m = 0; m < 4; ++m) v[m] = {G::splat(T(1)), G::splat(T(0)), G::splat(T(0))};
      for (int l = 0; l < lanes; ++l) {
        const std::size_t s = std::size_t(slot[l]);
        const FloatAnswer& a = answers[base + s];
        live |= 1u << l;
        for (int e = 0; e < 9; ++e) C.R[e][l] = c.R[e][s];
        for (int i = 0; i < 3; ++i) C.t[i][l] = c.t[i][s];
        side(C.A, c.size_a, c.shape_a, s, l);
        side(C.B, c.size_b, c.shape_b, s, l);
        C.core_margin[l] = c.core_margin[s];
        C.touch[l] = c.floor[s];
        if (a.kind == 1) {
          sep_bits |= 1u << l;
          count[l] = 1;
          G::set_lane(v[0], l, Vec3<T>(T(a.direction[0]), T(a.direction[1]), T(a.direction[2])));
        } else {
          count[l] = a.count;
          for (int m = 0; m < int(a.count); ++m)
            G::set_lane(v[m], l, Vec3<T>(T(a.vertex[m][0]), T(a.vertex[m][1]), T(a.vertex[m][2])));
        }
      }
      // One vector load of the counts. (Built lane by lane into an unset vector, the scalar build (W = 1, GCC 12
      // -O3) read counts that were not these, lane masks of them false, in the first runs of a process: the
      // certificates of AVX2 and AVX-512 failed there. Not explained in the time this had.)
      static_assert(sizeof(typename G::mask) == sizeof count, "one count per lane");
      typename G::mask cnt;
      std::memcpy(&cnt, count, sizeof cnt);
      const typename G::mask sep = G::lanes_of(sep_bits), in = G::lanes_of(live);
      V3 p[4], sa, sb;
      G::minkowski(C, G::neg(v[0]), live, p[0], sa, sb);
      // Separated: the double GJK's ends_separated test along d.
      const typename G::real lb = G::dot(p[0], v[0]) / root(G::norm2(v[0]));
      const typename G::mask over = in & ~sep;
      typename G::real V[4] = {}, total{}, xn{};
      if (any(over)) {
        for (int m = 1; m < 4; ++m) {
          const std::uint32_t need = lane_bits(over & (cnt > G::splat_mask(m)));
          p[m] = p[0];
          if (need) G::minkowski(C, G::neg(v[m]), need, p[m], sa, sb);
        }
        // Four vertices: tetrahedron()'s signed volumes (project()'s operations), for its containment test below.
        V[0] = G::det3(p[1], p[2], p[3]), V[1] = -G::det3(p[0], p[2], p[3]), V[2] = G::det3(p[0], p[1], p[3]),
        V[3] = -G::det3(p[0], p[1], p[2]);
        total = ((V[0] + V[1]) + V[2]) + V[3];
        // One vertex: its norm. (Two or three vertices, ended by |x| <= core margin in float, are left to the double
        // GJK: `x = pick(multi, project(p, s, cnt - 1, multi).x, x)` here left x = p[0] in the scalar build (W = 1,
        // GCC 12, -O1 and -O3) for triangles whose project() answer is the face, on inputs bit-identical to AVX2's,
        // deterministically (also under valgrind). memcheck (scalar and AVX2) and -fsanitize=undefined on
        // isa_scalar.cpp (trapping) report nothing, -fno-strict-aliasing and -fno-tree-(slp-)vectorize do not
        // change it, and a debug print of cnt and the masks before this line makes it go away. So a code-generation
        // problem with the 1-lane vector types is suspected rather than a memory error; not reduced further.)
        const V3 x = p[0];
        xn = root(G::norm2(x));
      }
      // The decision lane by lane, in plain scalars (the same tests as the double GJK's, on the same values).
      bool ok[W] = {};
      for (int l = 0; l < lanes; ++l) {
        if (sep_bits >> l & 1u) {
          ok[l] = lb[l] > C.core_margin[l];
        } else if (count[l] == 4) {
          // tetrahedron()'s inside: total != 0 and no volume of the opposite sign (project()'s opposite_sign()).
          const T t = total[l];
          bool inside = t != T(0);
          for (int m = 0; m < 4; ++m) inside = inside && !((V[m][l] > T(0) && t < T(0)) || (V[m][l] < T(0) && t > T(0)));
          ok[l] = inside;
        } else if (count[l] == 1) {
          // The double GJK's ends_collision (|x| <= core margin) and ends_overlap (|x| <= touch) tests.
          const T cm = C.core_margin[l], touch = C.touch[l];
          ok[l] = xn[l] <= (cm < touch ? touch : cm);
        }
      }
      for (int l = 0; l < lanes; ++l) {
        if (!ok[l]) continue;
        const std::size_t s = std::size_t(slot[l]);
        const FloatAnswer& a = answers[base + s];
        const std::uint32_t i = c.pair[s];
        LanePair lp;
        for (int r = 0; r < 3; ++r)
          for (int j = 0; j < 3; ++j) lp.Ra[j][r] = c.Ra[3 * r + j][s];
        out.status[i] = Status::converged;
        out.collide[i] = a.kind == 1 ? 0 : 1;
        lp.put_world(out.direction, i, Vec3<T>(T(a.direction[0]), T(a.direction[1]), T(a.direction[2])), false);
        out.iterations[i] = a.iterations;
        chunk.left &= ~(std::uint64_t(1) << s);
      }
    }

    /// A distance / witness query's usual ending (GJK converged, or its budget ran out with x away from the
    /// origin): complete_from_gjk() and write_pair_output() for it, with their operations in their order, straight
    /// from the lane, without the GjkResult (the simplex, ~40 values), the PairOutput and the out-of-line
    /// completion (finish() + complete_from_gjk() + write_pair_output() were ~300 instructions per demo pair,
    /// AVX2). Values the query level does not write are not computed.
    void converged(const Lanes& L, int l, GjkStatus status) {
      const LanePair& lp = lane[l];
      const std::uint32_t i = lp.pair;
      const Vec3<T> x = G::get_lane(L.x, l);
      // complete_from_gjk()'s own expression, g.x.norm(), not norm3(): Eigen reduces a 3-vector of doubles as
      // (x^2 + y^2) + z^2 but one of floats as x^2 + (y^2 + z^2) (measured with GCC 12, Eigen 3.4, on SSE2, AVX2
      // and AVX-512 flags alike), so only the same call gives the same bits in both precisions.
      const T xn = x.norm();
      out.status[i] = status == GjkStatus::max_iterations ? Status::max_iterations : Status::converged;
      out.collide[i] = L.lower[l] > L.core_margin[l] ? 0 : 1;  // finish(): !(lower bound > core margin)
      const QueryLevel level = options.level;
      if (level >= QueryLevel::distance) out.distance[i] = static_cast<double>(xn - lp.radii);
      if (level >= QueryLevel::witness) {
        const Vec3<T> n = -x / xn;
        // GjkResult::witness_a() / witness_b(): sum of lambda[m] times the vertex's point, from zero, in m order.
        Vec3<T> pa = Vec3<T>::Zero(), pb = Vec3<T>::Zero();
        const int count = int(L.count[l]);
        for (int m = 0; m < count; ++m) {
          const int q = int(L.slot[m][l]) & 3;
          const T lambda = L.lambda[m][l];
          pa += lambda * G::get_lane(L.a[q], l);
          pb += lambda * G::get_lane(L.b[q], l);
        }
        lp.put_world(out.witness_a, i, pa + lp.radius_a * n, true);
        lp.put_world(out.witness_b, i, pb - lp.radius_b * n, true);
        lp.put_world(out.normal, i, n, false);
      }
      lp.put_world(out.direction, i, G::get_lane(L.direction, l), false);
      out.iterations[i] = int(L.k[l]);
    }

    /// Overlapping cores below QueryLevel::penetration (no EPA): complete_from_gjk() answers collide with no
    /// distance, no witness and no normal (its PairOutput's NaNs), which write_pair_output() maps to the world like
    /// any point; the same operations here on the same NaNs, without the GjkResult and the out-of-line calls (a
    /// mixed batch like the demo's ends many of its GJK pairs this way). Out of line: inlined into drive(), it cost
    /// the loop of every other pair ~0.5% (box-cylinder witness 6720 -> 6760 instructions per pair, AVX2).
    __attribute__((noinline)) void overlapping(const Lanes& L, int l) {
      const LanePair& lp = lane[l];
      const std::uint32_t i = lp.pair;
      out.status[i] = Status::converged;
      out.collide[i] = 1;
      const QueryLevel level = options.level;
      if (level >= QueryLevel::distance) out.distance[i] = static_cast<double>(quiet_nan<T>());
      if (level >= QueryLevel::witness) {
        // write_pair_output()'s R NaN (+ t) of the PairOutput's NaNs, stored without the arithmetic: on x86 a
        // product or sum with a quiet NaN operand returns that NaN, so every component is double(quiet_nan<T>()),
        // the default quiet NaN, in either precision (the same bits; tested against the scalar path).
        const double none = static_cast<double>(quiet_nan<T>());
        for (double* const* v : {out.witness_a, out.witness_b, out.normal})
          for (int c = 0; c < 3; ++c) v[c][i] = none;
      }
      lp.put_world(out.direction, i, G::get_lane(L.direction, l), false);
      out.iterations[i] = int(L.k[l]);
    }
  };

  static std::size_t run(const PairView& in, ShapeType type_a, ShapeType type_b, const std::uint32_t* pairs,
                         std::size_t n, const QueryOptions& options, const ResultView& out, std::uint32_t* fallback) {
    if (n == 0) return 0;
    if constexpr (std::is_same_v<T, double>)
      if (options.level == QueryLevel::boolean && certified_pays(type_a) && certified_pays(type_b))
        return run_certified(in, type_a, type_b, pairs, n, options, out, fallback);
    Lanes L;
    L.A.type = type_a;
    L.B.type = type_b;
    typename G::Rows rows;
    rows.attach(L.A, L.B);
    Source source{in, options, type_a, type_b, pairs, n, out, fallback};
    source.start_run(L);
    if (options.level == QueryLevel::boolean) G::drive_boolean(L, source, options.solver);  // start_run: all boolean
    else G::drive(L, source, options.solver, options.level >= QueryLevel::witness);
    return source.fallbacks;
  }

  /// The types whose boolean double groups run_certified() answers: those whose float GJK saves more than the
  /// certificate and the second setup cost (measured, boolean close double, 2 threads, same runs with Coal,
  /// AVX-512: box-cylinder 366 -> 222 ns/pair, cone-cone 332 -> 220, convex8 301 -> 278; but capsule-box
  /// 143 -> 206 and ellipsoid-ellipsoid 194 -> 182 with +10% instructions (1184 -> 1298, callgrind AVX2): cheap
  /// supports gain little from wider lanes). Capsule, sphere and ellipsoid groups keep the double GJK.
  /// Convex hulls are left out as well (measured at 34aca43 against main, boolean double, AVX-512, 2 threads,
  /// ns/pair: convex8 close 103.8 -> 96.2 but overlap 96.5 -> 108.9 and distant 33 -> 61; convex250 close
  /// 200 -> 195..220, overlap 271 -> 320: four double hull supports for an overlap certificate cost about what the
  /// double GJK saves).
  static constexpr bool certified_pays(ShapeType t) {
    return t == ShapeType::box || t == ShapeType::cylinder || t == ShapeType::cone;
  }

  /// The float pass of a certified boolean double run: every pair's float answer into answers[position]
  /// (kind 0 where none: answers must come zeroed). Pairs the float setup rejects are listed in `rejected`
  /// (discarded: the double pass rejects them again).
  static void run_float_answers(const PairView& in, ShapeType type_a, ShapeType type_b, const std::uint32_t* pairs,
                                std::size_t n, const QueryOptions& options, const ResultView& out,
                                std::uint32_t* rejected, FloatAnswer* answers) {
    Lanes L;
    L.A.type = type_a;
    L.B.type = type_b;
    typename G::Rows rows;
    rows.attach(L.A, L.B);
    Source source{in, options, type_a, type_b, pairs, n, out, rejected};
    source.record = answers;
    source.start_run(L);
    G::drive_boolean_directions(L, source, options.solver);
  }

  /// A boolean double query as a floating-point filter: the float GJK (twice the lanes per register) answers every
  /// pair, a double certificate (Source::certify_chunk()) accepts the answer or sends the pair to the double GJK
  /// (then it has the plain double run's status, collide and direction, and the iterations of both passes).
  /// Every answer is thus proven by a double-precision test as strong as the double GJK's own stopping test: the
  /// collide bits are the double GJK's wherever that one's proof is not itself within rounding of touching. An
  /// accepted answer's direction is the float pass's last search direction and its iterations the float pass's.
  /// The same bits on every instruction set and thread count (each lane's float run, certificate and double run
  /// are per-lane operations in a fixed order).
  static std::size_t run_certified(const PairView& in, ShapeType type_a, ShapeType type_b, const std::uint32_t* pairs,
                                   std::size_t n, const QueryOptions& options, const ResultView& out,
                                   std::uint32_t* fallback) {
    thread_local std::vector<FloatAnswer> answers;
    thread_local std::vector<std::uint32_t> rejected;
    answers.assign(n, FloatAnswer{});
    rejected.resize(n);
    WideGjkPairs<float>::run_float_answers(in, type_a, type_b, pairs, n, options, out, rejected.data(),
                                           answers.data());
    Lanes L, check;
    L.A.type = check.A.type = type_a;
    L.B.type = check.B.type = type_b;
    typename G::Rows rows, check_rows;
    rows.attach(L.A, L.B);
    check_rows.attach(check.A, check.B);
    Source source{in, options, type_a, type_b, pairs, n, out, fallback};
    source.answers = answers.data();
    source.check = &check;
    source.start_run(L);
    G::drive_boolean(L, source, options.solver);
    return source.fallbacks;
  }
};
