#include "ray_wide_bvh.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <atomic>
#include <cmath>
#include <memory>

namespace batchcol {
namespace {

BvhBox box_of_ref(const RayBvh& bvh, const broadphase::AabbSoa& b, std::uint32_t ref) {
  if (ref & kLeafBit) {
    const std::uint32_t i = bvh.leaf_object()[ref & ~kLeafBit];
    return {{b.min_x[i], b.min_y[i], b.min_z[i]}, {b.max_x[i], b.max_y[i], b.max_z[i]}};
  }
  const BvhNode& n = bvh.nodes()[ref];
  BvhBox r;
  for (int k = 0; k < 3; ++k)
    r.lo[k] = std::fmin(n.box[0].lo[k], n.box[1].lo[k]), r.hi[k] = std::fmax(n.box[0].hi[k], n.box[1].hi[k]);
  return r;
}

// Half the surface area (the ordering is all that matters); double, so that large boxes do not overflow.
double half_area(const BvhBox& b) {
  const double x = double(b.hi[0]) - b.lo[0], y = double(b.hi[1]) - b.lo[1], z = double(b.hi[2]) - b.lo[2];
  return x * y + y * z + z * x;
}

void set_slot(WideNode& n, int k, const BvhBox& b, std::uint32_t child) {
  n.lo_x[k] = b.lo[0], n.lo_y[k] = b.lo[1], n.lo_z[k] = b.lo[2];
  n.hi_x[k] = b.hi[0], n.hi_y[k] = b.hi[1], n.hi_z[k] = b.hi[2];
  n.child[k] = child;
}

void clear_slot(WideNode& n, int k) {
  n.lo_x[k] = n.lo_y[k] = n.lo_z[k] = INFINITY;
  n.hi_x[k] = n.hi_y[k] = n.hi_z[k] = -INFINITY;
  n.child[k] = kWideEmpty;
}

}  // namespace

// Cost-based choice of each wide node's children (after Ylitie, Karras and Laine, "Efficient incoherent ray
// traversal on GPUs through compressed wide BVHs", HPG 2017, here for leaves of one object): a ray visits a wide node
// with a probability proportional to the surface area of its box, and a node costs the same whatever its fill (one
// SIMD test of its 16 slots), while every leaf is a slot somewhere whichever the tree. So the tree with the fewest
// expected node visits minimises the sum of its wide nodes' areas. cost[x][j - 1] is that sum for the subtree of
// binary node x when it may fill j slots of its parent: as one slot (x becomes a wide node: its area plus the best
// split of 16 slots between its children) or, for j >= 2, spread over the slots (j' + (j - j') slots to its two
// children, x itself no node). Leaves cost 0. It replaces the greedy rule (open the largest-area internal child
// until 8 children), cheaper to build but leaving bottom subtrees of 2-3 leaves as nodes of their own: at 8 slots,
// on 10k hulls 3634 wide nodes of 3.75 children there, 2621 of 4.81 here, and 4% fewer traversal instructions per
// ray (the small nodes it removes have small boxes, so rays seldom reached them: the expected visits fall less than
// the count). At 16 slots the 100k mixed scene has 25927 nodes, 14188 of them with 2 children and 4262 full.
struct CollapsePlan {
  std::vector<std::array<double, kWideArity>> cost;       // per binary node, j = 1..16
  std::vector<std::array<std::uint8_t, kWideArity>> left;  // slots given to child 0 (0: x is one slot, a node)

  double of(std::uint32_t ref, int j) const {
    return (ref & kLeafBit) ? 0.0 : cost[ref][j - 1];
  }

  // Bottom-up and in parallel, as the binary refit (ray_bvh.cpp): from every leaf up, the first child to arrive at
  // a node stops and the second computes it, so each node is computed once, after both children (acq_rel on the
  // counter publishes the first child's row). Each row depends on its children's rows only: the same for any
  // thread count.
  void plan(const RayBvh& bvh, const broadphase::AabbSoa& boxes) {
    const std::size_t n = bvh.nodes().size(), leaves = bvh.leaf_count();
    cost.resize(n), left.resize(n);
    std::unique_ptr<std::atomic<std::uint32_t>[]> arrivals(new std::atomic<std::uint32_t>[n]);
    for (std::size_t i = 0; i < n; ++i) arrivals[i].store(0, std::memory_order_relaxed);
    const std::vector<std::uint32_t>& parent = bvh.parents();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, leaves, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t k = r.begin(); k < r.end(); ++k) {
        std::uint32_t x = parent[n + k];
        for (;;) {
          if (arrivals[x].fetch_add(1, std::memory_order_acq_rel) == 0) break;
          compute(bvh, boxes, x);
          if (x == 0) break;
          x = parent[x];
        }
      }
    });
  }

  void compute(const RayBvh& bvh, const broadphase::AabbSoa& boxes, std::uint32_t x) {
    const BvhNode& node = bvh.nodes()[x];
    const std::uint32_t a = node.child[0], b = node.child[1];
    // best[j - 1]: the children spread over j slots (j >= 2), k of them to child 0.
    double best[kWideArity];
    std::uint8_t best_k[kWideArity];
    for (int j = 2; j <= kWideArity; ++j) {
      best[j - 1] = INFINITY, best_k[j - 1] = 1;
      for (int k = 1; k < j; ++k) {
        const double c = of(a, k) + of(b, j - k);
        if (c < best[j - 1]) best[j - 1] = c, best_k[j - 1] = static_cast<std::uint8_t>(k);
      }
    }
    const double as_node = half_area(box_of_ref(bvh, boxes, x)) + best[kWideArity - 1];
    cost[x][0] = as_node, left[x][0] = 0;
    for (int j = 2; j <= kWideArity; ++j) {
      const bool spread = best[j - 1] < as_node;
      cost[x][j - 1] = spread ? best[j - 1] : as_node;
      left[x][j - 1] = spread ? best_k[j - 1] : 0;
    }
  }

  // The slots of binary node x given j of them: itself (a leaf, or a node of its own) or its children's slots.
  void slots(const RayBvh& bvh, std::uint32_t ref, int j, std::uint32_t* out, int& count) const {
    if ((ref & kLeafBit) || left[ref][j - 1] == 0) {
      out[count++] = ref;
      return;
    }
    const int k = left[ref][j - 1];
    slots(bvh, bvh.nodes()[ref].child[0], k, out, count);
    slots(bvh, bvh.nodes()[ref].child[1], j - k, out, count);
  }

  // The children of the wide node made from binary node x: the best split of 16 slots.
  int wide_children(const RayBvh& bvh, std::uint32_t x, std::uint32_t* out) const {
    // cost[x][0] chose x as a node: its 16 slots are split as for j = 16 without the "as node" option.
    const BvhNode& node = bvh.nodes()[x];
    double best = INFINITY;
    int best_k = 1;
    for (int k = 1; k < kWideArity; ++k) {
      const double c = of(node.child[0], k) + of(node.child[1], kWideArity - k);
      if (c < best) best = c, best_k = k;
    }
    int count = 0;
    slots(bvh, node.child[0], best_k, out, count);
    slots(bvh, node.child[1], kWideArity - best_k, out, count);
    return count;
  }
};

void WideBvh::collapse(const RayBvh& bvh, const broadphase::AabbSoa& boxes) {
  nodes_.clear();
  source_.clear();
  if (bvh.leaf_count() < 2) return;
  CollapsePlan plan;
  plan.plan(bvh, boxes);
  struct Task {
    std::uint32_t binary, wide;
  };
  std::vector<Task> todo{{0u, 0u}};
  // At most leaves - 1 nodes (each has >= 2 children and is itself a child, except the root): reserved, so the
  // array is never copied as it grows. Only the pages written are faulted in (on huge pages each regrowth faulted
  // a fresh mapping in: the 100k-object collapse took 167-172 ms against 104-122 ms reserved, load average 13).
  nodes_.reserve(bvh.leaf_count() - 1);
  source_.reserve((bvh.leaf_count() - 1) * kWideArity);
  nodes_.emplace_back();
  source_.resize(kWideArity);
  while (!todo.empty()) {
    const Task task = todo.back();
    todo.pop_back();
    std::uint32_t refs[kWideArity];
    const int count = plan.wide_children(bvh, task.binary, refs);
    for (int k = 0; k < kWideArity; ++k) {
      source_[std::size_t(task.wide) * kWideArity + k] = k < count ? refs[k] : kWideEmpty;
      if (k >= count) {
        clear_slot(nodes_[task.wide], k);
        continue;
      }
      const BvhBox box = box_of_ref(bvh, boxes, refs[k]);
      if (refs[k] & kLeafBit) {
        set_slot(nodes_[task.wide], k, box, refs[k]);
      } else {
        const std::uint32_t child = static_cast<std::uint32_t>(nodes_.size());
        nodes_.emplace_back();
        source_.resize(nodes_.size() * kWideArity);
        set_slot(nodes_[task.wide], k, box, child);
        todo.push_back({refs[k], child});
      }
    }
  }
}

void WideBvh::refit(const RayBvh& bvh, const broadphase::AabbSoa& boxes) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nodes_.size(), 256),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i < r.end(); ++i) {
                        WideNode& n = nodes_[i];
                        for (int k = 0; k < kWideArity; ++k) {
                          const std::uint32_t ref = source_[i * kWideArity + k];
                          if (ref != kWideEmpty) set_slot(n, k, box_of_ref(bvh, boxes, ref), n.child[k]);
                        }
                      }
                    });
}

}  // namespace batchcol
