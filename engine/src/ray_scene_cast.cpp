// RaySceneIndex::cast(): each ray walks the 16-wide BVH (ray_wide_traverse.hpp; rays outside float's range walk the
// binary LBVH in double) depth first, nearest child first, and intersects the objects of the leaves it reaches with
// the exact kernels (kernels/rays/); halfspaces (unbounded) are tested first for every ray.
// Closest-hit pruning: a subtree is skipped when its box starts beyond the best hit so far. Ties in t go to the lower
// object slot, so the answer does not depend on the traversal order. Rays are split into fixed chunks; all-hit rows
// are collected per chunk and concatenated in ray order: bitwise the same for any thread count.
#include "ray_cast_arena.hpp"
#include "ray_order_keys.hpp"
#include "ray_scene_state.hpp"
#include "ray_wide_traverse.hpp"
#include "rays_common.hpp"

#include "broadphase/radix_sort.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <new>

namespace batchcol {
namespace {

using kernels::Vec3;
namespace kr = kernels::rays;

struct Hit {
  double t;
  Vec3<double> normal;
  ObjectHandle object;
};

// Batches from this size on are cast in RayOrder (below) when what a ray reads at random, the wide nodes and the leaf
// records (RayLeaf: the leaf's ball and object), takes at least kRandomReadBytes; records of rays this far ahead in
// that order are prefetched. The order costs ~280 instructions a ray (AVX2: key 118, sort 120, scatter 38); it pays
// when those arrays do not stay in a core's L2 (2 MB on the Xeons measured, shared with the shapes' data and the rays):
// 100k mixed objects (26 MB of nodes, 13 MB of leaves), +20% rays/s, and 10k hulls of 250 vertices (0.67 MB of nodes,
// 1.28 MB of leaves, ~0.6 MB of hull walk data), where perf put 25% of the traversal's samples on the first load of a
// node and 13% on the leaf's ball in input order (14% and 8% in this order), and the order measured +5% rays per CPU
// second (1 thread, 4 alternating rounds) and +12% in the same-run ratio to Embree (2 threads, median of 8 alternating
// pairs; Emerald Rapids VM at 2.1 GHz; the nodes alone, the previous criterion, are below 1 MiB there). The traversal
// prefetches pushed nodes on trees whose nodes alone exceed it (kLargeTreeBytes): on 10k hulls in this order that
// prefetching measured 0.83-1.00 of the rays per CPU second without it (4 rounds).
constexpr std::size_t kSortedCastMin = 4096;
constexpr std::size_t kRandomReadBytes = std::size_t(1) << 20;
constexpr std::size_t kLargeTreeBytes = std::size_t(1) << 20;
constexpr std::size_t kPrefetchAhead = 8;

// The packet cast's window: the rays of one call of the packet traversal, kWidePacketStreams packets of one octant.
constexpr unsigned kWidePacketWindow = kWidePacketLanes * kWidePacketStreams;

bool before(const Hit& a, const Hit& b) { return a.t < b.t || (a.t == b.t && a.object.slot < b.object.slot); }

struct RayContext {
  Vec3<double> o, d, inv;  // inv: set by traverse() for the binary tree only
  double t_max, d2;  // d2 = |d|^2
  bool wide_ok;  // the float test of the wide tree is safe for this ray (else: the binary tree in double)
  // The ray's entry in the caller's setup array, balls and prefetch already set (Caster::prepare()): not a copy,
  // two copies of its 88 bytes cost ~30 instructions a ray.
  const WideRay* wide = nullptr;
};

// Slab test of a float box (outward-rounded, so it contains the object with room to spare for this double
// arithmetic): the entry parameter, or +inf when the ray segment [0, t_far] misses the box. A zero direction
// component gives inv = +-inf and (lo - o) * inv = NaN only when o lies on the slab plane; NaN loses every
// comparison below, which keeps the box (conservative).
double box_entry(const BvhBox& b, const RayContext& r, double t_far) {
  double t0 = 0.0, t1 = t_far;
  for (int k = 0; k < 3; ++k) {
    const double a = (double(b.lo[k]) - r.o[k]) * r.inv[k], c = (double(b.hi[k]) - r.o[k]) * r.inv[k];
    const double near = a < c ? a : c, far = a < c ? c : a;
    t0 = near > t0 ? near : t0;
    t1 = far < t1 ? far : t1;
  }
  return t0 <= t1 ? t0 : kr::infinity<double>();
}

class Caster {
 public:
  Caster(const RaySceneIndex::State& s, const RayOptions& o, int isa)
      : s_(s), gjk_{o.tolerance, o.max_iterations}, wide_(select_wide_traverse(isa)),
        packet_(select_wide_packet_traverse(isa)), isa_(isa) {}

  // True when the closest hit of a ray does not depend on the order in which its leaves are visited, nor on how
  // many: every shape has an exact kernel whose hit parameter and status do not depend on the limit it is tested
  // with (finish(): the limit only accepts or rejects), so the answer is the least (t, slot) over the objects the
  // ray hits, whichever superset of the leaves the pruning allows is tested. Not hulls (the walk starts from the
  // limit-clipped ball) nor the GJK ray cast of inflated shapes (its iterations and status depend on the limit).
  bool order_free() const {
    if (s_.wide.nodes().empty()) return false;
    for (const kr::RayShape<double>& shape : s_.prepared.shapes) {
      const ShapeType type = shape.core.type;
      if (type == ShapeType::convex) return false;
      if (shape.inflation > 0.0 && type != ShapeType::sphere && type != ShapeType::capsule &&
          type != ShapeType::halfspace)
        return false;
    }
    return true;
  }

  // Tests `obj` against r below `limit`; a hit before the best so far (before(): t, then slot) becomes the best and
  // the new limit. The one rule of the closest / any searches, one ray at a time and in packets.
  [[gnu::always_inline]] bool keep_nearer(const RayObject& obj, const RayContext& r, double& limit, Hit& best,
                                          bool& found, bool& capped) const {
    Hit h;
    if (!test(obj, r, limit, h, capped) || (found && !before(h, best))) return false;
    best = h, found = true, limit = best.t;
    return true;
  }

  // Closest hits of rays of one direction octant (wide_ok) through the packet traversal, in `count` packets (slices
  // of r, at most kWidePacketWindow rays in all): the halfspaces first, as closest_or_any(), then the tree; for
  // order_free() scenes only (the same answers as one ray at a time).
  void closest_packets(const RayContext* r, const WidePacket* packets, unsigned count, Hit* best, bool* found,
                       bool* capped) const {
    double limit[kWidePacketWindow];
    float lim[kWidePacketWindow];
    const WideRay* wide[kWidePacketWindow];
    const unsigned n = packets[count - 1].first + packets[count - 1].n;
    for (unsigned l = 0; l < n; ++l) {
      limit[l] = r[l].t_max;
      for (const RayObject& obj : s_.halfspaces) keep_nearer(obj, r[l], limit[l], best[l], found[l], capped[l]);
      lim[l] = wide_limit(limit[l]);
      wide[l] = r[l].wide;
    }
    auto leaf = [&](unsigned l, std::uint32_t k, float& fl) {
      if (keep_nearer(s_.leaves[k].object, r[l], limit[l], best[l], found[l], capped[l])) fl = wide_limit(limit[l]);
    };
    using Leaf = decltype(leaf);
    packet_(s_.wide.nodes().data(), wide, lim, packets, count,
            [](void* c, unsigned l, std::uint32_t k, float& fl) { (*static_cast<Leaf*>(c))(l, k, fl); }, &leaf);
  }

  // The traversal's per-tree settings in the setup's rays: leaves whose ball the ray misses are skipped without a
  // call, and on trees larger than the L2 pushed nodes are prefetched.
  void prepare(WideRay* rays, std::size_t n) const {
    const float* balls = s_.leaves.empty() ? nullptr : s_.leaves.data()->ball;
    const bool prefetch = s_.wide.nodes().size() * sizeof(WideNode) >= kLargeTreeBytes;
    for (std::size_t l = 0; l < n; ++l)
      rays[l].balls = balls, rays[l].ball_stride = sizeof(RayLeaf) / sizeof(float), rays[l].prefetch = prefetch;
  }

  // Intersects one object; true on a hit with t <= t_max.
  bool test(const RayObject& obj, const RayContext& r, double t_max, Hit& hit, bool& capped) const {
    double ball_entry = kernels::quiet_nan<double>();
    if (ball_misses(obj, r, t_max, ball_entry)) return false;
    const Vec3<double> o = kernels::mul_transposed(obj.R, Vec3<double>(r.o - obj.t));
    const Vec3<double> d = kernels::mul_transposed(obj.R, r.d);
    // Uninflated hulls (the ball filter always passes them with an entry) go straight to the walk.
    const kr::RayShape<double>& shape = s_.prepared.shapes[obj.shape];
    const kr::LocalHit<double> h =
        shape.core.type == ShapeType::convex && !(shape.inflation > 0.0) && ball_entry == ball_entry
            ? kr::ray_local_hull(shape, o, d, t_max, ball_entry, isa_)
            : kr::ray_local(shape, o, d, t_max, gjk_, ball_entry, isa_);
    capped = capped || h.status != kr::LocalStatus::converged;
    if (!h.hit) return false;
    hit = {h.t, kernels::mul(obj.R, h.normal), obj.handle};
    return true;
  }

  // The object's bounding ball, in the world frame: most leaves a ray reaches miss their object, and this rejects
  // them before the transform to the local frame and the kernel. Only a filter: the radius is widened by 1e-12 of
  // (|o - centre| + radius), a thousand times the rounding of the closest-point form here and of the local-frame
  // transform (a few 1e-16 of the same lengths), so a ray the exact kernel hits is never rejected. On a pass,
  // `entry` is where the ray enters the widened ball: every point before it is outside the shape, so hulls start
  // their walk there (ray_local) instead of testing their ball again in the local frame.
  bool ball_misses(const RayObject& obj, const RayContext& r, double t_max, double& entry) const {
    const double bound = s_.prepared.shapes[obj.shape].bound;
    if (!(bound > 0.0)) return false;  // halfspaces
    const Vec3<double> oc = r.o - obj.t;
    const double tc = -oc.dot(r.d) / r.d2;
    const Vec3<double> p = oc + tc * r.d;
    const double R = bound + 1e-12 * (oc.cwiseAbs().maxCoeff() + bound), h2 = R * R - p.squaredNorm();
    if (!(h2 >= 0.0)) return true;
    const double half = std::sqrt(h2 / r.d2);
    entry = tc - half;
    return tc + half < 0.0 || entry > t_max;
  }

  // Visits the leaves whose boxes the ray segment [0, limit()] reaches; visit(leaf) returns false to stop.
  template <class Visit, class Limit> void traverse(const RayContext& r, const Limit& limit, const Visit& visit) const {
    if (r.wide_ok && !s_.wide.nodes().empty()) {
      double last = limit();
      auto leaf = [&](std::uint32_t k, float& lim) {
        if (!visit(k)) return false;
        if (const double l = limit(); l != last) last = l, lim = wide_limit(l);  // only a hit moves the limit
        return true;
      };
      using Leaf = decltype(leaf);
      wide_(s_.wide.nodes().data(), *r.wide, wide_limit(last),
            [](void* c, std::uint32_t k, float& lim) { return (*static_cast<Leaf*>(c))(k, lim); }, &leaf);
      return;
    }
    RayContext rb = r;  // the reciprocal only this path reads (three divisions the wide path does not need)
    rb.inv = Vec3<double>(1.0 / r.d.x(), 1.0 / r.d.y(), 1.0 / r.d.z());
    binary_traverse(rb, limit, visit);
  }

  // The binary tree in double (rays outside the float test's range, and scenes of one object).
  template <class Visit, class Limit>
  void binary_traverse(const RayContext& r, const Limit& limit, const Visit& visit) const {
    const RayBvh& bvh = s_.bvh;
    if (bvh.leaf_count() == 0) return;
    if (bvh.leaf_count() == 1) {
      if (box_entry(bvh.single_box(), r, limit()) < kr::infinity<double>()) visit(0u);
      return;
    }
    // Depth <= 64: every level of a Karras tree splits on a distinct bit of the 64-bit keys.
    struct Entry {
      std::uint32_t node;
      double t;
    };
    Entry stack[80];
    int top = 0;
    std::uint32_t node = 0;
    const std::vector<BvhNode>& nodes = bvh.nodes();
    for (;;) {
      const BvhNode& n = nodes[node];
      const double lim = limit();
      const double t0 = box_entry(n.box[0], r, lim), t1 = box_entry(n.box[1], r, lim);
      const bool h0 = t0 < kr::infinity<double>(), h1 = t1 < kr::infinity<double>();
      std::uint32_t next[2];
      double tn[2];
      int count = 0;
      if (h0 && h1) {
        const int first = t1 < t0 ? 1 : 0;
        next[0] = n.child[first], tn[0] = first ? t1 : t0;
        next[1] = n.child[1 - first], tn[1] = first ? t0 : t1;
        count = 2;
      } else if (h0 || h1) {
        next[0] = n.child[h0 ? 0 : 1], tn[0] = h0 ? t0 : t1;
        count = 1;
      }
      // Leaves are visited at once (nearer first); the nearer internal child is descended, the other one stacked.
      std::uint32_t descend = kLeafBit;
      for (int c = 0; c < count; ++c) {
        if (next[c] & kLeafBit) {
          if (!visit(next[c] & ~kLeafBit)) return;
        } else if (descend == kLeafBit) {
          descend = next[c];
        } else {
          stack[top++] = {next[c], tn[c]};
        }
      }
      if (descend != kLeafBit) {
        node = descend;
        continue;
      }
      // Pop the next subtree still within reach (the limit shrinks as closer hits are found).
      for (;;) {
        if (top == 0) return;
        const Entry e = stack[--top];
        if (e.t <= limit()) {
          node = e.node;
          break;
        }
      }
    }
  }

  // Always inlined into the cast loops: with wide_limit() inline GCC otherwise made it a call (+80 instructions a ray).
  [[gnu::always_inline]] void closest_or_any(const RayContext& r, bool any, Hit& best, bool& found,
                                             bool& capped) const {
    double limit = r.t_max;
    for (const RayObject& obj : s_.halfspaces) {
      keep_nearer(obj, r, limit, best, found, capped);
      if (found && any) return;
    }
    traverse(r, [&] { return limit; }, [&](std::uint32_t leaf) {
      return !(keep_nearer(s_.leaves[leaf].object, r, limit, best, found, capped) && any);
    });
  }

  void all(const RayContext& r, std::vector<Hit>& hits, bool& capped) const {
    Hit h;
    for (const RayObject& obj : s_.halfspaces)
      if (test(obj, r, r.t_max, h, capped)) hits.push_back(h);
    traverse(r, [&] { return r.t_max; }, [&](std::uint32_t leaf) {
      if (test(s_.leaves[leaf].object, r, r.t_max, h, capped)) hits.push_back(h);
      return true;
    });
  }

 private:
  const RaySceneIndex::State& s_;
  kr::RayGjkSettings gjk_;
  WideTraverse wide_;
  WidePacketTraverse packet_;
  int isa_;  // RayOptions::isa (ray_isa_index()): the hulls' clipping loop follows it as the traversal does
};

void store(RayResults& out, std::size_t i, const Hit& h) {
  out.hit[i] = 1;
  out.t[i] = h.t;
  out.normal.set(i, h.normal);
  out.object[i] = h.object;
}

// detail::size_ray_results() without its default values, for a cast that writes every field of every ray.
void size_unfilled(RayResults& r, std::size_t n) {
  r.status.resize(n), r.hit.resize(n), r.t.resize(n), r.normal.resize(n), r.object.resize(n);
  r.hit_begin.clear(), r.all_t.clear(), r.all_normal.resize(0), r.all_object.clear();
}

// Ray order for a large batch: rays that enter the scene near each other in similar directions are cast one after
// the other (the key: ray_order_keys.hpp), so that the nodes one ray loads are still in cache for the next (random
// rays over a 100k-object scene otherwise miss the L2 on most wide nodes). Only the order of work changes: each ray's
// answer depends on that ray alone, so the results are bitwise those of input order. Word = key << 32 | ray index;
// the radix sort is stable and splits its work independently of the thread count.
// Reading the caller's 7 input and writing its 7 result arrays at the scattered indices of that order cost more than
// the order saved (10k hulls, whose tree fits the L2: 0.57 -> 0.38 M rays/s on one thread, prefetching or not; the
// page walks of 14 random lines a ray): the rays are copied once, in input order, into one 64-byte record each, the
// results go to a buffer in cast order, and a last pass writes the caller's arrays in input order, so a ray touches
// 3 scattered lines (its record, its slot of the inverse order, its result), not 14.
// The buffers (~130 bytes a ray) are the index's RayCastArena (ray_cast_arena.hpp), on huge pages when large: the
// records and results are read at scattered places in the cast order and the scatter, one TLB entry per ray with
// small pages, one per 2 MiB with huge ones; mapped once, not faulted in and cleared by the kernel for every cast.
using PackedRay = WideRayRecord;  // one cache line

// The cast's context of a packed ray whose setup status is not kWideRayInvalid (its wide record `wide`).
RayContext context_of(const PackedRay& p, std::uint8_t status, const WideRay* wide) {
  RayContext r;
  r.o = Vec3<double>(p.o[0], p.o[1], p.o[2]);
  r.d = Vec3<double>(p.d[0], p.d[1], p.d[2]);
  r.t_max = p.t_max;
  r.d2 = r.d.squaredNorm();
  r.wide_ok = status == kWideRaySupported;
  r.wide = wide;
  return r;
}

struct CastResult {
  Hit best;
  bool found;
  RayStatus status;
};
static_assert(sizeof(CastResult) >= sizeof(std::uint64_t), "the sort's scratch words alias the results");

class RayOrder {
 public:
  /// The arena's bytes for n rays.
  static std::size_t bytes(std::size_t n) { return results_at(n) + n * sizeof(CastResult); }

  RayOrder(const RayBatch& rays, const WideNode& root, int isa, detail::RayCastArena& arena) : n_(rays.size()) {
    char* const base = static_cast<char*>(arena.get(bytes(n_)));
    packed_ = reinterpret_cast<PackedRay*>(base);
    words_ = reinterpret_cast<std::uint64_t*>(base + n_ * sizeof(PackedRay));
    results_ = reinterpret_cast<CastResult*>(base + results_at(n_));
    const detail::RayOrderBox box = detail::ray_order_box(root);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n_, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      std::uint32_t keys[kKeyBlock];
      for (std::size_t b = r.begin(); b < r.end(); b += kKeyBlock) {
        const std::size_t m = std::min(kKeyBlock, r.end() - b);
        detail::ray_order_keys(rays, b, m, box, keys, isa);
        for (std::size_t l = 0; l < m; ++l) {
          const std::size_t i = b + l;
          packed_[i] = {{rays.origin.x[i], rays.origin.y[i], rays.origin.z[i]},
                        {rays.direction.x[i], rays.direction.y[i], rays.direction.z[i]},
                        rays.t_max[i],
                        0.0};
          words_[i] = std::uint64_t(keys[l]) << 32 | std::uint64_t(i);
        }
      }
    });
    // The sort's scratch words share the results' bytes: the cast writes the results after the sort.
    broadphase::radix_sort(words_, reinterpret_cast<std::uint64_t*>(results_), n_, broadphase::digit_shifts(32, 62));
  }

  std::size_t size() const { return n_; }
  /// The input index of the k-th ray in cast order, and its record.
  std::size_t index(std::size_t k) const { return std::size_t(words_[k] & 0xffffffffu); }
  const PackedRay& ray(std::size_t k) const { return packed_[index(k)]; }
  void prefetch(std::size_t k) const { __builtin_prefetch(&packed_[index(k)]); }
  /// The result of the k-th ray in cast order (default-initialised: the caller sets every field it reads back).
  CastResult& result(std::size_t k) { return *::new (static_cast<void*>(results_ + k)) CastResult; }

  /// Writes the results (cast order) to out (input order); the inverse order takes the records' bytes (read no
  /// more by then).
  void scatter(RayResults& out) {
    std::uint32_t* const position = reinterpret_cast<std::uint32_t*>(packed_);
    const double nan = std::nan("");
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n_, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t k = r.begin(); k < r.end(); ++k) position[index(k)] = static_cast<std::uint32_t>(k);
    });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n_, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i < r.end(); ++i) {
        const CastResult& c = results_[position[i]];
        out.status[i] = c.status;
        if (c.found) {
          store(out, i, c.best);
        } else {  // the defaults of detail::size_ray_results()
          out.hit[i] = 0;
          out.t[i] = nan;
          out.normal.set(i, Vec3<double>(nan, nan, nan));
          out.object[i] = ObjectHandle{};
        }
      }
    });
  }

 private:
  static constexpr std::size_t kKeyBlock = 64;

  // The results' offset in the arena: after the records and the words, on a cache line of their own.
  static std::size_t results_at(std::size_t n) {
    return (n * (sizeof(PackedRay) + sizeof(std::uint64_t)) + 63) & ~std::size_t(63);
  }

  std::size_t n_;
  PackedRay* packed_;
  std::uint64_t* words_;
  CastResult* results_;
};

// The ordered cast of closest hits in packets (Caster::closest_packets): each window of kWidePacketWindow rays in cast
// order (neighbours in origin and direction: ray_order_keys.hpp) splits by direction octant; octants of two or more
// rays go through the tree in packets of up to kWidePacketLanes consecutive rays, the packets of one octant in one
// call (walked at once, a step of each in turn, so one packet's cache misses overlap the others' work), single rays
// and rays outside the float test's range one at a time. Windows lie
// inside the fixed chunks, and each ray's answer is its own (order_free()): the same bits for any thread count.
// Why: in this order neighbouring rays cross many of the same nodes. Counted on 100k mixed objects x 1M rays (1
// thread): 29.6 node tests a ray; distinct nodes over aligned groups of 2 / 8 / 32 / 64 rays 23.2 / 14.1 / 8.8 / 6.9
// a ray (sharing 1.28x / 2.10x / 3.38x / 4.29x). A packet loads and pops each node once for its rays and overlaps
// the rays' tests (independent work) where the one-ray loop runs one dependent node step after another.
void cast_packets(RayOrder& order, const Caster& caster, WideRecordSetup setup) {
  constexpr std::size_t kGroup = kWidePacketWindow;
  const std::size_t n = order.size(), chunks = (n + detail::kRayChunk - 1) / detail::kRayChunk;
  // A window's buffers (~110 KB for 256 rays) are on the heap, once per range of chunks: on the stack they and the
  // packet walks took ~220 KB of the thread's stack, and the caller's own thread takes part in the cast.
  struct Window {
    const WideRayRecord* group[kGroup];
    WideRay wide[kGroup];
    std::uint8_t status[kGroup];
    RayContext ctx[kGroup], packet[kGroup];
    Hit best[kGroup], pb[kGroup];
    bool found[kGroup], capped[kGroup], pf[kGroup], pc[kGroup];
    unsigned by_octant[8][kGroup];
    WidePacket packets[kGroup / 2];
  };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks), [&](const tbb::blocked_range<std::size_t>& range) {
    const std::unique_ptr<Window> window = std::make_unique<Window>();
    auto& [group, wide, status, ctx, packet, best, pb, found, capped, pf, pc, by_octant, packets] = *window;
    for (std::size_t c = range.begin(); c != range.end(); ++c) {
      const std::size_t begin = c * detail::kRayChunk, end = std::min(n, begin + detail::kRayChunk);
      for (std::size_t k = begin; k < end; k += kGroup) {
        const std::size_t m = std::min(kGroup, end - k);
        for (std::size_t l = 0; l < m && k + kGroup + l < end; ++l) order.prefetch(k + kGroup + l);
        for (std::size_t l = 0; l < m; ++l) group[l] = &order.ray(k + l);
        for (std::size_t s = 0; s < m; s += kWideRaySetupLanes)
          setup(group + s, std::min(kWideRaySetupLanes, m - s), wide + s, status + s);
        caster.prepare(wide, m);
        unsigned per_octant[8] = {};
        for (std::size_t l = 0; l < m; ++l) {
          found[l] = false, capped[l] = false;
          if (status[l] == kWideRayInvalid) continue;
          RayContext& r = ctx[l];
          r = context_of(*group[l], status[l], &wide[l]);
          if (r.wide_ok)
            by_octant[wide[l].octant][per_octant[wide[l].octant]++] = unsigned(l);
          else
            caster.closest_or_any(r, false, best[l], found[l], capped[l]);
        }
        for (unsigned o = 0; o < 8; ++o) {
          const unsigned total = per_octant[o];
          const unsigned* lane_of = by_octant[o];
          if (total == 1) {
            const unsigned l = lane_of[0];
            caster.closest_or_any(ctx[l], false, best[l], found[l], capped[l]);
            continue;
          }
          if (total == 0) continue;
          // Packets of near-equal size (33 rays: 16 and 17, not 32 and a lone ray), in cast order.
          const unsigned count = (total + kWidePacketLanes - 1) / kWidePacketLanes;
          for (unsigned p = 0, first = 0; p < count; ++p) {
            packets[p].first = first, packets[p].n = (total - first) / (count - p);
            first += packets[p].n;
          }
          for (unsigned j = 0; j < total; ++j) packet[j] = ctx[lane_of[j]], pf[j] = false, pc[j] = false;
          caster.closest_packets(packet, packets, count, pb, pf, pc);
          for (unsigned j = 0; j < total; ++j) {
            const unsigned l = lane_of[j];
            best[l] = pb[j], found[l] = pf[j], capped[l] = pc[j];
          }
        }
        for (std::size_t l = 0; l < m; ++l) {
          CastResult& res = order.result(k + l);
          res.found = found[l];
          if (found[l]) res.best = best[l];
          res.status = status[l] == kWideRayInvalid ? RayStatus::invalid_input
                       : capped[l]                 ? RayStatus::max_iterations
                                                   : RayStatus::ok;
        }
      }
    }
  });
}

}  // namespace

void RaySceneIndex::cast(const RayBatch& rays, const RayOptions& options, RayResults& out) const {
  validate(options);
  detail::check_ray_batch(rays);
  if (!state_->ready) throw InputError("RaySceneIndex::cast: call update(scene) first");
  const std::size_t n = rays.size(), chunks = (n + detail::kRayChunk - 1) / detail::kRayChunk;
  const bool all = options.query == RayQuery::all;
  // Closest and any hits of large batches are cast in RayOrder (all-hit rows are gathered per chunk in input order,
  // so that query keeps the input order; small batches gain nothing from the sort). Its scatter writes every field
  // of every ray, so the results are only sized here, not filled with defaults first (a serial pass of 42 bytes a
  // ray).
  const bool ordered =
      !all && n >= kSortedCastMin && n < (std::size_t(1) << 32) &&
      state_->wide.nodes().size() * sizeof(WideNode) + state_->leaves.size() * sizeof(RayLeaf) >= kRandomReadBytes;
  const int isa = detail::ray_isa_index(options.isa);  // InputError when this CPU lacks the requested set
  if (ordered)
    size_unfilled(out, n);
  else
    detail::size_ray_results(out, n, true);
  const Caster caster(*state_, options, isa);
  std::vector<std::vector<Hit>> chunk_hits(all ? chunks : 0);
  std::vector<std::vector<std::uint32_t>> chunk_counts(all ? chunks : 0);
  if (ordered) {
    // The index's arena, unless another cast holds it (a concurrent one takes memory of its own).
    std::unique_lock<std::mutex> lock(state_->cast_arena.mutex, std::try_to_lock);
    detail::RayCastArena own;
    detail::RayCastArena& arena = lock.owns_lock() ? state_->cast_arena : own;
    detail::run_with_threads(options.threads, [&] {
      RayOrder order(rays, state_->wide.nodes()[0], isa, arena);
      const bool any = options.query == RayQuery::any;
      const bool packets = !any && caster.order_free();
      const WideRecordSetup setup = select_wide_record_setup(isa);
      if (packets) {
        cast_packets(order, caster, setup);
        order.scatter(out);
        return;
      }
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks), [&](const tbb::blocked_range<std::size_t>& range) {
        const WideRayRecord* group[kWideRaySetupLanes];  // the next 8 records in cast order
        WideRay wide[kWideRaySetupLanes];
        std::uint8_t status[kWideRaySetupLanes];
        for (std::size_t c = range.begin(); c != range.end(); ++c) {
          const std::size_t begin = c * detail::kRayChunk, end = std::min(n, begin + detail::kRayChunk);
          for (std::size_t k = begin; k < end; ++k) {
            if (k + kPrefetchAhead < end) order.prefetch(k + kPrefetchAhead);
            const std::size_t lane = (k - begin) % kWideRaySetupLanes;
            if (lane == 0) {  // the next 8 records' setup in lanes (as in input order below)
              const std::size_t m = std::min(kWideRaySetupLanes, end - k);
              for (std::size_t l = 0; l < m; ++l) group[l] = &order.ray(k + l);
              setup(group, m, wide, status);
              caster.prepare(wide, m);
            }
            CastResult& res = order.result(k);
            res.found = false, res.status = RayStatus::invalid_input;
            if (status[lane] == kWideRayInvalid) continue;
            RayContext r = context_of(order.ray(k), status[lane], &wide[lane]);
            bool capped = false;
            caster.closest_or_any(r, any, res.best, res.found, capped);
            res.status = capped ? RayStatus::max_iterations : RayStatus::ok;
          }
        }
      });
      order.scatter(out);
    });
    return;
  }
  // Input order: the rays' validity and wide setup are computed 8 at a time in SIMD lanes (WideRaySetup: the same
  // bits as ray_is_valid() and make_wide_ray(), without their data-dependent branches).
  const WideRaySetup setup = select_wide_ray_setup(isa);
  const WideRayInput input{{rays.origin.x.data(), rays.origin.y.data(), rays.origin.z.data()},
                           {rays.direction.x.data(), rays.direction.y.data(), rays.direction.z.data()},
                           rays.t_max.data()};
  detail::run_with_threads(options.threads, [&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks), [&](const tbb::blocked_range<std::size_t>& range) {
      WideRay wide[kWideRaySetupLanes];
      std::uint8_t status[kWideRaySetupLanes];
      for (std::size_t c = range.begin(); c != range.end(); ++c) {
        const std::size_t begin = c * detail::kRayChunk, end = std::min(n, begin + detail::kRayChunk);
        for (std::size_t i = begin; i < end; ++i) {
          if (all) chunk_counts[c].push_back(0);
          const std::size_t lane = (i - begin) % kWideRaySetupLanes;
          if (lane == 0) {
            const std::size_t m = std::min(kWideRaySetupLanes, end - i);
            setup(input, i, m, wide, status);
            caster.prepare(wide, m);
          }
          if (status[lane] == kWideRayInvalid) continue;
          RayContext r;
          r.o = Vec3<double>(rays.origin.x[i], rays.origin.y[i], rays.origin.z[i]);
          r.d = Vec3<double>(rays.direction.x[i], rays.direction.y[i], rays.direction.z[i]);
          r.t_max = rays.t_max[i];
          r.d2 = r.d.squaredNorm();
          r.wide_ok = status[lane] == kWideRaySupported;
          r.wide = &wide[lane];
          bool capped = false;
          if (all) {
            std::vector<Hit>& hits = chunk_hits[c];
            const std::size_t first = hits.size();
            caster.all(r, hits, capped);
            std::sort(hits.begin() + static_cast<std::ptrdiff_t>(first), hits.end(), before);
            chunk_counts[c].back() = static_cast<std::uint32_t>(hits.size() - first);
            if (hits.size() > first) store(out, i, hits[first]);
          } else {
            Hit best{};
            bool found = false;
            caster.closest_or_any(r, options.query == RayQuery::any, best, found, capped);
            if (found) store(out, i, best);
          }
          out.status[i] = capped ? RayStatus::max_iterations : RayStatus::ok;
        }
      }
    });
  });
  if (!all) return;
  out.hit_begin.assign(n + 1, 0);
  std::size_t total = 0, i = 0;
  for (std::size_t c = 0; c < chunks; ++c) {
    for (const std::uint32_t k : chunk_counts[c]) out.hit_begin[i++] = total, total += k;
  }
  out.hit_begin[n] = total;
  out.all_t.resize(total);
  out.all_normal.resize(total);
  out.all_object.resize(total);
  std::size_t row = 0;
  for (const std::vector<Hit>& hits : chunk_hits) {
    for (const Hit& h : hits) {
      out.all_t[row] = h.t;
      out.all_normal.set(row, h.normal);
      out.all_object[row] = h.object;
      ++row;
    }
  }
}

}  // namespace batchcol
