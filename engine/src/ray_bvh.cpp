#include "ray_bvh.hpp"

#include "broadphase/radix_sort.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>

namespace batchcol {
namespace {

// Spreads the low 10 bits of v to every third bit (bits 0, 3, ..., 27).
std::uint32_t spread_bits(std::uint32_t v) {
  v &= 0x3ffu;
  v = (v | (v << 16)) & 0x030000ffu;
  v = (v | (v << 8)) & 0x0300f00fu;
  v = (v | (v << 4)) & 0x030c30c3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

struct Bounds {
  float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
};

BvhBox box_of(const broadphase::AabbSoa& b, std::size_t i) {
  return {{b.min_x[i], b.min_y[i], b.min_z[i]}, {b.max_x[i], b.max_y[i], b.max_z[i]}};
}

BvhBox unite(const BvhBox& a, const BvhBox& b) {
  BvhBox r;
  for (int k = 0; k < 3; ++k) r.lo[k] = std::min(a.lo[k], b.lo[k]), r.hi[k] = std::max(a.hi[k], b.hi[k]);
  return r;
}

// Length of the common prefix of keys i and j (64 - 1 when equal cannot happen: keys end in the object index);
// -1 outside [0, n).
int delta(const std::uint64_t* keys, std::int64_t n, std::int64_t i, std::int64_t j) {
  if (j < 0 || j >= n) return -1;
  return __builtin_clzll(keys[i] ^ keys[j]);
}

}  // namespace

void RayBvh::build(const broadphase::AabbSoa& boxes) {
  const std::size_t n = boxes.size();
  leaf_object_.resize(n);
  if (n == 0) return;
  if (n == 1) {
    leaf_object_[0] = 0;
    nodes_.clear();
    single_ = box_of(boxes, 0);
    return;
  }
  // Bounds of the box centres (centres doubled: lo + hi, to stay in float without a rounding halving).
  const Bounds bounds = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, 4096), Bounds{},
      [&](const tbb::blocked_range<std::size_t>& r, Bounds b) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) {
          const float c[3] = {boxes.min_x[i] + boxes.max_x[i], boxes.min_y[i] + boxes.max_y[i],
                              boxes.min_z[i] + boxes.max_z[i]};
          for (int k = 0; k < 3; ++k) b.lo[k] = std::min(b.lo[k], c[k]), b.hi[k] = std::max(b.hi[k], c[k]);
        }
        return b;
      },
      [](Bounds a, const Bounds& b) {
        for (int k = 0; k < 3; ++k) a.lo[k] = std::min(a.lo[k], b.lo[k]), a.hi[k] = std::max(a.hi[k], b.hi[k]);
        return a;
      });
  keys_.resize(n);
  scratch_.resize(n);
  double scale[3];
  for (int k = 0; k < 3; ++k) {
    const double extent = double(bounds.hi[k]) - double(bounds.lo[k]);
    scale[k] = extent > 0.0 ? 1023.0 / extent : 0.0;
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      const double c[3] = {double(boxes.min_x[i] + boxes.max_x[i]), double(boxes.min_y[i] + boxes.max_y[i]),
                           double(boxes.min_z[i] + boxes.max_z[i])};
      std::uint32_t q[3];
      for (int k = 0; k < 3; ++k)
        q[k] = static_cast<std::uint32_t>(std::min(1023.0, std::max(0.0, (c[k] - bounds.lo[k]) * scale[k])));
      const std::uint32_t morton = (spread_bits(q[0]) << 2) | (spread_bits(q[1]) << 1) | spread_bits(q[2]);
      keys_[i] = (std::uint64_t(morton) << 32) | std::uint64_t(i);
    }
  });
  broadphase::radix_sort(keys_.data(), scratch_.data(), n, broadphase::digit_shifts(32, 62), histograms_);
  for (std::size_t k = 0; k < n; ++k) leaf_object_[k] = static_cast<std::uint32_t>(keys_[k] & 0xffffffffu);

  nodes_.resize(n - 1);
  parent_.assign(2 * n - 1, 0);
  if (arrivals_size_ < n - 1) {
    arrivals_.reset(new std::atomic<std::uint32_t>[n - 1]);
    arrivals_size_ = n - 1;
  }
  const std::int64_t m = static_cast<std::int64_t>(n);
  const std::uint64_t* keys = keys_.data();
  tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, m - 1, 1024), [&](const tbb::blocked_range<std::int64_t>& r) {
    for (std::int64_t i = r.begin(); i < r.end(); ++i) {
      // Direction of the node's range, then its other end j by exponential + binary search (Karras, Fig. 4).
      const int d = delta(keys, m, i, i + 1) - delta(keys, m, i, i - 1) > 0 ? 1 : -1;
      const int d_min = delta(keys, m, i, i - d);
      std::int64_t l_max = 2;
      while (delta(keys, m, i, i + l_max * d) > d_min) l_max *= 2;
      std::int64_t l = 0;
      for (std::int64_t t = l_max / 2; t >= 1; t /= 2)
        if (delta(keys, m, i, i + (l + t) * d) > d_min) l += t;
      const std::int64_t j = i + l * d;
      // Split position: the highest differing bit inside [min(i, j), max(i, j)].
      const int d_node = delta(keys, m, i, j);
      std::int64_t s = 0;
      for (std::int64_t div = 2;; div *= 2) {
        const std::int64_t t = (l + div - 1) / div;
        if (delta(keys, m, i, i + (s + t) * d) > d_node) s += t;
        if (t <= 1) break;
      }
      const std::int64_t gamma = i + s * d + std::min(d, 0);
      BvhNode& node = nodes_[static_cast<std::size_t>(i)];
      const bool left_leaf = std::min(i, j) == gamma, right_leaf = std::max(i, j) == gamma + 1;
      node.child[0] = static_cast<std::uint32_t>(gamma) | (left_leaf ? kLeafBit : 0u);
      node.child[1] = static_cast<std::uint32_t>(gamma + 1) | (right_leaf ? kLeafBit : 0u);
      parent_[left_leaf ? std::size_t(m - 1 + gamma) : std::size_t(gamma)] = static_cast<std::uint32_t>(i);
      parent_[right_leaf ? std::size_t(m + gamma) : std::size_t(gamma + 1)] = static_cast<std::uint32_t>(i);
    }
  });
  refit(boxes);
}

void RayBvh::refit(const broadphase::AabbSoa& boxes) {
  const std::size_t n = leaf_object_.size();
  if (n == 1) single_ = box_of(boxes, 0);
  if (n <= 1) return;
  for (std::size_t i = 0; i + 1 < n; ++i) arrivals_[i].store(0, std::memory_order_relaxed);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k < r.end(); ++k) {
      std::uint32_t child = static_cast<std::uint32_t>(k) | kLeafBit;
      BvhBox box = box_of(boxes, leaf_object_[k]);
      std::uint32_t node = parent_[n - 1 + k];
      for (;;) {
        BvhNode& p = nodes_[node];
        p.box[p.child[0] == child ? 0 : 1] = box;
        // The first child to arrive stops; the second sees the first's box (acq_rel) and goes up.
        if (arrivals_[node].fetch_add(1, std::memory_order_acq_rel) == 0) break;
        if (node == 0) break;
        box = unite(p.box[0], p.box[1]);
        child = node;
        node = parent_[node];
      }
    }
  });
}

}  // namespace batchcol
