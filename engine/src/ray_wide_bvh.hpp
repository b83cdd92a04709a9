// An 8-wide BVH collapsed from the binary LBVH (ray_bvh.hpp) for traversal: each node holds the boxes of up to 8
// children in structure-of-arrays float form, so one SIMD pass tests a ray against all of them (ray_wide_traverse).
// Collapse: each wide node's children are the binary descendants (at most 8) that minimise the expected number of
// wide-node visits, the sum of the wide nodes' surface areas, chosen by dynamic programming over the binary tree
// (after Ylitie et al., HPG 2017; ray_wide_bvh.cpp). Fewer, fuller nodes mean fewer box tests per ray than the
// binary tree's pairs.
// The topology depends only on the binary tree (built deterministically) and the boxes; every child slot remembers
// its binary node so a refit is a parallel copy of the binary tree's refitted boxes (exact float min/max).
#pragma once

#include "broadphase/aabb_soa.hpp"
#include "ray_bvh.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace batchcol {

constexpr int kWideArity = 8;
/// Child reference of an empty slot; its box is empty (lo = +inf, hi = -inf) and never hit.
constexpr std::uint32_t kWideEmpty = 0xffffffffu;

/// One node: child k's box is [lo_x[k], hi_x[k]] x ... ; child[k] is kLeafBit | leaf index (Morton rank), a node
/// index, or kWideEmpty. 224 bytes of data, aligned to whole cache lines.
struct alignas(64) WideNode {
  float lo_x[kWideArity], lo_y[kWideArity], lo_z[kWideArity];
  float hi_x[kWideArity], hi_y[kWideArity], hi_z[kWideArity];
  std::uint32_t child[kWideArity];
};
static_assert(sizeof(WideNode) == 256, "WideNode layout");

/// The same node with its child boxes quantised to 8 bits in a per-node frame (after Ylitie et al., HPG 2017), half
/// the size: trees of WideNodes larger than a core's L2 (100k objects: 7.6 MB) miss it on most node visits, and this
/// halves the lines a visit loads. Plane p of slot k (p: lo_x, lo_y, lo_z, hi_x, hi_y, hi_z; axis a = p % 3) is the
/// float origin[a] + float(q[p][k]) * scale[a], evaluated in that order in float (scale is a power of two, so the
/// product is exact and a fused multiply-add gives the same bits). The codes are chosen against exactly that value
/// (quantize(), ray_wide_bvh.cpp): lo planes at or below the WideNode's, hi planes at or above, so a dequantised box
/// contains the float box and the traversal's conservative float slab test (ray_wide_traverse.hpp) holds for it
/// unchanged; boxes only grow. Slots without a child have their bit clear in `live` (their codes are no box).
struct alignas(64) WideQNode {
  float origin[3], scale[3];
  std::uint8_t q[6][kWideArity];
  std::uint32_t child[kWideArity];
  std::uint32_t live;
};
static_assert(sizeof(WideQNode) == 128, "WideQNode layout");

/// Trees of WideNodes from this size on also get quantised nodes (WideBvh::quantized()): smaller ones stay in the L2
/// as floats, where dequantising would only add instructions.
constexpr std::size_t kWideQuantizeBytes = std::size_t(1) << 20;

class WideBvh {
 public:
  /// Collapses `bvh` (which must have at least 2 leaves; with fewer there is nothing to collapse); the nodes are also
  /// quantised when they take at least `quantize_from` bytes as WideNodes (the tests pass 0).
  void collapse(const RayBvh& bvh, const broadphase::AabbSoa& boxes, std::size_t quantize_from = kWideQuantizeBytes);
  /// Copies the boxes of a refitted `bvh` (same topology as at collapse()) into the wide nodes, in parallel (and
  /// quantises them again, as at collapse()).
  void refit(const RayBvh& bvh, const broadphase::AabbSoa& boxes);

  const std::vector<WideNode>& nodes() const { return nodes_; }
  /// The nodes quantised (same indices and children), or empty: trees below kWideQuantizeBytes, and trees with a box
  /// coordinate that is not finite or too large for an exact frame (those keep the float nodes only).
  const std::vector<WideQNode>& quantized() const { return qnodes_; }
  void clear() { nodes_.clear(), source_.clear(), qnodes_.clear(); }

 private:
  std::vector<WideNode> nodes_;        // node 0 is the root
  std::vector<std::uint32_t> source_;  // per node and slot: the binary reference whose box fills the slot
  std::vector<WideQNode> qnodes_;
  std::size_t quantize_from_ = kWideQuantizeBytes;
  void quantize();
};

/// Quantises one node (see WideQNode); false when a live box has a coordinate that is not finite or the frame's scale
/// would pass 2^100 (the codes' products must stay exact and finite).
bool quantize_wide_node(const WideNode& in, WideQNode& out);
/// Plane p of slot k as the traversal computes it.
inline float dequantized(const WideQNode& n, int p, int k) {
  return n.origin[p % 3] + float(n.q[p][k]) * n.scale[p % 3];
}

}  // namespace batchcol
