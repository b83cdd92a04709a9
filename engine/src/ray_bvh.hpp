// Linear BVH over float boxes: T. Karras, "Maximizing parallelism in the construction of BVHs, octrees, and k-d
// trees", HPG 2012. Leaves are the boxes sorted by the 30-bit Morton code of their centres (the broad phase's TBB
// radix sort); every internal node is built independently from the sorted keys, then boxes are refitted bottom-up
// (the second child to arrive at a node computes its box, so each node is written once). Box unions are min/max of
// floats: exact, so the tree is bitwise the same for any thread count.
#pragma once

#include "broadphase/aabb_soa.hpp"

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

namespace batchcol {

/// A node reference: a leaf (kLeafBit set; the low bits are the leaf index, i.e. the rank in Morton order) or an
/// internal node.
constexpr std::uint32_t kLeafBit = 0x80000000u;

struct BvhBox {
  float lo[3], hi[3];
};

/// An internal node holds the boxes of both children, so traversal reads one cache line to test two boxes.
struct alignas(64) BvhNode {  // one cache line per node (56 bytes of data)
  BvhBox box[2];
  std::uint32_t child[2];
};

class RayBvh {
 public:
  /// Builds the hierarchy over `boxes` (one per object). Leaf k is object leaf_object()[k]. Runs in the caller's
  /// TBB arena.
  void build(const broadphase::AabbSoa& boxes);
  /// New boxes for the same objects (same count and numbering as the last build): boxes only, same topology.
  void refit(const broadphase::AabbSoa& boxes);

  std::size_t leaf_count() const { return leaf_object_.size(); }
  const std::vector<std::uint32_t>& leaf_object() const { return leaf_object_; }
  const std::vector<BvhNode>& nodes() const { return nodes_; }
  /// The root reference (a leaf when there is one object); only valid when leaf_count() > 0.
  std::uint32_t root() const { return leaf_count() == 1 ? kLeafBit : 0u; }
  /// Parent node of internal node i (entry i, i in [0, n - 1); the root's entry is unused) and of leaf k (entry
  /// n - 1 + k), for bottom-up passes over the tree.
  const std::vector<std::uint32_t>& parents() const { return parent_; }
  /// The box of the single leaf when there is one object.
  const BvhBox& single_box() const { return single_; }

 private:
  std::vector<std::uint64_t> keys_, scratch_;
  std::vector<std::array<std::uint32_t, 256>> histograms_;
  std::vector<std::uint32_t> leaf_object_;
  std::vector<BvhNode> nodes_;
  std::vector<std::uint32_t> parent_;       // internal nodes [0, n-1) then leaves [n-1, 2n-1): parent node index
  std::unique_ptr<std::atomic<std::uint32_t>[]> arrivals_;  // per internal node, for the bottom-up refit
  std::size_t arrivals_size_ = 0;
  BvhBox single_{};
};

}  // namespace batchcol
