// The 8-wide BVH of the ray scenes (engine/src/ray_wide_bvh.*, ray_wide_traverse.*): structure after collapse and
// refit, the float slab test never rejecting a box the exact ray segment touches (rays built to end exactly on a
// box's boundary, grazing faces, edges and corners, at several scales), not being much looser than the exact test,
// and the same visiting order on every instruction set.
#include "support/ray_reference.hpp"
#include "engine/src/ray_bvh.hpp"
#include "engine/src/ray_wide_bvh.hpp"
#include "engine/src/ray_wide_traverse.hpp"
#include "engine/src/rays_common.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace batchcol {
namespace {

using Rng = std::mt19937_64;

double uniform(Rng& rng, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }

// Random boxes in [-extent, extent]^3 with sides up to `size`, coordinates floats (the AabbSoa's own type).
broadphase::AabbSoa random_boxes(Rng& rng, std::size_t n, double extent, double size) {
  broadphase::AabbSoa b;
  b.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    float* lo[3] = {&b.min_x[i], &b.min_y[i], &b.min_z[i]};
    float* hi[3] = {&b.max_x[i], &b.max_y[i], &b.max_z[i]};
    for (int k = 0; k < 3; ++k) {
      const double c = uniform(rng, -extent, extent), h = uniform(rng, 0.0, size);
      *lo[k] = static_cast<float>(c - h), *hi[k] = static_cast<float>(c + h);
      if (i % 7 == 0 && k == 1) *hi[k] = *lo[k];  // flat boxes (triangles, discs seen edge-on)
    }
  }
  return b;
}

// Random boxes (random_boxes()), their binary tree and its wide collapse.
struct Trees {
  broadphase::AabbSoa b;
  RayBvh bvh;
  WideBvh wide;
  Trees(Rng& rng, std::size_t n, double extent, double size) : b(random_boxes(rng, n, extent, size)) {
    bvh.build(b);
    wide.collapse(bvh, b);
  }
};

struct Leaves {
  std::vector<std::uint32_t> seen;  // leaf ranks in visiting order
};

bool record(void* context, std::uint32_t leaf, float&) {
  static_cast<Leaves*>(context)->seen.push_back(leaf);
  return true;
}

// The box of a wide slot's subtree, from the leaves below it (exact float min/max).
void check_subtree(const WideBvh& wide, const RayBvh& bvh, const broadphase::AabbSoa& b, std::uint32_t node,
                   std::vector<int>& count, float out_lo[3], float out_hi[3]) {
  for (int k = 0; k < 3; ++k) out_lo[k] = INFINITY, out_hi[k] = -INFINITY;
  const WideNode& n = wide.nodes()[node];
  int used = 0;
  for (int s = 0; s < kWideArity; ++s) {
    if (n.child[s] == kWideEmpty) {
      EXPECT_EQ(n.lo_x[s], INFINITY);
      EXPECT_EQ(n.hi_z[s], -INFINITY);
      continue;
    }
    ++used;
    float lo[3], hi[3];
    if (n.child[s] & kLeafBit) {
      const std::uint32_t leaf = n.child[s] & ~kLeafBit;
      ++count.at(leaf);
      const std::uint32_t i = bvh.leaf_object()[leaf];
      lo[0] = b.min_x[i], lo[1] = b.min_y[i], lo[2] = b.min_z[i], hi[0] = b.max_x[i], hi[1] = b.max_y[i],
      hi[2] = b.max_z[i];
    } else {
      EXPECT_GT(n.child[s], node);  // depth-first numbering: children after their parent
      check_subtree(wide, bvh, b, n.child[s], count, lo, hi);
    }
    // The slot holds exactly the union of its subtree (min / max of floats are exact).
    EXPECT_EQ(n.lo_x[s], lo[0]);
    EXPECT_EQ(n.lo_y[s], lo[1]);
    EXPECT_EQ(n.lo_z[s], lo[2]);
    EXPECT_EQ(n.hi_x[s], hi[0]);
    EXPECT_EQ(n.hi_y[s], hi[1]);
    EXPECT_EQ(n.hi_z[s], hi[2]);
    for (int k = 0; k < 3; ++k) out_lo[k] = std::min(out_lo[k], lo[k]), out_hi[k] = std::max(out_hi[k], hi[k]);
  }
  EXPECT_GE(used, 2);
}

void check_structure(const WideBvh& wide, const RayBvh& bvh, const broadphase::AabbSoa& b) {
  std::vector<int> count(b.size(), 0);
  float lo[3], hi[3];
  check_subtree(wide, bvh, b, 0, count, lo, hi);
  for (std::size_t i = 0; i < count.size(); ++i) EXPECT_EQ(count[i], 1) << "leaf " << i;
}

TEST(RayWideBvh, CollapseAndRefitKeepEveryLeafOnceInsideExactUnions) {
  Rng rng(5);
  for (std::size_t n : {2u, 3u, 9u, 64u, 65u, 3000u}) {
    SCOPED_TRACE(n);
    broadphase::AabbSoa b = random_boxes(rng, n, 50.0, 2.0);
    RayBvh bvh;
    bvh.build(b);
    WideBvh wide;
    wide.collapse(bvh, b);
    if (n > 8) {
      EXPECT_LE(wide.nodes().size() * 4, n);  // mostly full nodes (a binary tree has n - 1)
    }
    check_structure(wide, bvh, b);
    // Move every box, refit both trees: same topology, the new unions.
    const broadphase::AabbSoa moved = random_boxes(rng, n, 50.0, 2.0);
    bvh.refit(moved);
    wide.refit(bvh, moved);
    check_structure(wide, bvh, moved);
  }
}

// The ray index's large arrays are mapped for huge pages (ray_huge_pages.hpp): 2 MiB-aligned from kHugePageMin on
// (on Linux), the ordinary allocator's alignment below, and the contents kept through growth across the threshold
// (a vector copies into a new mapping). Whether the kernel backs them with huge pages is its choice; the results
// cannot depend on it, which the scene tests' bitwise checks cover.
TEST(RayWideBvh, LargeArraysAreHugePageAlignedAndKeepTheirContents) {
  std::vector<std::uint64_t, detail::HugePageAllocator<std::uint64_t>> v;
  const std::size_t large = 3 * detail::kHugePageMin / sizeof(std::uint64_t) + 5;
  for (std::size_t i = 0; i < large; ++i) {
    v.push_back(i * 0x9e3779b97f4a7c15ull);
    if (i == 7) {
      EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % alignof(std::uint64_t), 0u);
    }
  }
#if defined(__linux__)
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % detail::kHugePageBytes, 0u);
#endif
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < large; ++i) wrong += v[i] != i * 0x9e3779b97f4a7c15ull;
  EXPECT_EQ(wrong, 0u);
  // A tree whose nodes pass the threshold: aligned, and whole after a refit.
  Rng rng(11);
  Trees trees(rng, 40000, 200.0, 2.0);
  auto& [b, bvh, wide] = trees;
  ASSERT_GE(wide.nodes().size() * sizeof(WideNode), detail::kHugePageMin);
#if defined(__linux__)
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(wide.nodes().data()) % detail::kHugePageBytes, 0u);
#endif
  check_structure(wide, bvh, b);
  const broadphase::AabbSoa moved = random_boxes(rng, 40000, 200.0, 2.0);
  bvh.refit(moved);
  wide.refit(bvh, moved);
  check_structure(wide, bvh, moved);
}

// Exact reference: does the segment o + t d, t in [0, t_max], touch the closed box? Only used on rays whose
// parameters are exact below (t_max = 1 on a boundary point) or with a relative margin.
bool slab_hits(const double lo[3], const double hi[3], const double o[3], const double d[3], double t_max) {
  return testing::exact_box_entry(o, d, lo, hi, t_max) != INFINITY;
}

TEST(RayWideBvh, FloatTestNeverMissesABoxTheSegmentTouches) {
  // Each ray ends exactly (t = t_max) on a boundary point p of box `target` (a corner, an edge or a face point),
  // from an origin that is generally no float, often in a face's plane (direction component 0: grazing).
  // o = m 2^-30 with |m| < 2^40 and p a float of magnitude in [2^-7, 1024]: p - o is a multiple of 2^-30 below 2^41,
  // exact in double, so the exact segment touches the box at t = t_max. Scaling by powers of two keeps that exact.
  Rng rng(17);
  int checked = 0, grazing = 0;
  for (int scale_exp : {-40, -10, 0, 12, 40}) {
    const double scale = std::ldexp(1.0, scale_exp);
    broadphase::AabbSoa b = random_boxes(rng, 500, 400.0, 3.0);
    for (std::size_t i = 0; i < b.size(); ++i) {
      b.min_x[i] = float(b.min_x[i] * scale), b.min_y[i] = float(b.min_y[i] * scale);
      b.min_z[i] = float(b.min_z[i] * scale), b.max_x[i] = float(b.max_x[i] * scale);
      b.max_y[i] = float(b.max_y[i] * scale), b.max_z[i] = float(b.max_z[i] * scale);
    }
    RayBvh bvh;
    bvh.build(b);
    WideBvh wide;
    wide.collapse(bvh, b);
    std::vector<std::uint32_t> rank(b.size());
    for (std::uint32_t k = 0; k < b.size(); ++k) rank[bvh.leaf_object()[k]] = k;
    for (int trial = 0; trial < 3000; ++trial) {
      const std::size_t target = rng() % b.size();
      const double lo[3] = {b.min_x[target], b.min_y[target], b.min_z[target]};
      const double hi[3] = {b.max_x[target], b.max_y[target], b.max_z[target]};
      double p[3], o[3], d[3];
      const int fixed = int(rng() % 3) + 1;  // coordinates on a bound: 1 face, 2 edge, 3 corner
      for (int k = 0; k < 3; ++k) {
        if (k < fixed) {
          p[k] = rng() % 2 ? lo[k] : hi[k];
        } else {
          // A float strictly inside [lo, hi] (or the bound itself for a flat side).
          p[k] = double(float(uniform(rng, lo[k], hi[k])));
          p[k] = std::min(std::max(p[k], lo[k]), hi[k]);
        }
      }
      // Below 2^-7 (times the scale) a float's ulp is finer than 2^-30 and p - o might round: skip those.
      if (std::fabs(p[0]) < 0x1p-7 * scale || std::fabs(p[1]) < 0x1p-7 * scale || std::fabs(p[2]) < 0x1p-7 * scale)
        continue;
      for (int k = 0; k < 3; ++k) {
        // The origin: mostly a non-float within 2^10 scale of p; sometimes in the plane of the bound p lies on.
        const int kind = int(rng() % 4);
        if (kind == 0) {
          o[k] = p[k];
        } else {
          const double m = std::floor(uniform(rng, -1.0, 1.0) * 0x1p39);
          o[k] = m * 0x1p-30 * scale;
        }
      }
      const int d_exp = int(rng() % 9) - 3;  // direction scaled by 2^d_exp, t_max by 2^-d_exp
      for (int k = 0; k < 3; ++k) d[k] = std::ldexp(p[k] - o[k], d_exp);
      if (d[0] == 0.0 && d[1] == 0.0 && d[2] == 0.0) continue;
      const double t_max = std::ldexp(1.0, -d_exp);
      ASSERT_TRUE(slab_hits(lo, hi, o, d, t_max));  // the construction is exact
      if (!wide_ray_supported(o, d)) continue;
      grazing += (d[0] == 0.0) + (d[1] == 0.0) + (d[2] == 0.0) > 0;
      const WideRay ray = make_wide_ray(o, d);
      for (int isa = 0; isa < 3; ++isa) {
        const WideTraverse traverse = wide_traverse_for(isa);
        if (!traverse) continue;
        Leaves seen;
        traverse(wide.nodes().data(), ray, wide_limit(t_max), record, &seen);
        const bool found = std::find(seen.seen.begin(), seen.seen.end(), rank[target]) != seen.seen.end();
        ASSERT_TRUE(found) << "isa " << isa << " scale 2^" << scale_exp << " box " << target << " o " << o[0] << ' '
                           << o[1] << ' ' << o[2] << " d " << d[0] << ' ' << d[1] << ' ' << d[2];
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 12000);
  EXPECT_GT(grazing, 1000);
}

/// One wide node over unit-height boxes [x_lo, x_lo + 0.5] x [-1, 1]^2 (the ordering tests' scenes): every leaf a
/// child of the root, which the tests check as their premise.
struct RowOfBoxes {
  broadphase::AabbSoa b;
  RayBvh bvh;
  WideBvh wide;
  RowOfBoxes(const float* x_lo, std::size_t n) {
    b.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      b.min_x[i] = x_lo[i], b.max_x[i] = x_lo[i] + 0.5f;
      b.min_y[i] = b.min_z[i] = -1.0f, b.max_y[i] = b.max_z[i] = 1.0f;
    }
    bvh.build(b);
    wide.collapse(bvh, b);
  }
  const WideNode& root() const { return wide.nodes()[0]; }
  std::uint32_t object(int slot) const { return bvh.leaf_object()[root().child[slot] & ~kLeafBit]; }
};

/// Every instruction set's traversal of `row` by the ray (o, d) visits the leaves of `slots` in their order.
void expect_visits(const RowOfBoxes& row, const std::vector<int>& slots, const double* o, const double* d,
                   const std::string& what) {
  std::vector<std::uint32_t> expected;
  for (int s : slots) expected.push_back(row.root().child[s] & ~kLeafBit);
  const WideRay ray = make_wide_ray(o, d);
  for (int isa = 0; isa < 3; ++isa) {
    if (const WideTraverse traverse = wide_traverse_for(isa)) {
      Leaves seen;
      traverse(row.wide.nodes().data(), ray, wide_limit(INFINITY), record, &seen);
      EXPECT_EQ(seen.seen, expected) << what << " isa " << isa;
    }
  }
}

TEST(RayWideBvh, ChildrenAreVisitedNearestFirstTiesInSlotOrderInEveryOctant) {
  // Seven boxes in one wide node (three of them identical, so their entries tie), crossed by a ray along +-x in each
  // of the 8 direction octants: the traversal runs one loop per octant and ranks 3+ hit children without a sort, and
  // must visit them by entry (the near plane: x_lo going +x, x_hi going -x), equal entries in slot order.
  const float x_lo[7] = {0.0f, 3.0f, 1.0f, 3.0f, 5.0f, 2.0f, 3.0f};
  const RowOfBoxes row(x_lo, 7);
  ASSERT_EQ(row.wide.nodes().size(), 1u);  // the premise: every leaf is a child of the root
  for (int octant = 0; octant < 8; ++octant) {
    const double sx = octant & 1 ? -1.0 : 1.0, sy = octant & 2 ? -1.0 : 1.0, sz = octant & 4 ? -1.0 : 1.0;
    const double o[3] = {-50.0 * sx + 2.75, 0.0, 0.0}, d[3] = {sx, 1e-3 * sy, 1e-3 * sz};
    std::vector<int> slots;
    for (int s = 0; s < kWideArity; ++s)
      if (row.root().child[s] != kWideEmpty) slots.push_back(s);
    ASSERT_EQ(slots.size(), 7u);
    const auto entry = [&](int s) {
      const std::uint32_t i = row.object(s);
      return sx > 0 ? double(row.b.min_x[i]) : -double(row.b.max_x[i]);
    };
    std::stable_sort(slots.begin(), slots.end(), [&](int a, int c) { return entry(a) < entry(c); });
    expect_visits(row, slots, o, d, "octant " + std::to_string(octant));
  }
}

TEST(RayWideBvh, SixteenChildrenInOneNodeAreRankedAcrossBothHalves) {
  // Sixteen boxes fit one wide node (kWideArity = 16; an 8-wide tree needed 3 nodes here). AVX2 and the baseline
  // test its slots as two 8-lane halves and AVX-512 as one 16-lane vector; entries tie within and across the halves
  // (x_lo 3 appears five times, 1 three times), so a rank that ignored the other half or its slot order would show.
  // Two origins: far outside (every entry positive), and inside the five boxes at x_lo 3, whose entries are then 0
  // (the rank compares entry bits, and 0 is the edge of that rule). Every octant, every instruction set: the
  // visiting order is by entry, ties in slot order.
  const float x_lo[16] = {3.0f, 0.0f, 1.0f, 3.0f, 6.0f, 2.0f, 3.0f, 1.0f,
                          4.0f, 3.0f, 7.0f, 1.0f, 3.0f, 5.0f, 8.0f, 9.0f};
  const RowOfBoxes row(x_lo, 16);
  ASSERT_EQ(row.wide.nodes().size(), 1u);  // every leaf is a child of the root
  const auto& b = row.b;
  for (const bool inside : {false, true}) {
    for (int octant = 0; octant < 8; ++octant) {
      const double sx = octant & 1 ? -1.0 : 1.0, sy = octant & 2 ? -1.0 : 1.0, sz = octant & 4 ? -1.0 : 1.0;
      const double ox = inside ? 3.25 : -50.0 * sx + 4.75;
      const double o[3] = {ox, 0.0, 0.0}, d[3] = {sx, 1e-3 * sy, 1e-3 * sz};
      std::vector<int> slots;
      const auto box = [&](int s) { return row.object(s); };
      for (int s = 0; s < kWideArity; ++s) {
        if (row.root().child[s] == kWideEmpty) continue;
        const double far = sx > 0 ? double(b.max_x[box(s)]) - ox : ox - double(b.min_x[box(s)]);
        if (far >= 0.0) slots.push_back(s);  // not behind the origin
      }
      ASSERT_EQ(slots.size(), inside ? (sx > 0 ? 11u : 10u) : 16u);
      const auto entry = [&](int s) {
        const double near = sx > 0 ? double(b.min_x[box(s)]) - ox : ox - double(b.max_x[box(s)]);
        return std::max(near, 0.0);
      };
      std::stable_sort(slots.begin(), slots.end(), [&](int a, int c) { return entry(a) < entry(c); });
      expect_visits(row, slots, o, d, "inside " + std::to_string(inside) + " octant " + std::to_string(octant));
    }
  }
}

TEST(RayWideBvh, FloatTestIsTightAndTheSameOnEveryInstructionSet) {
  // Random rays: every leaf the float test visits is hit by the exact test on the box widened by 1e-5 of its scale,
  // and every leaf the exact test hits on the box narrowed by 1e-5 is visited (no test this bounds can pass by
  // visiting everything). The visiting order is the same for every instruction set.
  Rng rng(23);
  const Trees trees(rng, 2000, 60.0, 2.0);
  const auto& [b, bvh, wide] = trees;
  std::size_t visited = 0, isa_runs = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    double o[3], d[3];
    for (int k = 0; k < 3; ++k) o[k] = uniform(rng, -80, 80), d[k] = uniform(rng, -60, 60) - o[k];
    if (trial % 5 == 0) d[trial % 3] = 0.0;  // axis-parallel rays
    const double t_max = trial % 3 == 0 ? uniform(rng, 10, 100) : INFINITY;
    const WideRay ray = make_wide_ray(o, d);
    Leaves reference;
    wide_traverse_for(0)(wide.nodes().data(), ray, wide_limit(t_max), record, &reference);
    for (int isa = 1; isa < 3; ++isa) {
      if (const WideTraverse traverse = wide_traverse_for(isa)) {
        Leaves seen;
        traverse(wide.nodes().data(), ray, wide_limit(t_max), record, &seen);
        EXPECT_EQ(seen.seen, reference.seen) << "isa " << isa;
        ++isa_runs;
      }
    }
    std::vector<char> in(b.size(), 0);
    for (std::uint32_t leaf : reference.seen) in[leaf] = 1;
    visited += reference.seen.size();
    for (std::uint32_t leaf = 0; leaf < b.size(); ++leaf) {
      const std::uint32_t i = bvh.leaf_object()[leaf];
      const double lo[3] = {b.min_x[i], b.min_y[i], b.min_z[i]}, hi[3] = {b.max_x[i], b.max_y[i], b.max_z[i]};
      const double pad = 1e-5 * 100.0;
      const double wlo[3] = {lo[0] - pad, lo[1] - pad, lo[2] - pad}, whi[3] = {hi[0] + pad, hi[1] + pad, hi[2] + pad};
      const double nlo[3] = {lo[0] + pad, lo[1] + pad, lo[2] + pad}, nhi[3] = {hi[0] - pad, hi[1] - pad, hi[2] - pad};
      if (in[leaf]) {
        EXPECT_TRUE(slab_hits(wlo, whi, o, d, t_max * (1 + 1e-5))) << "leaf " << leaf;
      } else if (nlo[0] <= nhi[0] && nlo[1] <= nhi[1] && nlo[2] <= nhi[2]) {
        EXPECT_FALSE(slab_hits(nlo, nhi, o, d, t_max * (1 - 1e-5))) << "leaf " << leaf;
      }
    }
  }
  EXPECT_GT(visited, 1000u);  // rays do reach boxes
  if (__builtin_cpu_supports("avx2")) {
    EXPECT_GT(isa_runs, 0u);
  }
}

TEST(RayWideBvh, InstructionSetOptionPicksThatTraversal) {
  // RayOptions::isa reaches the traversal through ray_isa_index() and select_wide_traverse(isa): each set's own loop
  // (the same code would hide a wrong mapping behind equal answers), and the AVX2 ray setup for both vector sets.
  EXPECT_EQ(detail::ray_isa_index(InstructionSet::scalar), 0);
  EXPECT_EQ(select_wide_traverse(0), wide_traverse_for(0));
  EXPECT_EQ(select_wide_ray_setup(0), wide_ray_setup_for(0));
  if (wide_traverse_for(1) != nullptr) {
    EXPECT_EQ(detail::ray_isa_index(InstructionSet::avx2), 1);
    EXPECT_EQ(select_wide_traverse(1), wide_traverse_for(1));
    EXPECT_EQ(select_wide_ray_setup(1), wide_ray_setup_for(1));
    EXPECT_NE(select_wide_traverse(1), select_wide_traverse(0));
  }
  if (wide_traverse_for(2) != nullptr) {
    EXPECT_EQ(detail::ray_isa_index(InstructionSet::avx512), 2);
    EXPECT_EQ(select_wide_traverse(2), wide_traverse_for(2));
    EXPECT_EQ(select_wide_ray_setup(2), wide_ray_setup_for(1));
    EXPECT_EQ(select_wide_traverse(), wide_traverse_for(2));
  }
}

TEST(RayWideBvh, RaysOutsideFloatRangeAreRefused) {
  const double o[3] = {0, 0, 0}, d_ok[3] = {1, 0, -0.0}, d_tiny[3] = {1, 1e-30, 0}, far_o[3] = {1e30, 0, 0};
  EXPECT_TRUE(wide_ray_supported(o, d_ok));
  EXPECT_FALSE(wide_ray_supported(o, d_tiny));
  EXPECT_FALSE(wide_ray_supported(far_o, d_ok));
  // Rounding of the limit: never below the exact value.
  for (double t : {1.0, 0.1, 1e-30, 3e38, 1e300}) EXPECT_GE(double(wide_limit(t)), t);
  EXPECT_EQ(wide_limit(INFINITY), INFINITY);
}

// The octant that picks the traversal loop: bit k set for a negative direction component k, -0 included (1 / -0 =
// -inf pairs with the hi plane), in make_wide_ray() and in the SIMD setup.
TEST(RayWideBvh, OctantIsTheDirectionsSignBits) {
  const double o[3] = {0.5, -0.25, 3.0}, values[] = {1.0, -1.0, 0.0, -0.0, 0x1p-60, -0x1p60};
  for (double x : values)
    for (double y : values)
      for (double z : values) {
        const double d[3] = {x, y, z};
        const std::uint32_t want =
            (std::signbit(x) ? 1u : 0u) | (std::signbit(y) ? 2u : 0u) | (std::signbit(z) ? 4u : 0u);
        EXPECT_EQ(make_wide_ray(o, d).octant, want) << x << " " << y << " " << z;
        for (int isa = 0; isa < 3; ++isa) {
          const WideRaySetup setup = wide_ray_setup_for(isa);
          if (setup == nullptr) continue;
          const double t_max = 1.0;
          const WideRayInput in{{&o[0], &o[1], &o[2]}, {&d[0], &d[1], &d[2]}, &t_max};
          WideRay out[kWideRaySetupLanes];
          std::uint8_t status[kWideRaySetupLanes];
          setup(in, 0, 1, out, status);
          ASSERT_EQ(status[0], std::abs(x) + std::abs(y) + std::abs(z) > 0.0 ? kWideRaySupported : kWideRayInvalid);
          if (status[0] == kWideRaySupported) {
            EXPECT_EQ(out[0].octant, want) << "isa " << isa;
          }
        }
      }
}

// wide_limit()'s branch-free rounding for limits >= 0 (the bit pattern plus one) gives round_up()'s bits: at float
// values and just beside them (where the conversion is exact or rounds either way), at 0, subnormals, the float
// range's top (FLT_MAX -> +inf) and on random magnitudes; negative and NaN limits take round_up() itself.
TEST(RayWideBvh, BranchFreeLimitGivesTheRoundUpBits) {
  const auto bits = [](float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
  };
  std::vector<double> limits = {0.0, -0.0, 0x1p-149, 0x1p-140, 1e-300, 1.0, 0.1, 3e38, 0x1.fffffep127, 1e39,
                                INFINITY, -1.0, -0x1p-149};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> exponent(-150.0, 130.0), unit(0.0, 1.0);
  for (int i = 0; i < 20000; ++i) {
    const double t = std::exp2(exponent(rng)) * (1.0 + unit(rng));
    const float f = static_cast<float>(t / double(kFarScale));
    limits.insert(limits.end(), {t, double(f) / double(kFarScale), std::nextafter(double(f), 0.0) / double(kFarScale)});
  }
  for (double t : limits) {
    const float expected = wide_limit_round_up(t * double(kFarScale));
    ASSERT_EQ(bits(wide_limit(t)), bits(expected)) << "t = " << t;
  }
  EXPECT_TRUE(std::isnan(wide_limit(NAN)));
}

// The SIMD setup of 8 rays at once (WideRaySetup, used by RaySceneIndex::cast) gives every ray the status of the
// scalar ray_is_valid() / wide_ray_supported() and, when supported, make_wide_ray()'s fields bit for bit, on every
// instruction set and for partial groups: random rays, and the cases where the rounding or the sign decides (origins
// exactly representable in float or not, +-0, subnormal and huge components, the range limits 2^-60 / 2^60), and
// invalid rays (NaN, inf, zero direction, negative or NaN t_max).
// Random rays mixed with the special values of the setup tests below.
RayBatch setup_test_rays() {
  Rng rng(19);
  RayBatch rays;
  const double special[] = {0.0, -0.0, 1.0, -1.0, 0.1, -0.1, 1.0 + 0x1p-40, -(1.0 + 0x1p-40), 0x1p-60, -0x1p-60,
                            0x1p-61, 0x1p60, -0x1p60, 0x1p61, 1e-310, -1e-310, 1e-45, 3.4e38, 1e300, NAN, INFINITY,
                            -INFINITY};
  const std::size_t s = std::size(special);
  for (int i = 0; i < 20000; ++i) {
    double o[3], d[3], t = uniform(rng, 0.0, 10.0);
    for (int k = 0; k < 3; ++k) {
      const int mode = int(rng() % 4);
      o[k] = mode == 0 ? special[rng() % s] : uniform(rng, -100.0, 100.0);
      d[k] = mode == 1 ? special[rng() % s] : uniform(rng, -1.0, 1.0);
      if (mode == 2) o[k] = double(float(o[k]));  // exactly a float: no rounding step
    }
    if (i % 50 == 0) t = special[rng() % s] * (rng() % 2 ? 1.0 : -1.0);
    if (i % 97 == 0) d[0] = d[1] = d[2] = 0.0;
    rays.add(Eigen::Vector3d(o[0], o[1], o[2]), Eigen::Vector3d(d[0], d[1], d[2]), t);
  }
  return rays;
}

TEST(RayWideBvh, SimdSetupMatchesTheScalarSetupBitwise) {
  const RayBatch rays = setup_test_rays();
  const WideRayInput in{{rays.origin.x.data(), rays.origin.y.data(), rays.origin.z.data()},
                        {rays.direction.x.data(), rays.direction.y.data(), rays.direction.z.data()},
                        rays.t_max.data()};
  std::size_t counts[3] = {0, 0, 0};
  for (int isa = 0; isa < 3; ++isa) {
    const WideRaySetup setup = wide_ray_setup_for(isa);
    if (setup == nullptr) continue;
    for (std::size_t group : {std::size_t(8), std::size_t(5)}) {
      for (std::size_t b = 0; b < rays.size(); b += group) {
        const std::size_t n = std::min(group, rays.size() - b);
        WideRay out[kWideRaySetupLanes];
        std::uint8_t status[kWideRaySetupLanes];
        setup(in, b, n, out, status);
        for (std::size_t l = 0; l < n; ++l) {
          const std::size_t i = b + l;
          const double o[3] = {rays.origin.x[i], rays.origin.y[i], rays.origin.z[i]};
          const double d[3] = {rays.direction.x[i], rays.direction.y[i], rays.direction.z[i]};
          const bool valid = detail::ray_is_valid(rays, i), supported = valid && wide_ray_supported(o, d);
          const std::uint8_t expected = supported ? kWideRaySupported : valid ? kWideRayBinary : kWideRayInvalid;
          ASSERT_EQ(status[l], expected) << "isa " << isa << " ray " << i;
          if (isa == 0 && group == 8) ++counts[expected];
          if (!supported) continue;
          const WideRay w = make_wide_ray(o, d);
          const WideRay& v = out[l];
          EXPECT_EQ(std::memcmp(w.o_near, v.o_near, sizeof w.o_near), 0) << "isa " << isa << " ray " << i;
          EXPECT_EQ(std::memcmp(w.o_far, v.o_far, sizeof w.o_far), 0) << "isa " << isa << " ray " << i;
          EXPECT_EQ(std::memcmp(w.inv, v.inv, sizeof w.inv), 0) << "isa " << isa << " ray " << i;
          EXPECT_EQ(w.octant, v.octant) << "isa " << isa << " ray " << i;
          EXPECT_EQ(std::memcmp(w.ball_o, v.ball_o, sizeof w.ball_o), 0) << "isa " << isa << " ray " << i;
          EXPECT_EQ(std::memcmp(w.ball_d, v.ball_d, sizeof w.ball_d), 0) << "isa " << isa << " ray " << i;
          EXPECT_EQ(std::memcmp(&w.ball_margin, &v.ball_margin, sizeof w.ball_margin), 0) << "isa " << isa;
          EXPECT_EQ(v.balls, nullptr);
          EXPECT_FALSE(v.prefetch);
        }
      }
    }
  }
  // Every class occurs often enough to mean something.
  EXPECT_GT(counts[kWideRayInvalid], 500u);
  EXPECT_GT(counts[kWideRayBinary], 500u);
  EXPECT_GT(counts[kWideRaySupported], 5000u);
}

// The ordered cast's setup from records at scattered addresses (WideRecordSetup) gives the status and every field of
// the array setup (WideRaySetup, checked against the scalar setup above) bit for bit: the same rays, groups of 8 and
// partial groups, records taken in a shuffled order, on every instruction set either has; the padding lanes of a
// partial group are not written (the rays after it keep a marker).
TEST(RayWideBvh, RecordSetupMatchesTheArraySetupBitwise) {
  const RayBatch rays = setup_test_rays();
  std::vector<WideRayRecord> records(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i)
    records[i] = {{rays.origin.x[i], rays.origin.y[i], rays.origin.z[i]},
                  {rays.direction.x[i], rays.direction.y[i], rays.direction.z[i]},
                  rays.t_max[i],
                  0.0};
  std::vector<std::size_t> order(rays.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), Rng(5));
  RayBatch shuffled;  // the rays in `order`, for the array setup
  for (std::size_t i : order)
    shuffled.add(Eigen::Vector3d(rays.origin.x[i], rays.origin.y[i], rays.origin.z[i]),
                 Eigen::Vector3d(rays.direction.x[i], rays.direction.y[i], rays.direction.z[i]), rays.t_max[i]);
  const WideRayInput sin{{shuffled.origin.x.data(), shuffled.origin.y.data(), shuffled.origin.z.data()},
                         {shuffled.direction.x.data(), shuffled.direction.y.data(), shuffled.direction.z.data()},
                         shuffled.t_max.data()};
  int sets = 0;
  for (int isa = 0; isa < 3; ++isa) {
    const WideRecordSetup by_record = wide_record_setup_for(isa);
    const WideRaySetup by_array = wide_ray_setup_for(isa);
    ASSERT_EQ(by_record == nullptr, by_array == nullptr) << "isa " << isa;
    if (by_record == nullptr) continue;
    ++sets;
    for (std::size_t group : {std::size_t(8), std::size_t(5), std::size_t(1)}) {
      for (std::size_t b = 0; b < rays.size(); b += group) {
        const std::size_t n = std::min(group, rays.size() - b);
        const WideRayRecord* addresses[kWideRaySetupLanes];
        for (std::size_t l = 0; l < n; ++l) addresses[l] = &records[order[b + l]];
        WideRay got[kWideRaySetupLanes], want[kWideRaySetupLanes];
        std::uint8_t got_status[kWideRaySetupLanes], want_status[kWideRaySetupLanes];
        for (std::size_t l = 0; l < kWideRaySetupLanes; ++l) got[l].ball_stride = 77, got_status[l] = 9;
        by_record(addresses, n, got, got_status);
        by_array(sin, b, n, want, want_status);
        for (std::size_t l = 0; l < n; ++l) {
          ASSERT_EQ(got_status[l], want_status[l]) << "isa " << isa << " ray " << order[b + l];
          // The 17 four-byte fields before `balls`: lanes compute them for every ray, valid or not.
          ASSERT_EQ(std::memcmp(&got[l], &want[l], offsetof(WideRay, octant) + sizeof(std::uint32_t)), 0)
              << "isa " << isa << " ray " << order[b + l];
          EXPECT_EQ(got[l].balls, nullptr);
          EXPECT_FALSE(got[l].prefetch);
        }
        for (std::size_t l = n; l < kWideRaySetupLanes; ++l) {
          EXPECT_EQ(got[l].ball_stride, 77u) << "padding lane written, isa " << isa;
          EXPECT_EQ(got_status[l], 9) << "padding lane written, isa " << isa;
        }
      }
    }
  }
  EXPECT_GE(sets, 1);
}

}  // namespace
}  // namespace batchcol
