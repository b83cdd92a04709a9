// The ordered cast's sort key (engine/src/ray_order_keys.hpp): the lanes give the one-ray reference's bits
// (tests/support/ray_order_key_reference.hpp) for every ray, the special ones included (invalid, missing the box,
// starting inside it, zero direction components, origins on a slab plane, a flat box), at every offset and group
// length, on the baseline and AVX2; the box is the union of the root's used children.
#include "engine/src/ray_order_keys.hpp"
#include "support/ray_order_key_reference.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace batchcol::detail {
namespace {

RayOrderBox box_of(const float lo[3], const float hi[3]) {
  WideNode root{};
  for (int c = 0; c < kWideArity; ++c) root.child[c] = kWideEmpty;
  // Two used children whose union is [lo, hi]; an unused slot holding a far larger box that must be ignored.
  root.child[1] = 7, root.child[4] = 9;
  const float mid[3] = {0.5f * (lo[0] + hi[0]), 0.5f * (lo[1] + hi[1]), 0.5f * (lo[2] + hi[2])};
  float* l[3] = {root.lo_x, root.lo_y, root.lo_z};
  float* h[3] = {root.hi_x, root.hi_y, root.hi_z};
  for (int k = 0; k < 3; ++k) {
    l[k][1] = lo[k], h[k][1] = mid[k];
    l[k][4] = mid[k], h[k][4] = hi[k];
    l[k][6] = -1e30f, h[k][6] = 1e30f;
  }
  const RayOrderBox box = ray_order_box(root);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(box.lo[k], lo[k]);
    EXPECT_EQ(box.hi[k], hi[k]);
  }
  return box;
}

RayBatch special_and_random_rays(std::mt19937_64& rng, std::size_t n) {
  std::uniform_real_distribution<double> u(-12.0, 12.0);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  RayBatch rays;
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Vector3d o(u(rng), u(rng), u(rng)), d(u(rng), u(rng), u(rng));
    double t_max = i % 5 == 0 ? inf : std::abs(u(rng)) * 3.0;
    switch (i % 23) {
      case 1: d = Eigen::Vector3d::Zero(); break;  // invalid
      case 2: o.y() = nan; break;
      case 3: d.z() = -inf; break;
      case 4: t_max = -1.0; break;
      case 5: t_max = nan; break;
      case 6: d.x() = 0.0, d.y() = -0.0; break;             // infinite reciprocals
      case 7: o.x() = -2.0, d.x() = 0.0; break;             // on the box's lo_x plane: NaN slab parameters
      case 8: o = Eigen::Vector3d(0.5, 0.25, -1.0); break;  // inside the box
      case 9: d *= 1e-200; break;                           // |d|^2 underflows to 0: invalid
      case 10: o *= 1e300, d *= 1e300; break;               // overflowing products
      case 11: t_max = 0.0; break;
      default: break;
    }
    rays.add(o, d, t_max);
  }
  return rays;
}

// isa 0: the baseline lanes; 1: AVX2 (the baseline again on a processor without it).
void expect_lanes_match(const RayBatch& rays, const RayOrderBox& box) {
  std::vector<std::uint32_t> keys(rays.size() + 1, 0xdeadbeefu);
  int misses = 0, others = 0;
  for (int isa : {0, 1})
    for (std::size_t begin : {std::size_t(0), std::size_t(1), std::size_t(3)}) {
      for (std::size_t n :
           {std::size_t(0), std::size_t(1), std::size_t(2), std::size_t(3), std::size_t(5), rays.size() - begin}) {
        keys.assign(keys.size(), 0xdeadbeefu);
        ray_order_keys(rays, begin, n, box, keys.data(), isa);
        for (std::size_t l = 0; l < n; ++l) {
          const std::uint32_t expected = testing::ray_order_key_reference(rays, begin + l, box);
          ASSERT_EQ(keys[l], expected) << "ray " << begin + l << " of " << n << " from " << begin << ", isa " << isa;
          (expected == kRayOrderMissKey ? misses : others) += 1;
        }
        EXPECT_EQ(keys[n], 0xdeadbeefu) << "written past the group";
      }
    }
  EXPECT_GT(misses, 100);
  EXPECT_GT(others, 100);
}

TEST(RayOrderKeys, LanesGiveTheScalarKey) {
  std::mt19937_64 rng(5);
  const RayBatch rays = special_and_random_rays(rng, 3001);
  const float lo[3] = {-2.0f, -1.5f, -3.0f}, hi[3] = {2.5f, 1.0f, 0.5f};
  expect_lanes_match(rays, box_of(lo, hi));
  // Invalid rays take the miss key whatever their numbers give.
  for (std::size_t i = 1; i < rays.size(); i += 23)
    EXPECT_EQ(testing::ray_order_key_reference(rays, i, box_of(lo, hi)), kRayOrderMissKey) << i;
}

TEST(RayOrderKeys, FlatBoxGivesTheScalarKey) {
  std::mt19937_64 rng(6);
  const RayBatch rays = special_and_random_rays(rng, 1201);
  const float lo[3] = {-2.0f, 0.25f, -3.0f}, hi[3] = {2.5f, 0.25f, 0.5f};  // scale 0 on y
  const RayOrderBox box = box_of(lo, hi);
  EXPECT_EQ(box.scale[1], 0.0);
  expect_lanes_match(rays, box);
}

// The key's layout: origin coordinate k's bits at 6 b + 5 - k, direction k's at 6 b + 2 - k (b = bit 0..4).
TEST(RayOrderKeys, KeyInterleavesTheSixCoordinates) {
  const float lo[3] = {0.0f, 0.0f, 0.0f}, hi[3] = {32.0f, 32.0f, 32.0f};
  const RayOrderBox box = box_of(lo, hi);
  RayBatch rays;
  // Origin inside the box at cell (31, 0, 0); direction (1, 0, 0): unit components quantise to 31, 16, 16.
  rays.add(Eigen::Vector3d(31.5, 0.5, 0.5), Eigen::Vector3d(1.0, 0.0, 0.0), 1.0);
  std::uint32_t expected = 0;
  for (int b = 0; b < 5; ++b) {
    expected |= ((31u >> b) & 1u) << (6 * b + 5);  // origin x
    expected |= ((31u >> b) & 1u) << (6 * b + 2);  // direction x
    expected |= ((16u >> b) & 1u) << (6 * b + 1);  // direction y
    expected |= ((16u >> b) & 1u) << (6 * b + 0);  // direction z
  }
  EXPECT_EQ(testing::ray_order_key_reference(rays, 0, box), expected);
  for (int isa : {0, 1}) {
    std::uint32_t lanes = 0;
    ray_order_keys(rays, 0, 1, box, &lanes, isa);
    EXPECT_EQ(lanes, expected) << isa;
  }
}

}  // namespace
}  // namespace batchcol::detail
