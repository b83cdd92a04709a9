#include "ray_wide_bvh.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

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

void WideBvh::collapse(const RayBvh& bvh, const broadphase::AabbSoa& boxes) {
  nodes_.clear();
  source_.clear();
  if (bvh.leaf_count() < 2) return;
  // Depth first, one wide node per step; a wide node's index is fixed when it is created, so the numbering (and the
  // whole structure) depends on the binary tree only.
  struct Task {
    std::uint32_t binary, wide;
  };
  std::vector<Task> todo{{0u, 0u}};
  nodes_.emplace_back();
  source_.resize(kWideArity);
  while (!todo.empty()) {
    const Task task = todo.back();
    todo.pop_back();
    std::uint32_t refs[kWideArity];
    BvhBox slot_box[kWideArity];
    int count = 2;
    refs[0] = bvh.nodes()[task.binary].child[0], refs[1] = bvh.nodes()[task.binary].child[1];
    slot_box[0] = box_of_ref(bvh, boxes, refs[0]), slot_box[1] = box_of_ref(bvh, boxes, refs[1]);
    while (count < kWideArity) {
      int open = -1;
      double best = -1.0;
      for (int k = 0; k < count; ++k) {
        if (refs[k] & kLeafBit) continue;
        const double a = half_area(slot_box[k]);
        if (a > best) best = a, open = k;
      }
      if (open < 0) break;
      const BvhNode& n = bvh.nodes()[refs[open]];
      refs[count] = n.child[1], slot_box[count] = box_of_ref(bvh, boxes, n.child[1]);
      refs[open] = n.child[0], slot_box[open] = box_of_ref(bvh, boxes, n.child[0]);
      ++count;
    }
    for (int k = 0; k < kWideArity; ++k) {
      source_[std::size_t(task.wide) * kWideArity + k] = k < count ? refs[k] : kWideEmpty;
      if (k >= count) {
        clear_slot(nodes_[task.wide], k);
      } else if (refs[k] & kLeafBit) {
        set_slot(nodes_[task.wide], k, slot_box[k], refs[k]);
      } else {
        const std::uint32_t child = static_cast<std::uint32_t>(nodes_.size());
        nodes_.emplace_back();
        source_.resize(nodes_.size() * kWideArity);
        set_slot(nodes_[task.wide], k, slot_box[k], child);
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
