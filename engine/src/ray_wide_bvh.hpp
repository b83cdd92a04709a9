// A 16-wide BVH collapsed from the binary LBVH (ray_bvh.hpp) for traversal: each node holds the boxes of up to 16
// children in structure-of-arrays float form, so one SIMD pass tests a ray against all of them (ray_wide_traverse:
// one 16-lane test on AVX-512, two 8-lane halves elsewhere).
// Collapse: each wide node's children are the binary descendants (at most 16) that minimise the expected number of
// wide-node visits, the sum of the wide nodes' surface areas, chosen by dynamic programming over the binary tree
// (after Ylitie et al., HPG 2017; ray_wide_bvh.cpp). Fewer, fuller nodes mean fewer box tests per ray than the
// binary tree's pairs.
// Why 16 and not 8: in the benchmark scenes (objects scattered evenly, a ray crossing ~1.2 of them) a ray's work is
// the nodes whose boxes it crosses, ~41 a ray on 100k mixed objects with 8 slots, 41% of them reaching no child; the
// wider node covers more space per test. The collapse's own cost (sum of node areas) falls 28% from 8 to 16 slots on
// 100k mixed (27% on 10k hulls; 12 slots: 16%, 32: 45%), and the node tests a ray makes fell 28% (822806 -> 591908 on
// 20k rays). A 16-lane test costs one AVX-512 instruction where 8 lanes did; AVX2 and the baseline pay two halves.
// The topology depends only on the binary tree (built deterministically) and the boxes; every child slot remembers
// its binary node so a refit is a parallel copy of the binary tree's refitted boxes (exact float min/max).
#pragma once

#include "broadphase/aabb_soa.hpp"
#include "ray_bvh.hpp"
#include "ray_huge_pages.hpp"

#include <cstdint>
#include <vector>

namespace batchcol {

constexpr int kWideArity = 16;  // a multiple of 8 (the AVX2 and baseline traversals test 8 slots at a time)
/// Child reference of an empty slot; its box is empty (lo = +inf, hi = -inf) and never hit.
constexpr std::uint32_t kWideEmpty = 0xffffffffu;

/// One node: child k's box is [lo_x[k], hi_x[k]] x ... ; child[k] is kLeafBit | leaf index (Morton rank), a node
/// index, or kWideEmpty; filled slots first. 448 bytes (7 cache lines).
struct alignas(64) WideNode {
  float lo_x[kWideArity], lo_y[kWideArity], lo_z[kWideArity];
  float hi_x[kWideArity], hi_y[kWideArity], hi_z[kWideArity];
  std::uint32_t child[kWideArity];
};
static_assert(sizeof(WideNode) == 448, "WideNode layout");
/// The nodes of a tree, on huge pages when large (ray_huge_pages.hpp: a ray reads ~20 of them at random).
using WideNodes = std::vector<WideNode, detail::HugePageAllocator<WideNode>>;

class WideBvh {
 public:
  /// Collapses `bvh` (which must have at least 2 leaves; with fewer there is nothing to collapse).
  void collapse(const RayBvh& bvh, const broadphase::AabbSoa& boxes);
  /// Copies the boxes of a refitted `bvh` (same topology as at collapse()) into the wide nodes, in parallel.
  void refit(const RayBvh& bvh, const broadphase::AabbSoa& boxes);

  const WideNodes& nodes() const { return nodes_; }
  void clear() { nodes_.clear(), source_.clear(); }

 private:
  WideNodes nodes_;                    // node 0 is the root
  std::vector<std::uint32_t> source_;  // per node and slot: the binary reference whose box fills the slot
};

}  // namespace batchcol
