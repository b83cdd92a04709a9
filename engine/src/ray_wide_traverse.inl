// The body of the wide traversal (see ray_wide_traverse.hpp), included once per instruction set inside a
// `#pragma GCC target` region and a namespace of its own. Expects BATCHCOL_WIDE_VLANES (the lanes of one vector:
// 16 or 8) and BATCHCOL_WIDE_LE(a, b) / BATCHCOL_WIDE_ILT(a, b): the lane bits of float a <= b and of signed 32-bit
// a < b (the comparison straight to a mask: on AVX-512 a vector compare, a vector mask and its bits cost three steps).
// The includer undefines them after ray_wide_packet.inl, which uses them too.

namespace {

// A node's 16 slots are tested in kParts vectors of kVLanes floats: one 16-lane vector on AVX-512, two 8-lane halves
// elsewhere (the same IEEE operations lane by lane, so the same bits on every set).
constexpr int kVLanes = BATCHCOL_WIDE_VLANES;
constexpr int kParts = kWideArity / kVLanes;
typedef float V __attribute__((vector_size(4 * kVLanes)));
typedef std::int32_t VI __attribute__((vector_size(4 * kVLanes)));

// A broadcast (a lane-by-lane loop became 16 masked broadcasts on AVX-512).
#if BATCHCOL_WIDE_VLANES == 16
inline V splat(float x) { return V{x, x, x, x, x, x, x, x, x, x, x, x, x, x, x, x}; }
inline VI splat_int(std::int32_t x) { return VI{x, x, x, x, x, x, x, x, x, x, x, x, x, x, x, x}; }
#else
inline V splat(float x) { return V{x, x, x, x, x, x, x, x}; }
inline VI splat_int(std::int32_t x) { return VI{x, x, x, x, x, x, x, x}; }
#endif

// kLowerOnes[k][j] = 1 for the slots j below k: the rank loop's tie rule as one integer subtraction (below).
struct LowerOnes {
  alignas(64) std::int32_t row[kWideArity][kWideArity];
  constexpr LowerOnes() : row{} {
    for (int k = 0; k < kWideArity; ++k)
      for (int j = 0; j < kWideArity; ++j) row[k][j] = j < k ? 1 : 0;
  }
};
constexpr LowerOnes kLowerOnes;

inline VI load_int(const std::int32_t* p) {
  VI v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}

inline V load_at(const WideNode* node, std::size_t byte_offset) {
  V v;
  __builtin_memcpy(&v, reinterpret_cast<const char*>(node) + byte_offset, sizeof v);
  return v;
}

// Ordered max / min: a NaN lane of x keeps acc (see the header).
inline V max_into(V x, V acc) { return x > acc ? x : acc; }
inline V min_into(V x, V acc) { return x < acc ? x : acc; }

// A child that was pushed is usually popped soon (after the nearer sibling's subtree, often a single leaf): on trees
// larger than the L2 (WideRay::prefetch) its cache lines are requested now, so the loads overlap the work in
// between; on smaller trees the lines are there anyway and the requests only cost issue slots. A node's seven lines;
// for a leaf with balls, the two lines of its record from the ball on (the caller's leaf records hold the ball and
// the object together: ray_scene_state.hpp).
// Always inlined: GCC 12 at -O1 and up found this function (prefetches only) free of side effects when it was not
// inlined, and deleted its calls: main at 044e99e issued none of these requests (objdump: no
// prefetch instruction in any traversal).
[[gnu::always_inline]] inline void prefetch_child(const WideNode* nodes, std::uint32_t ref, const WideRay& r) {
  if (ref & kLeafBit) {
    if (r.balls == nullptr) return;
    const char* p = reinterpret_cast<const char*>(r.balls + std::size_t(r.ball_stride) * (ref & ~kLeafBit));
    __builtin_prefetch(p), __builtin_prefetch(p + 64);
    return;
  }
  const char* p = reinterpret_cast<const char*>(nodes + ref);
  for (int line = 0; line < 7; ++line) __builtin_prefetch(p + 64 * line);
}

// True when the ray's line passes the leaf's ball farther than its radius plus the margins (ray_wide_traverse.hpp).
inline bool ball_misses(const float* b, const WideRay& r) {
  const float x = b[0] - r.ball_o[0], y = b[1] - r.ball_o[1], z = b[2] - r.ball_o[2];
  const float cx = y * r.ball_d[2] - z * r.ball_d[1], cy = z * r.ball_d[0] - x * r.ball_d[2],
              cz = x * r.ball_d[1] - y * r.ball_d[0];
  const float radius =
      b[3] + r.ball_margin + kBallMargin * (__builtin_fabsf(x) + __builtin_fabsf(y) + __builtin_fabsf(z));
  return cx * cx + cy * cy + cz * cz > radius * radius;
}

struct Entry {
  std::uint32_t ref;
  float t;
};

}  // namespace

// The loop for one octant of ray directions (bit k of kOctant: the direction's component k is negative, -0
// included, as in make_wide_ray()): which of a node's lo / hi arrays is the near and which the far plane is then a
// constant offset, so each plane is one subtraction with a memory operand, and the ray's offsets stay out of the
// registers the loop needs. The parameter is computed as (o - plane) * (-inv): round-to-nearest is symmetric, so
// fl(o - p) = -fl(p - o) and fl(-a * -b) = fl(a * b): the value of the header's (plane - o) * inv (only a zero may
// come out with the other sign, which no comparison below sees), so the visiting order is the one before and the
// same on every instruction set.
namespace {

template <int kOctant>
void traverse_octant(const WideNode* nodes, const WideRay& r, float limit, WideLeafVisit visit, void* context) {
  constexpr bool neg_x = (kOctant & 1) != 0, neg_y = (kOctant & 2) != 0, neg_z = (kOctant & 4) != 0;
  constexpr std::size_t near_x = neg_x ? offsetof(WideNode, hi_x) : offsetof(WideNode, lo_x);
  constexpr std::size_t near_y = neg_y ? offsetof(WideNode, hi_y) : offsetof(WideNode, lo_y);
  constexpr std::size_t near_z = neg_z ? offsetof(WideNode, hi_z) : offsetof(WideNode, lo_z);
  constexpr std::size_t far_x = neg_x ? offsetof(WideNode, lo_x) : offsetof(WideNode, hi_x);
  constexpr std::size_t far_y = neg_y ? offsetof(WideNode, lo_y) : offsetof(WideNode, hi_y);
  constexpr std::size_t far_z = neg_z ? offsetof(WideNode, lo_z) : offsetof(WideNode, hi_z);
  const V onx = splat(r.o_near[0]), ony = splat(r.o_near[1]), onz = splat(r.o_near[2]);
  const V ofx = splat(r.o_far[0]), ofy = splat(r.o_far[1]), ofz = splat(r.o_far[2]);
  const V nix = splat(-r.inv[0]), niy = splat(-r.inv[1]), niz = splat(-r.inv[2]);
  const V scale = splat(kFarScale), slack = splat(kFarSlack);
  // The compiler is not told that `zero` is 0: knowing it, it turns the first max_into() into a compare and a mask
  // (two instructions) instead of one ordered max, the same value.
  float zero_scalar = 0.0f;
  __asm__("" : "+x"(zero_scalar));
  const V zero = splat(zero_scalar);
  // Each wide level descends at least one level of the binary tree, whose depth is at most 64 (every level of a
  // Karras tree splits on a distinct bit of the 64-bit keys); a node pushes at most kWideArity - 1 entries after popping one.
  Entry stack[64 * (kWideArity - 1) + 2];
  int top = 0;
  Entry e{0u, 0.0f};  // the root
  // `limit` lives in memory (visit() may lower it through its address); `lim` and `lim_v` are its copies for the
  // loop, refreshed after every visit, so the node test neither reloads nor broadcasts it.
  float lim = limit;
  V lim_v = splat(lim);
  // The next entry still within reach (a closer hit may have been found since it was pushed); false when none.
  const auto pop = [&] {
    do {
      if (top == 0) return false;
      e = stack[--top];
    } while (e.t > lim);
    return true;
  };
  for (;;) {
    if (e.ref & kLeafBit) {
      const std::uint32_t leaf = e.ref & ~kLeafBit;
      if (r.balls != nullptr && ball_misses(r.balls + std::size_t(r.ball_stride) * leaf, r)) {
        if (!pop()) return;
        continue;
      }
      const bool go_on = visit(context, leaf, limit);
      lim = limit;
      lim_v = splat(lim);
      if (!go_on || !pop()) return;
      continue;
    }
    const WideNode* n = nodes + e.ref;
    V tn[kParts];
    std::uint32_t bits = 0;
    for (int p = 0; p < kParts; ++p) {
      const std::size_t at = sizeof(V) * std::size_t(p);
      V a = zero;
      a = max_into((onx - load_at(n, near_x + at)) * nix, a);
      a = max_into((ony - load_at(n, near_y + at)) * niy, a);
      a = max_into((onz - load_at(n, near_z + at)) * niz, a);
      V f = lim_v;
      f = min_into((ofx - load_at(n, far_x + at)) * nix, f);
      f = min_into((ofy - load_at(n, far_y + at)) * niy, f);
      f = min_into((ofz - load_at(n, far_z + at)) * niz, f);
      f = f * scale + slack;
      tn[p] = a;
      bits |= BATCHCOL_WIDE_LE(a, f) << (kVLanes * p);
    }
    if (bits == 0) {
      if (!pop()) return;
      continue;
    }
    // Read lane by lane below (a copy into a float array was split and copied twice); slot k is float k of the
    // parts, which lie one after the other (tn[k / kVLanes][k % kVLanes] cost 4 more instructions a read on AVX2).
    const auto entry = [&tn](std::size_t k) {
      float t;
      __builtin_memcpy(&t, reinterpret_cast<const char*>(tn) + sizeof(float) * k, sizeof t);
      return t;
    };
    // One child reached (the common case deep in the tree): it is next, no sort and no stack.
    if ((bits & (bits - 1)) == 0) {
      const int k = __builtin_ctz(bits);
      e = Entry{n->child[k], entry(std::size_t(k))};
      continue;
    }
    // Hit children sorted by entry; all but the nearest pushed farthest first, the nearest processed next. Ties
    // keep the slot order (the sort is stable), so the order is a function of the node and the ray only.
    // Two children (half of the nodes with several hits) need one comparison, not the general loop below; the
    // order is the same (the lower slot first unless the other one is strictly nearer).
    const std::uint32_t rest = bits & (bits - 1);
    if ((rest & (rest - 1)) == 0) {
      const int k0 = __builtin_ctz(bits), k1 = __builtin_ctz(rest);
      const bool swap = entry(std::size_t(k1)) < entry(std::size_t(k0));
      const int near = swap ? k1 : k0, far = swap ? k0 : k1;
      stack[top++] = Entry{n->child[far], entry(std::size_t(far))};
      if (r.prefetch) prefetch_child(nodes, n->child[far], r);
      e = Entry{n->child[near], entry(std::size_t(near))};
      continue;
    }
    // Three or more: each hit child's rank in that order, counted without branches on the data: the hit children
    // strictly nearer, plus the equally near ones in lower slots (entries are never NaN: tn starts at 0 and the
    // ordered max drops NaN). Rank 0 is next; rank j >= 1 goes j places below the new top, so the stack pops them
    // nearest first, exactly as the stable sort this replaces (and the same on every instruction set).
    // One comparison a part, in integers: entries are +0 or positive floats or +inf (never -0: the ordered max keeps
    // the +0 it starts from against -0; never NaN), whose bit patterns order as the values, so "t_j < t_k, or
    // t_j = t_k and j < k" is bits_j - [j < k] < bits_k (bits_j = 0 gives -1: below every bits_k, as j's entry is).
    // [j < k] comes from a table (kLowerOnes); slot and rank are 64-bit counts (no sign extension before they
    // index). Was two float comparisons a part and a lower-slot mask: 24 -> 20 instructions a child on AVX-512,
    // 33 -> 27 on AVX2 (its two halves), with the flat entry read above.
    const int count = __builtin_popcount(bits);
    Entry* const base = stack + top + count - 1;
    VI tn_bits[kParts];
    __builtin_memcpy(tn_bits, tn, sizeof tn_bits);
    for (std::uint64_t b = bits; b != 0; b &= b - 1) {
      const std::size_t k = std::size_t(__builtin_ctzll(b));
      const float t = entry(k);
      std::int32_t t_bits;
      __builtin_memcpy(&t_bits, &t, sizeof t_bits);
      const VI tk = splat_int(t_bits);
      std::uint32_t nearer = 0;
      for (int p = 0; p < kParts; ++p)
        nearer |= BATCHCOL_WIDE_ILT(tn_bits[p] - load_int(kLowerOnes.row[k] + kVLanes * p), tk) << (kVLanes * p);
      const std::ptrdiff_t rank = __builtin_popcountll(std::uint64_t(bits & nearer));
      base[-rank] = Entry{n->child[k], t};
      if (r.prefetch && rank != 0) prefetch_child(nodes, n->child[k], r);
    }
    top += count - 1;
    e = stack[top];  // rank 0: the nearest child next, without a trip through the stack
  }
}
}  // namespace

void traverse(const WideNode* nodes, const WideRay& r, float limit, WideLeafVisit visit, void* context) {
  switch (r.octant) {
    case 0: return traverse_octant<0>(nodes, r, limit, visit, context);
    case 1: return traverse_octant<1>(nodes, r, limit, visit, context);
    case 2: return traverse_octant<2>(nodes, r, limit, visit, context);
    case 3: return traverse_octant<3>(nodes, r, limit, visit, context);
    case 4: return traverse_octant<4>(nodes, r, limit, visit, context);
    case 5: return traverse_octant<5>(nodes, r, limit, visit, context);
    case 6: return traverse_octant<6>(nodes, r, limit, visit, context);
    default: return traverse_octant<7>(nodes, r, limit, visit, context);
  }
}
