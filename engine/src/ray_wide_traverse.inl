// The body of the wide traversal (see ray_wide_traverse.hpp), included once per instruction set inside a
// `#pragma GCC target` region and a namespace of its own. Expects BATCHCOL_WIDE_BITS(m): the 8 lane bits of a mask,
// BATCHCOL_WIDE_MADD(a, b, c): a * b + c lane-wise (fused or not: it only meets exact products), and
// BATCHCOL_WIDE_CODES(p): the 8 bytes at p as floats (GCC scalarises __builtin_convertvector's byte-to-float form).

namespace {

typedef float V __attribute__((vector_size(32)));
typedef int M __attribute__((vector_size(32)));

inline V splat(float x) { return V{x, x, x, x, x, x, x, x}; }

// Plane p (lo_x, lo_y, lo_z, hi_x, hi_y, hi_z) of a node's 8 slots: float nodes hold them as 6 consecutive arrays;
// quantised ones dequantise (ray_wide_bvh.hpp: origin + code * scale, the product exact, so BATCHCOL_WIDE_MADD's
// fused form gives the bits of the two roundings the codes were chosen against).
template <int p> inline V plane(const WideNode* node) {
  V v;
  __builtin_memcpy(&v, reinterpret_cast<const char*>(node) + p * sizeof v, sizeof v);
  return v;
}
template <int p> inline V plane(const WideQNode* node) {
  return BATCHCOL_WIDE_MADD(BATCHCOL_WIDE_CODES(node->q[p]), splat(node->scale[p % 3]), splat(node->origin[p % 3]));
}
// The hit slots that hold a child: a float node's empty slots have the box +-inf, never hit; a quantised node's
// codes for them are no box, so its live bits decide.
inline std::uint32_t live_hits(const WideNode*, std::uint32_t bits) { return bits; }
inline std::uint32_t live_hits(const WideQNode* node, std::uint32_t bits) { return bits & node->live; }

// Ordered max / min: a NaN lane of x keeps acc (see the header).
inline V max_into(V x, V acc) { return x > acc ? x : acc; }
inline V min_into(V x, V acc) { return x < acc ? x : acc; }

// A node that was pushed is usually popped soon (after the nearer sibling's subtree, often a single leaf): on trees
// larger than the L2 (WideRay::prefetch) its four cache lines are requested now, so the loads overlap the work in
// between; on smaller trees the lines are there anyway and the requests only cost issue slots.
template <class Node> inline void prefetch_node(const Node* nodes, std::uint32_t ref) {
  if (ref & kLeafBit) return;
  const char* p = reinterpret_cast<const char*>(nodes + ref);
  for (std::size_t line = 0; line < sizeof(Node) / 64; ++line) __builtin_prefetch(p + 64 * line);
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

template <int kOctant, class Node>
void traverse_octant(const Node* nodes, const WideRay& r, float limit, WideLeafVisit visit, void* context) {
  constexpr bool neg_x = (kOctant & 1) != 0, neg_y = (kOctant & 2) != 0, neg_z = (kOctant & 4) != 0;
  constexpr int near_x = neg_x ? 3 : 0, near_y = neg_y ? 4 : 1, near_z = neg_z ? 5 : 2;  // plane<>() indices
  constexpr int far_x = neg_x ? 0 : 3, far_y = neg_y ? 1 : 4, far_z = neg_z ? 2 : 5;
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
  // Karras tree splits on a distinct bit of the 64-bit keys); a node pushes at most 8 entries after popping one.
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
      if (r.balls != nullptr && ball_misses(r.balls + 4 * std::size_t(leaf), r)) {
        if (!pop()) return;
        continue;
      }
      const bool go_on = visit(context, leaf, limit);
      lim = limit;
      lim_v = splat(lim);
      if (!go_on || !pop()) return;
      continue;
    }
    const Node* n = nodes + e.ref;
    V tn = zero;
    tn = max_into((onx - plane<near_x>(n)) * nix, tn);
    tn = max_into((ony - plane<near_y>(n)) * niy, tn);
    tn = max_into((onz - plane<near_z>(n)) * niz, tn);
    V tf = lim_v;
    tf = min_into((ofx - plane<far_x>(n)) * nix, tf);
    tf = min_into((ofy - plane<far_y>(n)) * niy, tf);
    tf = min_into((ofz - plane<far_z>(n)) * niz, tf);
    tf = tf * scale + slack;
    std::uint32_t bits = live_hits(n, BATCHCOL_WIDE_BITS((M)(tn <= tf)));
    if (bits == 0) {
      if (!pop()) return;
      continue;
    }
    const V& entry = tn;  // read lane by lane below (a copy into a float array was split and copied twice)
    // One child reached (the common case deep in the tree): it is next, no sort and no stack.
    if ((bits & (bits - 1)) == 0) {
      const int k = __builtin_ctz(bits);
      e = Entry{n->child[k], entry[k]};
      continue;
    }
    // Hit children sorted by entry; all but the nearest pushed farthest first, the nearest processed next. Ties
    // keep the slot order (the sort is stable), so the order is a function of the node and the ray only.
    // Two children (half of the nodes with several hits) need one comparison, not the general loop below; the
    // order is the same (the lower slot first unless the other one is strictly nearer).
    const std::uint32_t rest = bits & (bits - 1);
    if ((rest & (rest - 1)) == 0) {
      const int k0 = __builtin_ctz(bits), k1 = __builtin_ctz(rest);
      const bool swap = entry[k1] < entry[k0];
      const int near = swap ? k1 : k0, far = swap ? k0 : k1;
      stack[top++] = Entry{n->child[far], entry[far]};
      if (r.prefetch) prefetch_node(nodes, n->child[far]);
      e = Entry{n->child[near], entry[near]};
      continue;
    }
    // Three or more: each hit child's rank in that order, counted without branches on the data: the hit children
    // strictly nearer, plus the equally near ones in lower slots (entries are never NaN: tn starts at 0 and the
    // ordered max drops NaN). Rank 0 is next; rank j >= 1 goes j places below the new top, so the stack pops them
    // nearest first, exactly as the stable sort this replaces (and the same on every instruction set).
    const int count = __builtin_popcount(bits);
    Entry* const base = stack + top + count - 1;
    for (std::uint32_t b = bits; b != 0; b &= b - 1) {
      const int k = __builtin_ctz(b);
      const float t = entry[k];
      const V tk = splat(t);
      const std::uint32_t nearer = BATCHCOL_WIDE_BITS((M)(tn < tk)), same = BATCHCOL_WIDE_BITS((M)(tn == tk));
      const int rank = __builtin_popcount(bits & (nearer | (same & ((1u << k) - 1u))));
      base[-rank] = Entry{n->child[k], t};
      if (r.prefetch && rank != 0) prefetch_node(nodes, n->child[k]);
    }
    top += count - 1;
    e = stack[top];  // rank 0: the nearest child next, without a trip through the stack
  }
}
}  // namespace

template <class Node>
void traverse_nodes(const Node* nodes, const WideRay& r, float limit, WideLeafVisit visit, void* context) {
  // The octant is read back from the near planes make_wide_ray() chose (hi: a negative component).
  const int octant = (r.near_offset[0] == offsetof(WideNode, hi_x) ? 1 : 0) |
                     (r.near_offset[1] == offsetof(WideNode, hi_y) ? 2 : 0) |
                     (r.near_offset[2] == offsetof(WideNode, hi_z) ? 4 : 0);
  switch (octant) {
    case 0: return traverse_octant<0, Node>(nodes, r, limit, visit, context);
    case 1: return traverse_octant<1, Node>(nodes, r, limit, visit, context);
    case 2: return traverse_octant<2, Node>(nodes, r, limit, visit, context);
    case 3: return traverse_octant<3, Node>(nodes, r, limit, visit, context);
    case 4: return traverse_octant<4, Node>(nodes, r, limit, visit, context);
    case 5: return traverse_octant<5, Node>(nodes, r, limit, visit, context);
    case 6: return traverse_octant<6, Node>(nodes, r, limit, visit, context);
    default: return traverse_octant<7, Node>(nodes, r, limit, visit, context);
  }
}

void traverse(const WideNode* nodes, const WideRay& r, float limit, WideLeafVisit visit, void* context) {
  traverse_nodes(nodes, r, limit, visit, context);
}
void traverse_quantized(const WideQNode* nodes, const WideRay& r, float limit, WideLeafVisit visit, void* context) {
  traverse_nodes(nodes, r, limit, visit, context);
}
