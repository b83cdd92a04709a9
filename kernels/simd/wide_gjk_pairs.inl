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
  template <std::size_t N> struct Slots {
    static_assert(N % std::size_t(Wd) == 0 && N % 64 == 0, "whole registers per array, whole words of bits");
    // B's pose in A's frame (R row-major, rounded to T as start_lane() took them), A's world pose for the output.
    T R[9][N], t[3][N];
    double Ra[9][N], ta[3][N];
    std::uint32_t pair[N];
    std::int64_t shape_a[N], shape_b[N];  // for the hull views
    // make_core()'s parameters, gjk_limits(), the first direction.
    T size_a[3][N], size_b[3][N], radius_a[N], radius_b[N];
    T radii[N], scale[N], floor[N], tolerance[N], core_margin[N];
    T init[3][N];
    T rim[6][N];  // rim / box-ellipsoid runs (Source::rim, box_ell): the start candidate's points of A and B, A's frame
  };
  struct Chunk : Slots<kChunk> {
    static_assert(kChunk <= 64, "one bit per slot");
    static_assert(kChunk % std::size_t(W) == 0, "whole registers of T");
    std::uint64_t left = 0;
    /// Boolean runs of primitives (gives_first()): each slot's first support point w = D.support(-init),
    /// first_points()'s, W slots per register.
    T first[3][kChunk];
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

  template <bool Given> struct SourceOf {
    /// Given: a boolean run of primitives (gives_first()), whose first support points are computed at set-up
    /// (first_points()) and given to the loop (WideGjk::GivesFirst).
    static constexpr bool gives_first = Given;
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
    /// Double distance / witness runs of a start_candidate_pair() type: the slots carry start points,
    /// rim_candidate()'s, box_round_candidate()'s or (box_ell) box_ellipsoid_candidate()'s. One flag for all where the
    /// lanes read them:
    /// a second test in load() cost boolean box-cylinder double +6 instructions per pair (callgrind, AVX2).
    bool rim = std::is_same_v<T, double> && options.level != QueryLevel::boolean && start_candidate_pair(type_a, type_b);
    bool box_ell = rim && box_ellipsoid_pair(type_a, type_b);
    /// The same for every pair of the run (gjk_limits() and the solver): set once per run in every lane by
    /// start_run(); a refill sets only what differs per pair (momentum too: the loop clears it per lane).
    Int momentum = options.solver != Solver::gjk ? Int(-1) : Int(0);
    Chunk chunk;
    LanePair lane[W];  // written by load() before done() reads it
    struct Sides {
      typename G::Side a, b;
    };
    struct NoSides {};
    [[no_unique_address]] std::conditional_t<Given, Sides, NoSides> first_sides;  // first_points()'s (types, sizes)

    // A constructor, not aggregate initialisation: that value-initialises the members it is not given, which
    // would zero the chunk's ~25 KB at every run (one run_plain() per type-pair group of a tile, a few dozen pairs
    // in a mixed batch).
    SourceOf(const PairView& in_, const QueryOptions& options_, ShapeType a, ShapeType b, const std::uint32_t* pairs_,
           std::size_t n_, const ResultView& out_, std::uint32_t* fallback_)
        : in(in_), options(options_), type_a(a), type_b(b), pairs(pairs_), n(n_), out(out_), fallback(fallback_) {
      if constexpr (Given) first_sides.a.type = a, first_sides.b.type = b;
    }

    /// The lanes' fields that are the same for every pair of the run (set_gjk_parameters()'s values):
    /// max_iterations, the relative tolerance, boolean_only, and the momentum normalisation (normalised
    /// directions unless both cores are strictly convex, ShapeCore::strictly_convex()).
    void start_run(Lanes& L) const {
      const bool normalize = !(type_a == ShapeType::ellipsoid && type_b == ShapeType::ellipsoid);
      L.max_iterations = G::splat_mask(Int(options.max_iterations));
      L.relative = G::splat(T(options.relative_tolerance));
      L.normalize = G::truth(normalize);
      L.boolean_only = G::truth(options.level == QueryLevel::boolean);
      L.rim_given = rim;
    }

    /// The next kChunk pairs, W per register: poses validated and B's pose in A's frame (prepare_pair's rule and
    /// arithmetic; invalid pairs go to the fallback), then set_gjk_parameters()'s values with the same
    /// operations.
    void fill_chunk() {
      chunk.left = 0;
      const std::size_t end = std::min(n, read + kChunk);
      fill_slots(chunk, read, end, [&](std::size_t s, std::uint32_t valid) { chunk.left |= std::uint64_t(valid) << s; });
      if constexpr (Given) first_points(end - read);
      read = end;
    }
    /// The first support point of slots [0, count), W per register: start()'s minkowski(L, -d_prev) on the values
    /// load() copies into a lane (R, t, the sizes, d_prev = init), so the same operations on the same values per
    /// lane: the same bits. In a loop pass only the ~1-2 lanes refilled since the last pass need it, so start()
    /// computed a whole register's supports for them (box-cylinder boolean float: ~85 instructions a pair, AVX2).
    /// The last register's lanes past the slots fill_slots() wrote compute on stale values, never loaded.
    void first_points(std::size_t count) {
      const Chunk& c = chunk;
      typename G::Side &side_a = first_sides.a, &side_b = first_sides.b;
      for (std::size_t s = 0; s < count; s += std::size_t(W)) {
        typename G::real R[9], t[3];
        for (int e = 0; e < 9; ++e) R[e] = lanes_at(c.R[e] + s);
        for (int i = 0; i < 3; ++i) t[i] = lanes_at(c.t[i] + s);
        side_a.s0 = lanes_at(c.size_a[0] + s), side_a.s1 = lanes_at(c.size_a[1] + s), side_a.s2 = lanes_at(c.size_a[2] + s);
        side_b.s0 = lanes_at(c.size_b[0] + s), side_b.s1 = lanes_at(c.size_b[1] + s), side_b.s2 = lanes_at(c.size_b[2] + s);
        const typename G::V3 init{lanes_at(c.init[0] + s), lanes_at(c.init[1] + s), lanes_at(c.init[2] + s)};
        typename G::V3 w, a, b;
        G::minkowski(side_a, side_b, R, t, G::neg(init), 0u, w, a, b);
        store_at(chunk.first[0] + s, w.x), store_at(chunk.first[1] + s, w.y), store_at(chunk.first[2] + s, w.z);
      }
    }
    /// fill_chunk()'s values of pairs[first .. end) into slots [0, end - first) of `chunk` (end - first <= N), Wd
    /// slots per register (the last register's lanes past `end` repeat the last pair). mark(s, bits): the valid
    /// pairs of the register at slot s; invalid pairs go to the fallback.
    template <std::size_t N, class Mark>
    void fill_slots(Slots<N>& chunk, std::size_t first, std::size_t end, const Mark& mark) {
      const T tolerance = T(options.tolerance), margin = T(options.margin);
      for (std::size_t k = first; k < end; k += Wd) {
        const std::size_t s = k - first;  // a multiple of Wd: whole registers stay inside the slots
        const auto b = P::block(pairs + first, end - first, s);
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
        if constexpr (std::is_same_v<T, double>) {
          if (rim) {
            typename G::V3 qa, qb;
            G::start_candidate(box_ell, type_a, type_b, R, t, A.size, B.size, qa, qb);
            const tvec q[6] = {qa.x, qa.y, qa.z, qb.x, qb.y, qb.z};
            for (int c = 0; c < 6; ++c) put(chunk.rim[c] + s, q[c]);
          }
        }

        const std::uint32_t valid = lane_bits(pa.valid & pb.valid) & b.live;
        mark(s, valid);
        for (std::uint32_t bad = b.live & ~valid; bad != 0; bad &= bad - 1)
          fallback[fallbacks++] = b.idx[__builtin_ctz(bad)];
      }
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
      if constexpr (Given) G::set_lane(L.first_w, l, Vec3<T>(c.first[0][s], c.first[1][s], c.first[2][s]));
      if (rim) {
        G::set_lane(L.rim_a, l, Vec3<T>(c.rim[0][s], c.rim[1][s], c.rim[2][s]));
        G::set_lane(L.rim_b, l, Vec3<T>(c.rim[3][s], c.rim[4][s], c.rim[5][s]));
      }
      L.momentum[l] = momentum;
      L.tolerance[l] = c.tolerance[s];
      L.touch[l] = c.floor[s];  // gjk_limits(): touch = floor
      L.core_margin[l] = c.core_margin[s];
      lane_pair(l, s);
      return true;
    }
    /// Lane l's LanePair (what done() reads: the pair, A's pose, the radii) from chunk slot s.
    __attribute__((always_inline)) void lane_pair(int l, std::size_t s) {
      const Chunk& c = chunk;
      LanePair& lp = lane[l];
      lp.pair = c.pair[s];
      // Whole vectors, built in registers and stored once each: element stores (GCC merged them into a 16-byte and
      // an 8-byte store per column) make put_world()'s 32-byte loads of them wait on a failed store forward.
      for (int j = 0; j < 3; ++j) lp.Ra[j] = d4{c.Ra[j][s], c.Ra[3 + j][s], c.Ra[6 + j][s], 0.0};
      if (witness) lp.ta = d4{c.ta[0][s], c.ta[1][s], c.ta[2][s], 0.0};
      lp.radius_a = c.radius_a[s];
      lp.radius_b = c.radius_b[s];
      lp.radii = c.radii[s];
      lp.scale = c.scale[s];
    }
    /// load() for the lanes of `want` at once (the boolean loop's refill on AVX-512, WideGjk::loop()): lane l takes
    /// the chunk's next valid slot in lane order, as load() lane by lane, so the same pairs go to the same lanes;
    /// the lanes that take consecutive slots get each field of Lanes by one expand load from the chunk's array
    /// instead of one scalar store per lane and field (~50 a lane: the loop's next vector reads of those fields
    /// then wait for the stores too). The lanes' LanePair and hulls are still copied lane by lane. Returns the
    /// lanes started (fewer than `want` when the run has no pairs left). Out of line as load() is: inlined into
    /// the loop it made GCC outline face_direction() from it.
    __attribute__((noinline)) std::uint32_t load_lanes(Lanes& L, std::uint32_t want) {
      std::uint32_t got = 0;
      while (want != 0) {
        while (chunk.left == 0) {
          if (read == n) return got;
          fill_chunk();
        }
        const int s = __builtin_ctzll(chunk.left);
        const std::uint64_t ends = ~(chunk.left >> s);  // its lowest bit: the end of the run of valid slots at s
        const int run = ends == 0 ? 64 : __builtin_ctzll(ends);
        std::uint32_t take = 0;  // the lowest min(run, popcount(want)) lanes of want
        int k = 0;
        for (std::uint32_t w = want; w != 0 && k < run; w &= w - 1, ++k) take |= w & (~w + 1u);
        load_run(L, take, std::size_t(s));
        chunk.left &= ~(((std::uint64_t(1) << k) - 1) << s);  // k <= W < 64
        want &= ~take;
        got |= take;
      }
      return got;
    }
    /// Slots s, s + 1, ... into the lanes of `take` in lane order: load()'s writes.
    __attribute__((always_inline)) void load_run(Lanes& L, std::uint32_t take, std::size_t s) {
      const Chunk& c = chunk;
      for (int e = 0; e < 9; ++e) L.R[e] = expand_load<T>(L.R[e], take, c.R[e] + s);
      for (int i = 0; i < 3; ++i) L.t[i] = expand_load<T>(L.t[i], take, c.t[i] + s);
      side_run(L.A, c.size_a, take, s);
      side_run(L.B, c.size_b, take, s);
      // Zero, not L.d_prev, under the lanes not taken: pick() in reset_search_lanes() drops them, and d_prev is
      // never initialised before a lane's first load.
      const typename G::real zero = G::splat(T(0));
      const typename G::V3 init{expand_load<T>(zero, take, c.init[0] + s), expand_load<T>(zero, take, c.init[1] + s),
                                expand_load<T>(zero, take, c.init[2] + s)};
      G::reset_search_lanes(L, take, init);
      if constexpr (Given)
        L.first_w = {expand_load<T>(L.first_w.x, take, c.first[0] + s), expand_load<T>(L.first_w.y, take, c.first[1] + s),
                     expand_load<T>(L.first_w.z, take, c.first[2] + s)};
      L.momentum = select(G::lanes_of(take), G::splat_mask(momentum), L.momentum);
      L.tolerance = expand_load<T>(L.tolerance, take, c.tolerance + s);
      L.touch = expand_load<T>(L.touch, take, c.floor + s);  // gjk_limits(): touch = floor
      L.core_margin = expand_load<T>(L.core_margin, take, c.core_margin + s);
      for (std::uint32_t left = take; left != 0; left &= left - 1, ++s) {
        const int l = __builtin_ctz(left);
        L.pair[l] = std::int64_t(s);
        if (L.A.type == ShapeType::convex) G::load_hull(L.A, &in.shape_hull[c.shape_a[s]], l);
        if (L.B.type == ShapeType::convex) G::load_hull(L.B, &in.shape_hull[c.shape_b[s]], l);
        lane_pair(l, s);
      }
    }
    /// side() for the lanes of `take` (slots s, s + 1, ...), hulls aside (load_run() loads them lane by lane).
    template <std::size_t N>
    __attribute__((always_inline)) static void side_run(typename G::Side& side, const T (&size)[3][N], std::uint32_t take, std::size_t s) {
      switch (side.type) {
        case ShapeType::sphere:
        case ShapeType::convex: return;
        case ShapeType::capsule: side.s1 = expand_load<T>(side.s1, take, size[1] + s); return;
        default:
          side.s0 = expand_load<T>(side.s0, take, size[0] + s);
          side.s1 = expand_load<T>(side.s1, take, size[1] + s);
          side.s2 = expand_load<T>(side.s2, take, size[2] + s);
          return;
      }
    }
    /// Slot s of one side into lane l, as load_side() takes it: the sizes of the types that have them (the
    /// support of the others reads none), the hull of a convex core. (No triangle: its pairs are not run here.)
    template <std::size_t N>
    void side(typename G::Side& side, const T (&size)[3][N], const std::int64_t* shape, std::size_t s,
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
        return;
      }
      if (status == GjkStatus::converged || status == GjkStatus::max_iterations) {
        converged(L, l, status);
        return;
      }
      if (status == GjkStatus::overlap && options.level != QueryLevel::penetration) {  // penetration: EPA below
        overlapping(L, l);
        return;
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
        return;
      }
      const Eigen::Vector3d ta(lp.ta[0], lp.ta[1], lp.ta[2]);
      write_pair_output(r, lp.rotation(), ta, lp.pair, options.level, out);
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
        Vec3<T> pa, pb;
        G::lane_witnesses(L, l, pa, pb);
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

  using Source = SourceOf<false>;
  /// Whether a run's first support points are computed at set-up (SourceOf<true>): boolean runs whose types'
  /// support reads only the side's sizes. Not hulls: a hull's support needs its rows, which only a lane's refill
  /// loads. Not distance / witness: their lanes run more passes per pair, so fewer fresh lanes share start()'s
  /// W-wide support, and the set-up would have to give A's and B's points too (witness double, callgrind AVX2,
  /// instructions a pair, with points given: box-cylinder 1930 -> 1942, cone-cone 1432 -> 1464).
  static bool gives_first(ShapeType a, ShapeType b, const QueryOptions& options) {
    const auto primitive = [](ShapeType t) { return t != ShapeType::convex && t != ShapeType::triangle; };
    return options.level == QueryLevel::boolean && primitive(a) && primitive(b);
  }

  /// Whether a group goes to run_certified() (boolean double queries of the types certified_pays() names) rather
  /// than run_plain(). The entry points (simd/isa_body.inl) put run_certified() in a translation unit of its own
  /// (it still instantiates run_plain() for the pairs it refuses; kernels/CMakeLists.txt: which copy is linked).
  static bool certifies(ShapeType type_a, ShapeType type_b, const QueryOptions& options) {
    if constexpr (std::is_same_v<T, double>)
      return options.level == QueryLevel::boolean && certified_pays(type_a) && certified_pays(type_b);
    return false;
  }
  /// Every pair through the GJK of precision T (a certified run's refused pairs too).
  static std::size_t run_plain(const PairView& in, ShapeType type_a, ShapeType type_b, const std::uint32_t* pairs,
                               std::size_t n, const QueryOptions& options, const ResultView& out,
                               std::uint32_t* fallback) {
    if (n == 0) return 0;
    Lanes L;
    L.A.type = type_a;
    L.B.type = type_b;
    typename G::Rows rows;
    rows.attach(L.A, L.B);
    if (gives_first(type_a, type_b, options)) {
      SourceOf<true> source{in, options, type_a, type_b, pairs, n, out, fallback};
      source.start_run(L);
      G::drive_boolean(L, source, options.solver);
      return source.fallbacks;
    }
    Source source{in, options, type_a, type_b, pairs, n, out, fallback};
    source.start_run(L);
    if (options.level == QueryLevel::boolean) G::drive_boolean(L, source, options.solver);  // start_run: all boolean
    else G::drive(L, source, options.solver, options.level >= QueryLevel::witness);
    return source.fallbacks;
  }

  // ---- Boolean double queries: a double gate, the float GJK, a double certificate (run_certified()) ----

  /// The types whose boolean double groups run_certified() answers. Their cores are centred at the origin (no hull
  /// centroid) and their swept radius is the inflation alone, or for spheres and capsules the inflation plus their
  /// radius (FloatFeed::load() and FloatFeed::radius() rely on both). Measured (callgrind AVX2,
  /// instructions per pair, main -> this, distant / close / overlap): ellipsoid-ellipsoid 495 -> 217, 1182 -> 955,
  /// 2186 -> 1755. Capsules and spheres end within the margin, the radius, on a segment or triangle (without a
  /// 2-3 vertex certificate capsule-box overlap was 964 -> 1700, the double GJK after the float one):
  /// certify_within() proves those, out of line (inlined, a plain-arithmetic version cost the other rows 1-2%,
  /// narrowphase-sessions.md). Left out: convex hulls (fdbl: convex8 overlap 96.5 -> 108.9 ns, convex250 overlap 271 -> 320:
  /// four double hull supports per overlap certificate; and a hull's centroid makes the float first direction
  /// differ from the double one rounded).
  static constexpr bool certified_pays(ShapeType t) {
    return t == ShapeType::box || t == ShapeType::cylinder || t == ShapeType::cone || t == ShapeType::ellipsoid ||
           rounded(t);
  }
  /// Spheres and capsules: a point or a segment swept by a radius. Their swept radius is T(inflation) + T(radius)
  /// (make_core()), so the float pass takes it from the shape table (FloatFeed::radius()); their overlaps end with
  /// the origin within the radius of a segment or triangle of D, which certify_within() proves.
  static constexpr bool rounded(ShapeType t) { return t == ShapeType::sphere || t == ShapeType::capsule; }
  /// The pairs of a certified run go through its stages a block at a time: one double setup (fill_slots()) that
  /// the gate, the float pass (converted) and the certificate all read, instead of a float and a double setup per
  /// pair (fdbl: ~140 instructions each, AVX2). 256 pairs: ~110 KB (L2); the float lanes drain at a block's end.
  static constexpr std::size_t kBlock = 256;
  struct Block : Slots<kBlock> {
    std::uint64_t valid[kBlock / 64];  // fill_slots()'s valid pairs, bit s = slot s
    std::uint64_t alive[kBlock / 64];  // the gate's survivors, bit s = slot s
    std::uint16_t list[kBlock];        // the same, by slot
    /// The float pass's answer of each survivor, by slot. kind 0: none to certify (ended otherwise than
    /// separated / overlapping: budget, convergence, stall), 1: separated along `direction` (the last search
    /// direction d, whose support point -d proved it), 2: the cores overlap or are within the margin, with the
    /// `count` simplex vertices being D's support points in the directions -vertex[m] (in simplex order).
    std::uint8_t kind[kBlock], count[kBlock];
    std::int32_t iterations[kBlock];
    float direction[3][kBlock], vertex[4][3][kBlock];
    float first[3][kBlock];  // the float pass's first support point of each survivor (float_first_points())
  };

  typedef T unaligned_real __attribute__((vector_size(sizeof(T) * W), aligned(alignof(T))));
  static typename G::real lanes_at(const T* p) { return *reinterpret_cast<const unaligned_real*>(p); }
  static void store_at(T* p, const typename G::real& v) { *reinterpret_cast<unaligned_real*>(p) = v; }

  /// Writes a certified run's own answers for the lanes `bits` of the register at slot s: converged, collide
  /// (`collide` lanes), the direction d (in A's frame) mapped to the world as LanePair::put_world() maps it (the
  /// same operations), the iterations.
  static void answer(const Block& c, std::size_t s, std::uint32_t bits, std::uint32_t collide,
                     const typename G::V3& d, const std::int32_t* iterations, const ResultView& out) {
    typename G::real world[3];
    for (int r = 0; r < 3; ++r)
      world[r] = (lanes_at(c.Ra[3 * r] + s) * d.x + lanes_at(c.Ra[3 * r + 1] + s) * d.y) +
                 lanes_at(c.Ra[3 * r + 2] + s) * d.z;
    for (; bits != 0; bits &= bits - 1) {
      const int l = __builtin_ctz(bits);
      const std::uint32_t i = c.pair[s + std::size_t(l)];
      out.status[i] = Status::converged;
      out.collide[i] = std::uint8_t(collide >> l & 1u);
      for (int r = 0; r < 3; ++r) out.direction[r][i] = world[r][l];
      out.iterations[i] = iterations[l];
    }
  }

  /// The gate, W pairs per register straight from the block's double setups: w = D.support(-d0) along the first
  /// direction d0 (the centres' offset, start_lane()'s), and the double loop's own separation test on it,
  /// <w, d0> / |d0| > core margin (ends_separated, the same operations). A pair that passes is separated, proven
  /// in double like any separated answer of the double GJK: it is answered here (collide 0, direction d0, one
  /// iteration) and runs neither GJK; the others are listed for the float pass. Distant pairs end here: one
  /// Minkowski support per pair instead of the GJK's loop (box-cylinder distant: 511 -> 232 instructions a pair,
  /// AVX2).
  static std::size_t gate(Block& c, std::size_t count, bool on, Lanes& g, const ResultView& out) {
    using V3 = typename G::V3;
    std::size_t survivors = 0;
    for (std::size_t s = 0; s < count; s += std::size_t(W)) {
      const std::uint32_t bits = std::uint32_t(c.valid[s / 64] >> (s % 64)) & ((2u << (W - 1)) - 1u);
      if (bits == 0) continue;
      for (int e = 0; e < 9; ++e) g.R[e] = lanes_at(c.R[e] + s);
      for (int i = 0; i < 3; ++i) g.t[i] = lanes_at(c.t[i] + s);
      g.A.s0 = lanes_at(c.size_a[0] + s), g.A.s1 = lanes_at(c.size_a[1] + s), g.A.s2 = lanes_at(c.size_a[2] + s);
      g.B.s0 = lanes_at(c.size_b[0] + s), g.B.s1 = lanes_at(c.size_b[1] + s), g.B.s2 = lanes_at(c.size_b[2] + s);
      const V3 d = {lanes_at(c.init[0] + s), lanes_at(c.init[1] + s), lanes_at(c.init[2] + s)};
      V3 w, sa, sb;
      G::minkowski(g, G::neg(d), bits, w, sa, sb);
      const typename G::real lb = G::dot(w, d) / G::norm(d);
      const std::uint32_t separated = on ? lane_bits(lb > lanes_at(c.core_margin + s)) & bits : 0u;
      if (separated != 0) {
        std::int32_t iterations[W];
        for (int l = 0; l < W; ++l) iterations[l] = 1;
        answer(c, s, separated, 0, d, iterations, out);
      }
      c.alive[s / 64] |= std::uint64_t(bits & ~separated) << (s % 64);
      for (std::uint32_t k = bits & ~separated; k != 0; k &= k - 1)
        c.list[survivors++] = std::uint16_t(s + std::size_t(__builtin_ctz(k)));
    }
    return survivors;
  }

  /// The float pass's first support point of the gate's survivors of a block, F::W slots per register (float
  /// lanes): FloatFeed::load()'s float values of R, t, the sizes and the first direction (each double rounded
  /// once, the direction's zero test and its x axis), then start()'s F::minkowski(-d_prev) on them: the same
  /// operations per lane as the float loop's start(), so the same bits, W lanes for all the block's survivors
  /// instead of one W-wide support per loop pass for the ~1-2 lanes refilled since the last. Registers without
  /// a survivor are skipped; lanes past the slots fill_slots() wrote compute on stale values, never loaded.
  static void float_first_points(Block& c, std::size_t count, typename WideGjk<float>::Side& A,
                                 typename WideGjk<float>::Side& B) {
    using F = WideGjk<float>;
    constexpr int FW = F::W;
    static_assert(kBlock % std::size_t(FW) == 0 && (FW <= 64 && 64 % FW == 0), "whole registers, inside a word");
    typedef double doubles __attribute__((vector_size(sizeof(double) * FW), aligned(alignof(double))));
    // (A macro's job, no lambda: a vector of 2 W doubles returned by value is an ABI warning in the SSE2 unit.)
#define BATCHCOL_NARROW(p) __builtin_convertvector(*reinterpret_cast<const doubles*>(p), typename F::real)
    for (std::size_t s = 0; s < count; s += std::size_t(FW)) {
      if ((c.alive[s / 64] >> (s % 64) & (~std::uint64_t(0) >> (64 - FW))) == 0) continue;
      typename F::real R[9], t[3];
      for (int e = 0; e < 9; ++e) R[e] = BATCHCOL_NARROW(c.R[e] + s);
      for (int i = 0; i < 3; ++i) t[i] = BATCHCOL_NARROW(c.t[i] + s);
      A.s0 = BATCHCOL_NARROW(c.size_a[0] + s), A.s1 = BATCHCOL_NARROW(c.size_a[1] + s), A.s2 = BATCHCOL_NARROW(c.size_a[2] + s);
      B.s0 = BATCHCOL_NARROW(c.size_b[0] + s), B.s1 = BATCHCOL_NARROW(c.size_b[1] + s), B.s2 = BATCHCOL_NARROW(c.size_b[2] + s);
      typename F::V3 init{BATCHCOL_NARROW(c.init[0] + s), BATCHCOL_NARROW(c.init[1] + s), BATCHCOL_NARROW(c.init[2] + s)};
      const typename F::real zero = F::splat(0.0f), one = F::splat(1.0f);
      const typename F::mask nonzero = F::norm2(init) > zero;  // FloatFeed::load()'s test, (x x + y y) + z z
      init = {F::blend(nonzero, init.x, one), F::blend(nonzero, init.y, zero), F::blend(nonzero, init.z, zero)};
      typename F::V3 w, a, b;
      F::minkowski(A, B, R, t, F::neg(init), 0u, w, a, b);
      typedef float floats __attribute__((vector_size(sizeof(float) * FW), aligned(alignof(float))));
      *reinterpret_cast<floats*>(c.first[0] + s) = w.x;
      *reinterpret_cast<floats*>(c.first[1] + s) = w.y;
      *reinterpret_cast<floats*>(c.first[2] + s) = w.z;
    }
#undef BATCHCOL_NARROW
  }

  /// The float pass's pairs (WideGjk<float>'s Source): the gate's survivors of a block, each lane's float setup
  /// converted from the block's double one, answers kept in the block by slot. The float setup's values are the
  /// float fill_slots()'s bits: R, t, the sizes, the inflations and the scale are computed in double there too and
  /// rounded once; the floor, tolerance, core margin and the zero test of the first direction are the same float
  /// operations on them; and the first direction, -t in either precision for cores centred at the origin
  /// (certified_pays()), rounds to the float one. So the float pass has solve_pair<float>'s answers.
  struct FloatFeed {
    using F = WideGjk<float>;
    static constexpr bool gives_first = true;  // float_first_points()
    Block& c;
    std::size_t count;
    float tolerance, margin;
    typename F::Int momentum;
    const PairView& in;
    bool rounded_a, rounded_b;  // rounded(type): the side's float radius comes from the shape table
    std::size_t next = 0;

    bool load(typename F::Lanes& L, int l) {
      if (next == count) return false;
      const std::size_t s = c.list[next++];
      L.pair[l] = std::int64_t(s);
      F::set_lane(L.first_w, l, Vec3<float>(c.first[0][s], c.first[1][s], c.first[2][s]));
      for (int e = 0; e < 9; ++e) L.R[e][l] = float(c.R[e][s]);
      for (int i = 0; i < 3; ++i) L.t[i][l] = float(c.t[i][s]);
      L.A.s0[l] = float(c.size_a[0][s]), L.A.s1[l] = float(c.size_a[1][s]), L.A.s2[l] = float(c.size_a[2][s]);
      L.B.s0[l] = float(c.size_b[0][s]), L.B.s1[l] = float(c.size_b[1][s]), L.B.s2[l] = float(c.size_b[2][s]);
      Vec3<float> init(float(c.init[0][s]), float(c.init[1][s]), float(c.init[2][s]));
      if (!((init.x() * init.x() + init.y() * init.y()) + init.z() * init.z() > 0.0f)) init = Vec3<float>::UnitX();
      F::reset_search(L, l, init);
      L.momentum[l] = momentum;
      const float floor = (16.0f * machine_epsilon<float>()) * float(c.scale[s]);  // tolerance_floor(scale)
      L.tolerance[l] = tolerance < floor ? floor : tolerance;
      L.touch[l] = floor;
      // The float swept radii, the float fill's radii + margin (the same operations).
      L.core_margin[l] = margin + (radius(rounded_a, c.radius_a, c.shape_a, s) + radius(rounded_b, c.radius_b, c.shape_b, s));
      return true;
    }
    /// make_core<float>()'s swept radius of one side of slot s. Boxes, cylinders, cones, ellipsoids: the inflation
    /// alone, so the block's double radius is the inflation exactly and rounds to the float fill's T(inflation).
    /// Spheres and capsules: float(inflation) + float(radius), which float(double(inflation) + double(radius))
    /// is not always, so the two are read from the shape table (two loads a side).
    float radius(bool round, const double* block_radius, const std::int64_t* shape, std::size_t s) const {
      if (!round) return float(block_radius[s]);
      const std::int64_t i = shape[s];
      return float(in.shape_inflation[i]) + float(in.shape_size[0][i]);
    }
    /// drive_boolean_directions(): vertex m's direction is in L.a[L.slot[m]]. Separated and overlapping answers
    /// are kept for the certificate; any other ending (budget, convergence, stall) leaves kind 0.
    void done(const typename F::Lanes& L, int l, GjkStatus status) {
      const std::size_t s = std::size_t(L.pair[l]);
      c.iterations[s] = std::int32_t(L.k[l]);
      const bool separated = status == GjkStatus::separated_proven;
      const bool overlapping = status == GjkStatus::collision_proven || status == GjkStatus::overlap;
      c.kind[s] = separated ? 1 : overlapping ? 2 : 0;
      c.direction[0][s] = L.direction.x[l], c.direction[1][s] = L.direction.y[l], c.direction[2][s] = L.direction.z[l];
      c.count[s] = overlapping ? std::uint8_t(L.count[l]) : 0;
      for (int m = 0; m < int(c.count[s]); ++m) {
        const int q = int(L.slot[m][l]) & 3;
        c.vertex[m][0][s] = L.a[q].x[l], c.vertex[m][1][s] = L.a[q].y[l], c.vertex[m][2][s] = L.a[q].z[l];
      }
    }
  };

  /// The proof for lanes whose float answer ended with 2 (segment) or 3 (`triangle` lanes) simplex vertices within
  /// the swept radius: p[0..2] are those vertices computed again in double (D.support(-v_m), points of the double
  /// problem's Minkowski difference of the cores, like every point the double GJK proves with). Returns the lanes
  /// where a point y* of their convex hull provably has |y*| <= `radius` (the double GJK's overlap test,
  /// max(core margin, touch)): then dist(0, D) <= radius and the shapes collide. No projection through project()
  /// (its branches and selects are the GJK's, and its result must be bitwise the reference's); instead one point
  /// of the simplex, any point, whose distance is bounded rigorously:
  ///  - weights: the segment's t = -<p0, e1> / |e1|^2, the triangle's (a, b) from the 2x2 normal equations
  ///    (Cramer), each clamped to [0, 1] (a NaN to 0). y* = p0 + a (p1 - p0) + b (p2 - p0) in exact arithmetic, with
  ///    the clamped doubles a, b, lies in the simplex iff a, b >= 0 and a + b <= 1: a + b < 1 in floating point
  ///    implies it (rounding is monotone and 1 is a double), and a + b is exact where a or b is 0 (segments: b = 0);
  ///  - y = fl(p0 + fl(a fl(p1 - p0))) + fl(b fl(p2 - p0)) differs from y* by at most ~4.1 u S per component
  ///    (u = 2^-53, S = the sum of the three terms' absolute components), so |y - y*| <= 4.1 u S; fl(|y|^2) is
  ///    |y|^2 within 3 u, and the bound c = radius - E and c^2 round by u each. Accepted iff c > 0 and fl(|y|^2)
  ///    <= fl(c c) with E = 2^-49 (S + radius) + DBL_MIN (4x the bounds above; DBL_MIN covers underflow):
  ///    |y*| <= |y| + 4.1 u S <= c (1 + 3.1 u) + 4.1 u S <= radius. NaN or infinite values fail the comparisons.
  /// Every operation is a lane-wise IEEE operation in a fixed order (no FMA: -ffp-contract=off tree-wide; no
  /// reductions, no min/max whose NaN rule could differ), so each lane's answer is the same bits at any W.
  /// Out of line, so that rows with no such lanes keep certify()'s body as it was (a plain-arithmetic certificate
  /// inlined there cost the other rows 1-2%).
  __attribute__((noinline)) static std::uint32_t certify_within(const typename G::V3 (&p)[4],
                                                                const typename G::mask& triangle,
                                                                const typename G::real& radius) {
    static_assert(std::is_same_v<T, double>, "the error bound's constants are double's");
    using V3 = typename G::V3;
    using real = typename G::real;
    using mask = typename G::mask;
    const real zero = G::splat(T(0)), one = G::splat(T(1));
    const V3 e1 = G::sub(p[1], p[0]);
    const V3 e2 = G::pick(triangle, G::sub(p[2], p[0]), V3{zero, zero, zero});
    const real d11 = G::dot(e1, e1), d12 = G::dot(e1, e2), d22 = G::dot(e2, e2);
    const real r1 = -G::dot(p[0], e1), r2 = -G::dot(p[0], e2);
    const real det = d11 * d22 - d12 * d12;
    real a = select(triangle, (d22 * r1 - d12 * r2) / det, r1 / d11);
    real b = select(triangle, (d11 * r2 - d12 * r1) / det, zero);
    a = select(a > zero, a, zero), b = select(b > zero, b, zero);  // NaN -> 0
    a = select(a < one, a, one), b = select(b < one, b, one);
    const mask in_simplex = (a + b < one) | (a == zero) | (b == zero);
    const V3 ta = G::scale(a, e1), tb = G::scale(b, e2);
    const V3 y = G::add(G::add(p[0], ta), tb);
    const real S = (magnitude(p[0]) + magnitude(ta)) + magnitude(tb);
    const real E = G::splat(T(0x1p-49)) * (S + radius) + G::splat(std::numeric_limits<T>::min());
    const real c = radius - E;
    return lane_bits(in_simplex & (c > zero) & (G::norm2(y) <= c * c));
  }

  /// |x| + |y| + |z| of each lane (certify_within()'s error bound).
  static typename G::real magnitude(const typename G::V3& v) {
    const typename G::real zero{};
    return (select(v.x < zero, -v.x, v.x) + select(v.y < zero, -v.y, v.y)) + select(v.z < zero, -v.z, v.z);
  }

  /// The certificates of the float answers of the survivors `bits` of the register at slot s, W pairs at a time in
  /// C's double lanes, read straight from the block (vector loads; the float answers widened): an accepted answer
  /// is written; a refused one (or kind 0) is appended to `refused` with its float iterations.
  ///  - separated along d: w = D.support(-d) in double (d widened), accepted iff <w, d> / |d| > core margin,
  ///    the double GJK's own test that ends a separated boolean pair (ends_separated);
  ///  - overlapping with 4 vertices: the vertices computed again in double (D.support(-v_m)), accepted iff
  ///    tetrahedron()'s signed volumes say it contains the origin (ends_contains); with one vertex: accepted iff
  ///    its norm is <= max(core margin, touch) (ends_collision, ends_overlap); with two or three: accepted iff a
  ///    point of the segment / triangle is proven within max(core margin, touch) (certify_within(), a rigorous
  ///    error bound; not project(): on fdbl a certificate through project() gave different bits in the scalar
  ///    build than in AVX2 / AVX-512, not root caused).
  /// A proven answer stands where the double GJK's differs: near touching, that GJK may stop at its tolerance
  /// (converged, collide 1 from a lower bound within the tolerance of the core margin) on a pair that is
  /// separated; the certificate accepts only a separation or an overlap it proves, so the answer is the true one
  /// there, and it is still deterministic (per-lane arithmetic). Running the double GJK after a proof to copy its
  /// tolerance answer would cost every overlap a double GJK, the cost this filter removes.
  /// The certificate's support points are points of the double problem's Minkowski difference, so an accepted
  /// answer is proven in double exactly as the double GJK proves its own; a pair within float error of touching
  /// fails it and runs the double GJK. The answer's direction is the float direction (widened), its iterations
  /// the float pass's.
  static void certify(const Block& c, std::size_t s, std::uint32_t bits, Lanes& C, const ResultView& out,
                      std::uint32_t* refused, std::int32_t* refused_iterations, std::size_t& refusals) {
    using V3 = typename G::V3;
    using real = typename G::real;
    using mask = typename G::mask;
    typedef float floats __attribute__((vector_size(sizeof(float) * W), aligned(alignof(float))));
    const auto widened = [&](const float* p) { return __builtin_convertvector(*reinterpret_cast<const floats*>(p + s), real); };
    std::uint32_t sep_bits = 0, four_bits = 0, one_bits = 0, two_bits = 0, three_bits = 0;
    for (std::uint32_t k = bits; k != 0; k &= k - 1) {
      const int l = __builtin_ctz(k);
      const std::size_t q = s + std::size_t(l);
      const std::uint32_t bit = 1u << l;
      if (c.kind[q] == 1) sep_bits |= bit;
      if (c.kind[q] == 2 && c.count[q] == 4) four_bits |= bit;
      if (c.kind[q] == 2 && c.count[q] == 1) one_bits |= bit;
      if (c.kind[q] == 2 && c.count[q] == 2) two_bits |= bit;
      if (c.kind[q] == 2 && c.count[q] == 3) three_bits |= bit;
    }
    const std::uint32_t live = sep_bits | four_bits | one_bits | two_bits | three_bits;
    std::uint32_t ok_bits = 0;
    const V3 dir = {widened(c.direction[0]), widened(c.direction[1]), widened(c.direction[2])};
    if (live != 0) {
      for (int e = 0; e < 9; ++e) C.R[e] = lanes_at(c.R[e] + s);
      for (int i = 0; i < 3; ++i) C.t[i] = lanes_at(c.t[i] + s);
      C.A.s0 = lanes_at(c.size_a[0] + s), C.A.s1 = lanes_at(c.size_a[1] + s), C.A.s2 = lanes_at(c.size_a[2] + s);
      C.B.s0 = lanes_at(c.size_b[0] + s), C.B.s1 = lanes_at(c.size_b[1] + s), C.B.s2 = lanes_at(c.size_b[2] + s);
      const real cm = lanes_at(c.core_margin + s), touch = lanes_at(c.floor + s);
      V3 v[4];
      for (int m = 0; m < 4; ++m)
        v[m] = {widened(c.vertex[m][0]), widened(c.vertex[m][1]), widened(c.vertex[m][2])};
      const mask sep = G::lanes_of(sep_bits);
      const V3 v0 = G::pick(sep, dir, v[0]);
      V3 p[4], sa, sb;
      G::minkowski(C, G::neg(v0), live, p[0], sa, sb);
      // Separated: the double GJK's ends_separated test along d.
      const real lb = G::dot(p[0], v0) / G::norm(v0);
      ok_bits = lane_bits(lb > cm) & sep_bits;
      if (one_bits != 0) {
        // The double GJK's ends_collision (|x| <= core margin) and ends_overlap (|x| <= touch) tests.
        ok_bits |= lane_bits(G::norm(p[0]) <= wmax(cm, touch)) & one_bits;
      }
      if (const std::uint32_t within = two_bits | three_bits; within != 0) {
        G::minkowski(C, G::neg(v[1]), within, p[1], sa, sb);
        if (three_bits != 0) G::minkowski(C, G::neg(v[2]), three_bits, p[2], sa, sb);
        else p[2] = p[0];  // read, not used (no triangle lane)
        ok_bits |= certify_within(p, G::lanes_of(three_bits), wmax(cm, touch)) & within;
      }
      if (four_bits != 0) {
        for (int m = 1; m < 4; ++m) G::minkowski(C, G::neg(v[m]), four_bits, p[m], sa, sb);
        // tetrahedron()'s signed volumes (project()'s operations) and its inside test: total != 0 and no volume
        // of the opposite sign (project()'s opposite_sign()).
        const real V[4] = {G::det3(p[1], p[2], p[3]), -G::det3(p[0], p[2], p[3]), G::det3(p[0], p[1], p[3]),
                           -G::det3(p[0], p[1], p[2])};
        const real total = ((V[0] + V[1]) + V[2]) + V[3];
        const real zero = G::splat(T(0));
        mask inside = total != zero;
        for (int m = 0; m < 4; ++m) inside &= ~(((V[m] > zero) & (total < zero)) | ((V[m] < zero) & (total > zero)));
        ok_bits |= lane_bits(inside) & four_bits;
      }
      if (ok_bits != 0) answer(c, s, ok_bits, ok_bits & ~sep_bits, dir, c.iterations + s, out);
    }
    for (std::uint32_t k = bits & ~ok_bits; k != 0; k &= k - 1) {
      const std::size_t q = s + std::size_t(__builtin_ctz(k));
      refused[refusals] = c.pair[q];
      refused_iterations[refusals++] = c.iterations[q];
    }
  }

  /// A boolean double query as a floating-point filter, a block of pairs at a time: their double setups
  /// (fill_slots()), the gate (gate(): pairs separated along their first direction are answered there), the float
  /// GJK (twice the lanes per register) on the others, and the double certificate of each float answer
  /// (certify()). Pairs whose float answer is refused, or that have none, run the double GJK (run_plain()) and
  /// have its status, collide and direction with the iterations of both passes. Every accepted answer is proven
  /// by a double-precision test as strong as the double GJK's own stopping test: the collide bits are the double
  /// GJK's wherever that one's proof is not itself within rounding of touching. The same bits on every
  /// instruction set and thread count (each pair's gate, float run, certificate and double run are per-lane
  /// operations in a fixed order).
  static std::size_t run_certified(const PairView& in, ShapeType type_a, ShapeType type_b, const std::uint32_t* pairs,
                                   std::size_t n, const QueryOptions& options, const ResultView& out,
                                   std::uint32_t* fallback) {
    using F = WideGjk<float>;
    thread_local Block block;
    thread_local std::vector<std::uint32_t> refused;
    thread_local std::vector<std::int32_t> refused_iterations;
    refused.resize(n);
    refused_iterations.resize(n);
    std::size_t refusals = 0;
    Source setup{in, options, type_a, type_b, pairs, n, out, fallback};
    Lanes check;  // the gate's and the certificate's lanes (R, t, the sizes, the margins)
    check.A.type = type_a;
    check.B.type = type_b;
    typename F::Lanes L;
    L.A.type = type_a;
    L.B.type = type_b;
    L.max_iterations = F::splat_mask(typename F::Int(options.max_iterations));
    L.relative = F::splat(float(options.relative_tolerance));
    L.normalize = F::truth(!(type_a == ShapeType::ellipsoid && type_b == ShapeType::ellipsoid));  // start_run()
    L.boolean_only = F::truth(true);
    typename F::Side side_a, side_b;
    side_a.type = type_a;
    side_b.type = type_b;
    FloatFeed feed{block,
                   0,
                   float(options.tolerance),
                   float(options.margin),
                   typename F::Int(options.solver != Solver::gjk ? -1 : 0),
                   in,
                   rounded(type_a),
                   rounded(type_b)};
    for (std::size_t first = 0; first < n; first += kBlock) {
      const std::size_t end = std::min(n, first + kBlock), count = end - first;
      for (std::size_t w = 0; w < kBlock / 64; ++w) block.valid[w] = block.alive[w] = 0;
      setup.fill_slots(block, first, end,
                       [&](std::size_t s, std::uint32_t v) { block.valid[s / 64] |= std::uint64_t(v) << (s % 64); });
      // No gate when the budget allows no iteration: the double GJK would end at its budget, undecided.
      const std::size_t survivors = gate(block, count, options.max_iterations >= 1, check, out);
      if (survivors == 0) continue;
      float_first_points(block, count, side_a, side_b);
      feed.count = survivors;
      feed.next = 0;
      F::drive_boolean_directions(L, feed, options.solver);
      for (std::size_t k = 0; k < count; k += std::size_t(W))
        if (const std::uint32_t bits = std::uint32_t(block.alive[k / 64] >> (k % 64)) & ((2u << (W - 1)) - 1u))
          certify(block, k, bits, check, out, refused.data(), refused_iterations.data(), refusals);
    }
    std::size_t fallbacks = setup.fallbacks;
    if (refusals == 0) return fallbacks;
    // Iterations start from 0 so that the float pass's can be added whichever way the double GJK ends (a pair
    // it leaves to the scalar fallback gets the scalar path's own there).
    for (std::size_t k = 0; k < refusals; ++k) out.iterations[refused[k]] = 0;
    fallbacks += run_plain(in, type_a, type_b, refused.data(), refusals, options, out, fallback + fallbacks);
    for (std::size_t k = 0; k < refusals; ++k) out.iterations[refused[k]] += refused_iterations[k];
    return fallbacks;
  }
};
