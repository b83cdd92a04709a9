// The body of the wide traversal (see ray_wide_traverse.hpp), included once per instruction set inside a
// `#pragma GCC target` region and a namespace of its own. Expects BATCHCOL_WIDE_BITS(m): the 8 lane bits of a mask.

namespace {

typedef float V __attribute__((vector_size(32)));
typedef int M __attribute__((vector_size(32)));

inline V splat(float x) { return V{x, x, x, x, x, x, x, x}; }

inline V load_at(const WideNode* node, std::uint32_t byte_offset) {
  V v;
  __builtin_memcpy(&v, reinterpret_cast<const char*>(node) + byte_offset, sizeof v);
  return v;
}

// Ordered max / min: a NaN lane of x keeps acc (see the header).
inline V max_into(V x, V acc) { return x > acc ? x : acc; }
inline V min_into(V x, V acc) { return x < acc ? x : acc; }

// A node that was pushed is usually popped soon (after the nearer sibling's subtree, often a single leaf): on trees
// larger than the L2 (WideRay::prefetch) its four cache lines are requested now, so the loads overlap the work in
// between; on smaller trees the lines are there anyway and the requests only cost issue slots.
inline void prefetch_node(const WideNode* nodes, std::uint32_t ref) {
  if (ref & kLeafBit) return;
  const char* p = reinterpret_cast<const char*>(nodes + ref);
  for (int line = 0; line < 4; ++line) __builtin_prefetch(p + 64 * line);
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

void traverse(const WideNode* nodes, const WideRay& r, float limit, WideLeafVisit visit, void* context) {
  const V onx = splat(r.o_near[0]), ony = splat(r.o_near[1]), onz = splat(r.o_near[2]);
  const V ofx = splat(r.o_far[0]), ofy = splat(r.o_far[1]), ofz = splat(r.o_far[2]);
  const V ix = splat(r.inv[0]), iy = splat(r.inv[1]), iz = splat(r.inv[2]);
  const V zero = splat(0.0f), scale = splat(kFarScale), slack = splat(kFarSlack);
  // Each wide level descends at least one level of the binary tree, whose depth is at most 64 (every level of a
  // Karras tree splits on a distinct bit of the 64-bit keys); a node pushes at most 8 entries after popping one.
  Entry stack[64 * (kWideArity - 1) + 2];
  int top = 0;
  Entry e{0u, 0.0f};  // the root
  // The next entry still within reach (a closer hit may have been found since it was pushed); false when none.
  const auto pop = [&] {
    do {
      if (top == 0) return false;
      e = stack[--top];
    } while (e.t > limit);
    return true;
  };
  for (;;) {
    if (e.ref & kLeafBit) {
      const std::uint32_t leaf = e.ref & ~kLeafBit;
      if (r.balls != nullptr && ball_misses(r.balls + 4 * std::size_t(leaf), r)) {
        if (!pop()) return;
        continue;
      }
      if (!visit(context, leaf, limit) || !pop()) return;
      continue;
    }
    const WideNode* n = nodes + e.ref;
    V tn = zero;
    tn = max_into((load_at(n, r.near_offset[0]) - onx) * ix, tn);
    tn = max_into((load_at(n, r.near_offset[1]) - ony) * iy, tn);
    tn = max_into((load_at(n, r.near_offset[2]) - onz) * iz, tn);
    V tf = splat(limit);
    tf = min_into((load_at(n, r.far_offset[0]) - ofx) * ix, tf);
    tf = min_into((load_at(n, r.far_offset[1]) - ofy) * iy, tf);
    tf = min_into((load_at(n, r.far_offset[2]) - ofz) * iz, tf);
    tf = tf * scale + slack;
    std::uint32_t bits = BATCHCOL_WIDE_BITS((M)(tn <= tf));
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
    Entry hit[kWideArity];
    int count = 0;
    while (bits != 0) {
      const int k = __builtin_ctz(bits);
      bits &= bits - 1;
      Entry x{n->child[k], entry[k]};
      int j = count++;
      for (; j > 0 && hit[j - 1].t > x.t; --j) hit[j] = hit[j - 1];
      hit[j] = x;
    }
    for (int j = count - 1; j >= 1; --j) {
      stack[top++] = hit[j];
      if (r.prefetch) prefetch_node(nodes, hit[j].ref);
    }
    e = hit[0];  // the nearest child next, without a trip through the stack
  }
}
