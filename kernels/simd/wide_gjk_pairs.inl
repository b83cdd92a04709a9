// GJK pairs straight from the batch arrays: the executor's per-pair work (pose validation, B's pose in A's frame,
// the setup, completion, the world-frame output) done without a PairSetup per pair. Poses are validated and the
// relative poses computed W pairs per register in double (PairLanes), a chunk at a time; each lane then takes its
// pair's shapes and parameters from those arrays when it is refilled, runs WideGjk's loop, and writes its answer
// into the result arrays. Every operation is the executor's scalar path's (prepare_pair's arithmetic, make_core,
// set_gjk_parameters, complete_from_gjk, write_pair_output), in the same order, so the results are the same bits
// (tested in tests/engine/executor_gjk_pairs_test.cpp); pairs that need more (invalid input, a float stall redone
// in double) go back to that path.
//
// No include guard: included once per instruction set by isa_body.inl, after wide_gjk.inl and wide_pairs.inl.

template <class T> struct WideGjkPairs {
  using G = WideGjk<T>;
  using Lanes = typename G::Lanes;
  using P = PairLanes;
  static constexpr int W = G::W;
  static constexpr int Wd = P::W;
  /// Pairs whose relative poses are computed ahead of the lanes: a few KB, in L1.
  static constexpr std::size_t kChunk = 64;

  /// Valid pairs of the current chunk, in double: B's pose in A's frame and A's world pose (row-major).
  /// Written before read: fill_chunk() sets count and the first count entries.
  struct Chunk {
    double R[9][kChunk], t[3][kChunk], Ra[9][kChunk], ta[3][kChunk];
    std::uint32_t pair[kChunk], shape_a[kChunk], shape_b[kChunk];
    std::size_t count = 0;
  };

  /// What a lane keeps of its pair until it finishes: where the answer goes and how it is completed.
  struct LanePair {
    std::uint32_t pair = 0;
    Eigen::Matrix3d Ra;
    Eigen::Vector3d ta;
    GjkCompletion<T> completion;
  };

  struct Source {
    const PairView& in;
    const QueryOptions& options;
    ShapeType type_a, type_b;
    const std::uint32_t* pairs;
    std::size_t n;
    const ResultView& out;
    std::uint32_t* fallback;
    std::size_t fallbacks = 0;
    std::size_t read = 0;  // pairs[0 .. read) went through the pose stage
    std::size_t next = 0;  // chunk slot the next load takes
    Chunk chunk;
    LanePair lane[W];  // written by load() before done() reads it
    /// Normalised momentum directions unless both cores are strictly convex (ShapeCore::strictly_convex()).
    bool normalize = !(type_a == ShapeType::ellipsoid && type_b == ShapeType::ellipsoid);

    // A constructor, not aggregate initialisation: that value-initialises the members it is not given, which
    // would zero the chunk's 13 KB at every run() (one run() per type-pair group of a tile, a few dozen pairs in a
    // mixed batch).
    Source(const PairView& in_, const QueryOptions& options_, ShapeType a, ShapeType b, const std::uint32_t* pairs_,
           std::size_t n_, const ResultView& out_, std::uint32_t* fallback_)
        : in(in_), options(options_), type_a(a), type_b(b), pairs(pairs_), n(n_), out(out_), fallback(fallback_) {}

    /// Validates the next kChunk pairs and computes their poses, W per register (prepare_pair's rule and
    /// arithmetic); invalid ones go to the fallback.
    void fill_chunk() {
      chunk.count = 0;
      next = 0;
      const std::size_t end = std::min(n, read + kChunk);
      for (std::size_t k = read; k < end; k += Wd) {
        const auto b = P::block(pairs + read, end - read, k - read);
        P::Pose pa = load(b, true), pb = load(b, false);
        P::normalize(pa);
        P::normalize(pb);
        const P::V3 ca[3] = {P::column(pa, 0), P::column(pa, 1), P::column(pa, 2)};
        const P::V3 cb[3] = {P::column(pb, 0), P::column(pb, 1), P::column(pb, 2)};
        const P::V3 d = P::sub(pb.t, pa.t);
        typename P::real R[9], t[3];
        for (int i = 0; i < 3; ++i) {
          for (int j = 0; j < 3; ++j) R[3 * i + j] = P::dot(ca[i], cb[j]);
          t[i] = P::dot(ca[i], d);
        }
        const std::uint32_t valid = lane_bits(pa.valid & pb.valid);
        for (int l = 0; l < b.lanes; ++l) {
          const std::uint32_t i = b.idx[l];
          if (!(valid >> l & 1u)) {
            fallback[fallbacks++] = i;
            continue;
          }
          const std::size_t s = chunk.count++;
          chunk.pair[s] = i;
          chunk.shape_a[s] = in.shape_a[i];
          chunk.shape_b[s] = in.shape_b[i];
          for (int e = 0; e < 9; ++e) chunk.R[e][s] = R[e][l];
          chunk.ta[0][s] = pa.t.x[l], chunk.ta[1][s] = pa.t.y[l], chunk.ta[2][s] = pa.t.z[l];
          for (int c = 0; c < 3; ++c) {
            chunk.t[c][s] = t[c][l];
            const P::V3& col = ca[c];  // column c of Ra: entries (0, c), (1, c), (2, c)
            chunk.Ra[c][s] = col.x[l], chunk.Ra[3 + c][s] = col.y[l], chunk.Ra[6 + c][s] = col.z[l];
          }
        }
      }
      read = end;
    }
    P::Pose load(const typename P::Block& b, bool side_a) const {
      return P::load_pose(in, side_a ? in.shape_a : in.shape_b, side_a ? in.translation_a : in.translation_b,
                          side_a ? in.rotation_a : in.rotation_b, b.idx, b.consecutive);
    }

    /// One side's core as make_core() builds it, read straight from the ShapeTable's per-shape arrays (no
    /// ShapeCore, no PairSetup: building those per pair was a fifth of an ellipsoid pair's work). `radius` gets the
    /// swept radius with make_core's roundings: T(inflation), plus T(radius) for spheres and capsules.
    static typename G::SideStart side(const PairView& in, std::uint32_t shape, T& radius) {
      typename G::SideStart c{{T(0), T(0), T(0)}, nullptr, nullptr};
      radius = T(in.shape_inflation[shape]);
      switch (in.shape_type[shape]) {
        case ShapeType::sphere: radius += T(in.shape_size[0][shape]); break;
        case ShapeType::capsule:
          radius += T(in.shape_size[0][shape]);
          c.size[1] = T(in.shape_size[1][shape]);
          break;
        case ShapeType::convex: c.hull = &in.shape_hull[shape]; break;
        default:
          for (int i = 0; i < 3; ++i) c.size[i] = T(in.shape_size[i][shape]);
          break;
      }
      return c;
    }
    /// ShapeCore::center() of a core (the hull's centroid, the origin for the other types in this path).
    static Vec3<T> center(const typename G::SideStart& c) {
      return c.hull ? hull_centroid<T>(*c.hull) : Vec3<T>::Zero();
    }

    /// setup_pair_into() and set_gjk_parameters() for a pair without closed form or warm start (the same
    /// gjk_limits(), make_core's radii and centre arithmetic), then WideGjk's start_lane().
    bool load(Lanes& L, int l) {
      while (next == chunk.count) {
        if (read == n) return false;
        fill_chunk();
      }
      const std::size_t s = next++;
      const std::uint32_t ia = chunk.shape_a[s], ib = chunk.shape_b[s];
      typename G::LaneStart q;
      T radius_a, radius_b;
      q.A = side(in, ia, radius_a);
      q.B = side(in, ib, radius_b);
      for (int e = 0; e < 9; ++e) q.R[e] = T(chunk.R[e][s]);
      const double tx = chunk.t[0][s], ty = chunk.t[1][s], tz = chunk.t[2][s];
      q.t[0] = T(tx), q.t[1] = T(ty), q.t[2] = T(tz);
      // |t| as norm3() computes it in setup_pair_into().
      const GjkLimits<T> g = gjk_limits<T>(radius_a, radius_b, in.bounding_radii[ia], in.bounding_radii[ib],
                                           std::sqrt((tx * tx + ty * ty) + tz * tz), options);
      q.tolerance = g.tolerance;
      q.relative = g.relative;
      q.max_iterations = g.max_iterations;
      q.momentum = options.solver != Solver::gjk;
      q.normalize = normalize;
      q.boolean_only = g.boolean_only;
      q.core_margin = g.core_margin;
      q.touch = g.touch;
      // MinkowskiDifference::center(): A's centre minus B's centre mapped into A's frame (mul()'s association).
      const Vec3<T> cb = center(q.B);
      const T* R = q.R;
      const Vec3<T> b_center((R[0] * cb.x() + R[1] * cb.y()) + R[2] * cb.z() + q.t[0],
                             (R[3] * cb.x() + R[4] * cb.y()) + R[5] * cb.z() + q.t[1],
                             (R[6] * cb.x() + R[7] * cb.y()) + R[8] * cb.z() + q.t[2]);
      q.initial_direction = center(q.A) - b_center;
      G::start_lane(L, l, q, std::int64_t(s));

      LanePair& lp = lane[l];
      lp.pair = chunk.pair[s];
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) lp.Ra(i, j) = chunk.Ra[3 * i + j][s];
        lp.ta[i] = chunk.ta[i][s];
      }
      lp.completion = {radius_a, radius_b, g.radii, g.scale, g.floor, g.tolerance, g.core_margin};
      return true;
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
        const Eigen::Vector3d d = mul<double>(lp.Ra, G::get_lane(L.direction, l).template cast<double>());
        for (int c = 0; c < 3; ++c) out.direction[c][i] = d[c];
        out.iterations[i] = int(L.k[l]);
        return;
      }
      GjkResult<T> g;
      G::finish(L, l, status, g, options.level >= QueryLevel::witness);
      const LanePair& lp = lane[l];
      PairOutput<T> r;
      if (!complete_from_gjk(lp.completion, g, options, r)) {
        fallback[fallbacks++] = lp.pair;
        return;
      }
      write_pair_output(r, lp.Ra, lp.ta, lp.pair, options.level, out);
    }
  };

  static std::size_t run(const PairView& in, ShapeType type_a, ShapeType type_b, const std::uint32_t* pairs,
                         std::size_t n, const QueryOptions& options, const ResultView& out, std::uint32_t* fallback) {
    if (n == 0) return 0;
    Lanes L;
    L.A.type = type_a;
    L.B.type = type_b;
    typename G::Rows rows;
    rows.attach(L.A, L.B);
    Source source{in, options, type_a, type_b, pairs, n, out, fallback};
    G::drive(L, source, options.solver, options.level >= QueryLevel::witness);
    return source.fallbacks;
  }
};
