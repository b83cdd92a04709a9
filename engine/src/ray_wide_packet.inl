// The packet traversal of the wide BVH (ray_wide_traverse.hpp: WidePacketTraverse), included after
// ray_wide_traverse.inl in each instruction set's namespace (it uses that file's vector types and helpers), with
// BATCHCOL_WIDE_LE8(a, b): the lane bits of a <= b for 8 floats.
// Up to kWidePacketLanes rays of one direction octant walk the tree together: a node is popped once for the packet and
// tested for each of its active rays (the same float slab test as the one-ray loop, ray by ray, so each ray's hit
// children and entries are that loop's bits); the children any active ray reaches are visited nearest first by the
// smallest entry over the rays reaching them (ties to the lower slot), each with the mask of the rays that reach it
// and that smallest entry; a popped entry keeps the rays whose limit is not below it (a ray whose own entry is beyond
// its limit may test the node once more and reach nothing, or test a leaf whose hit its limit then rejects).
// A ray may visit leaves in another order than alone, and more of them (its limit falls later); its closest hit is
// the same as long as an object's hit does not depend on the limit it is tested with (the caller's condition).

namespace {

typedef float V8 __attribute__((vector_size(32)));

struct PacketEntry {
  std::uint32_t ref;
  std::uint32_t mask;  // bit l: lane l still follows this entry
  float t;             // the smallest entry parameter over those lanes
};

// One packet's walk, a step at a time (a leaf's visits or a node's test, then the next entry), so that the caller
// can interleave several packets: a step ends knowing the next entry, whose lines are then requested (a child taken
// at once here; a popped one was requested when pushed) while the other packets take a step each; every packet's own
// sequence of steps, and so every lane's visits and limits, is the one it takes alone.
template <int kOctant>
class PacketWalk {
 public:
  // Lane l is the call's lane `first + l` (its ray rays[first + l], its limit limits[first + l]).
  void start(const WideNode* nodes, const WideRay* const* rays, unsigned first, unsigned n, float* limits) {
    nodes_ = nodes, rays_ = rays + first, limits_ = limits + first, first_ = first;
    for (unsigned l = 0; l < n; ++l)
      for (int k = 0; k < 3; ++k)
        c_[l].on[k] = rays_[l]->o_near[k], c_[l].of[k] = rays_[l]->o_far[k], c_[l].ni[k] = -rays_[l]->inv[k];
    for (unsigned l = 0; l < kWidePacketLanes; ++l) lim_[l] = l < n ? limits_[l] : -1.0f;
    top_ = 0;
    // The root with every lane; lanes >= n never pass the pop's test.
    ref_ = 0, mask_ = n >= 32 ? ~0u : (1u << n) - 1u;
  }

  // Processes the current entry and moves to the next; false when the walk is over.
  bool step(WidePacketVisit visit, void* context) {
    constexpr bool neg_x = (kOctant & 1) != 0, neg_y = (kOctant & 2) != 0, neg_z = (kOctant & 4) != 0;
    constexpr std::size_t near_x = neg_x ? offsetof(WideNode, hi_x) : offsetof(WideNode, lo_x);
    constexpr std::size_t near_y = neg_y ? offsetof(WideNode, hi_y) : offsetof(WideNode, lo_y);
    constexpr std::size_t near_z = neg_z ? offsetof(WideNode, hi_z) : offsetof(WideNode, lo_z);
    constexpr std::size_t far_x = neg_x ? offsetof(WideNode, lo_x) : offsetof(WideNode, hi_x);
    constexpr std::size_t far_y = neg_y ? offsetof(WideNode, lo_y) : offsetof(WideNode, hi_y);
    constexpr std::size_t far_z = neg_z ? offsetof(WideNode, lo_z) : offsetof(WideNode, hi_z);
    const WideRay& r0 = *rays_[0];  // balls and prefetch are the tree's, the same in every lane
    if (ref_ & kLeafBit) {
      const std::uint32_t leaf = ref_ & ~kLeafBit;
      const float* ball = r0.balls != nullptr ? r0.balls + std::size_t(r0.ball_stride) * leaf : nullptr;
      for (std::uint32_t b = mask_; b != 0; b &= b - 1) {
        const unsigned l = unsigned(__builtin_ctz(b));
        if (ball != nullptr && ball_misses(ball, *rays_[l])) continue;
        visit(context, first_ + l, leaf, limits_[l]);
        lim_[l] = limits_[l];
      }
      return pop();
    }
    float zero_scalar = 0.0f;
    __asm__("" : "+x"(zero_scalar));  // as in the one-ray loop: one ordered max, not a compare and a mask
    const V zero = splat(zero_scalar), scale = splat(kFarScale), slack = splat(kFarSlack);
    const V inf = splat(__builtin_inff());
    const WideNode* node = nodes_ + ref_;
    V key[kParts];  // per slot, the smallest entry over the lanes reaching it (+inf: none)
    VI lanes[kParts];  // per slot, bit l: lane l reaches it
    for (int p = 0; p < kParts; ++p) key[p] = inf, lanes[p] = splat_int(0);
    std::uint32_t reached = 0;
    for (std::uint32_t b = mask_; b != 0; b &= b - 1) {
      const unsigned l = unsigned(__builtin_ctz(b));
      const LaneConstants& r = c_[l];
      const V lim_v = splat(lim_[l]);
      std::uint32_t bits = 0;
      for (int p = 0; p < kParts; ++p) {
        const std::size_t at = sizeof(V) * std::size_t(p);
        const V nix = splat(r.ni[0]), niy = splat(r.ni[1]), niz = splat(r.ni[2]);
        V a = zero;
        a = max_into((splat(r.on[0]) - load_at(node, near_x + at)) * nix, a);
        a = max_into((splat(r.on[1]) - load_at(node, near_y + at)) * niy, a);
        a = max_into((splat(r.on[2]) - load_at(node, near_z + at)) * niz, a);
        V f = lim_v;
        f = min_into((splat(r.of[0]) - load_at(node, far_x + at)) * nix, f);
        f = min_into((splat(r.of[1]) - load_at(node, far_y + at)) * niy, f);
        f = min_into((splat(r.of[2]) - load_at(node, far_z + at)) * niz, f);
        f = f * scale + slack;
        const auto hit = a <= f;
        key[p] = (hit & (a < key[p])) ? a : key[p];
        lanes[p] |= hit & splat_int(std::int32_t(1u << l));
        bits |= BATCHCOL_WIDE_LE(a, f) << (kVLanes * p);
      }
      reached |= bits;
    }
    if (reached == 0) return pop();
    const auto slot_key = [&key](std::size_t k) {
      float t;
      __builtin_memcpy(&t, reinterpret_cast<const char*>(key) + sizeof(float) * k, sizeof t);
      return t;
    };
    const auto slot_lanes = [&lanes](std::size_t k) {
      std::uint32_t m;
      __builtin_memcpy(&m, reinterpret_cast<const char*>(lanes) + sizeof(std::uint32_t) * k, sizeof m);
      return m;
    };
    // Slot k as a stack entry: its child, lanes and their smallest entry.
    const auto write = [&](PacketEntry& e, std::size_t k) {
      e.ref = node->child[k];
      e.mask = slot_lanes(k);
      e.t = slot_key(k);
      if (r0.prefetch) prefetch_child(nodes_, e.ref, r0);
    };
    if ((reached & (reached - 1)) == 0) {  // one slot: next, with the lanes that reach it
      const int k = __builtin_ctz(reached);
      ref_ = node->child[k], mask_ = slot_lanes(std::size_t(k));
      if (r0.prefetch) prefetch_child(nodes_, ref_, r0);
      return true;
    }
    // Ranks by key, ties to the lower slot, as the one-ray loop's rank (keys are +0, positive or +inf).
    const int count = __builtin_popcount(reached);
    PacketEntry* const base = stack_ + top_ + count - 1;
    VI key_bits[kParts];
    __builtin_memcpy(key_bits, key, sizeof key_bits);
    std::size_t first = 0;
    for (std::uint64_t b = reached; b != 0; b &= b - 1) {
      const std::size_t k = std::size_t(__builtin_ctzll(b));
      std::int32_t t_bits;
      const float t = slot_key(k);
      __builtin_memcpy(&t_bits, &t, sizeof t_bits);
      const VI tk = splat_int(t_bits);
      std::uint32_t nearer = 0;
      for (int p = 0; p < kParts; ++p)
        nearer |= BATCHCOL_WIDE_ILT(key_bits[p] - load_int(kLowerOnes.row[k] + kVLanes * p), tk) << (kVLanes * p);
      const std::ptrdiff_t rank = __builtin_popcountll(std::uint64_t(reached & nearer));
      if (rank == 0)
        first = k;
      else
        write(base[-rank], k);
    }
    top_ += count - 1;
    ref_ = node->child[first], mask_ = slot_lanes(first);
    if (r0.prefetch) prefetch_child(nodes_, ref_, r0);
    return true;
  }

 private:
  // The next stacked entry that a lane still follows (its limit not below the entry), as the current one.
  bool pop() {
    for (;;) {
      if (top_ == 0) return false;
      const PacketEntry& p = stack_[--top_];
      const float t = p.t;
      const V8 tv = {t, t, t, t, t, t, t, t};
      std::uint32_t m = 0;
      for (unsigned h = 0; h < kWidePacketLanes / 8; ++h) {
        V8 l;
        __builtin_memcpy(&l, lim_ + 8 * h, sizeof l);
        m |= BATCHCOL_WIDE_LE8(tv, l) << (8 * h);
      }
      m &= p.mask;
      if (m != 0) {
        ref_ = p.ref, mask_ = m;
        return true;
      }
    }
  }

  // Each lane's slab constants side by side (one broadcast load each in the node test).
  struct LaneConstants {
    float on[3], of[3], ni[3];
  };
  alignas(64) float lim_[kWidePacketLanes];
  LaneConstants c_[kWidePacketLanes];
  const WideNode* nodes_;
  const WideRay* const* rays_;
  float* limits_;
  unsigned first_;
  std::uint32_t ref_, mask_;  // the current entry
  int top_;
  PacketEntry stack_[64 * (kWideArity - 1) + 2];
};

// Up to kWidePacketStreams packets walk at once, a step of each in turn: a step's next entry is requested at its end
// and loaded the next time round, so a packet's cache misses (the first node of a descent is not a pushed, already
// requested child; neither is a leaf taken at once) overlap the other packets' steps.
// The walks live on the heap, one block per thread kept from call to call: kWidePacketStreams walks take ~103 KB
// (mostly each walk's worst-case stack), too much for the stack of a caller's thread, which takes part in the cast.
// Every octant's PacketWalk has the same layout (the octant only selects code), so one block serves them all.
struct alignas(64) PacketWalkBlock {
  unsigned char bytes[kWidePacketStreams * sizeof(PacketWalk<0>)];
};
inline unsigned char* packet_walk_block() {
  thread_local std::unique_ptr<PacketWalkBlock> block;
  if (block == nullptr) block = std::make_unique<PacketWalkBlock>();
  return block->bytes;
}

template <int kOctant>
void traverse_packets_octant(const WideNode* nodes, const WideRay* const* rays, float* limits,
                             const WidePacket* packets, unsigned count, WidePacketVisit visit, void* context) {
  static_assert(sizeof(PacketWalk<kOctant>) == sizeof(PacketWalk<0>) &&
                std::is_trivially_destructible_v<PacketWalk<kOctant>>);
  unsigned char* const block = packet_walk_block();
  PacketWalk<kOctant>* live[kWidePacketStreams];
  unsigned active = 0, next = 0;
  for (; active < kWidePacketStreams && next < count; ++active, ++next) {
    live[active] = new (block + active * sizeof(PacketWalk<kOctant>)) PacketWalk<kOctant>;
    live[active]->start(nodes, rays, packets[next].first, packets[next].n, limits);
  }
  unsigned i = 0;
  while (active != 0) {
    PacketWalk<kOctant>& w = *live[i];
    if (w.step(visit, context)) {
      ++i;
    } else if (next < count) {  // the next packet takes the finished one's place (its root is in the cache)
      w.start(nodes, rays, packets[next].first, packets[next].n, limits);
      ++next, ++i;
    } else {
      live[i] = live[--active];
    }
    if (i >= active) i = 0;
  }
}
}  // namespace

void traverse_packets(const WideNode* nodes, const WideRay* const* rays, float* limits, const WidePacket* packets,
                      unsigned count, WidePacketVisit visit, void* context) {
  if (count == 0) return;
  switch (rays[packets[0].first]->octant) {
    case 0: return traverse_packets_octant<0>(nodes, rays, limits, packets, count, visit, context);
    case 1: return traverse_packets_octant<1>(nodes, rays, limits, packets, count, visit, context);
    case 2: return traverse_packets_octant<2>(nodes, rays, limits, packets, count, visit, context);
    case 3: return traverse_packets_octant<3>(nodes, rays, limits, packets, count, visit, context);
    case 4: return traverse_packets_octant<4>(nodes, rays, limits, packets, count, visit, context);
    case 5: return traverse_packets_octant<5>(nodes, rays, limits, packets, count, visit, context);
    case 6: return traverse_packets_octant<6>(nodes, rays, limits, packets, count, visit, context);
    default: return traverse_packets_octant<7>(nodes, rays, limits, packets, count, visit, context);
  }
}
