// Packets of rays through the wide BVH (engine/src/ray_wide_packet.inl) and the scene cast that uses them for
// closest hits on scenes whose answers do not depend on the visiting order (Caster::order_free()): each lane reaches
// exactly the leaves it reaches alone, and a scene's closest hits are bitwise those of one ray at a time, ties
// (duplicated objects, rays starting inside several objects) included, on every instruction set and thread count.
#include "support/generators.hpp"
#include "support/ray_reference.hpp"
#include "support/same_results.hpp"

#include "batchcol/rays.hpp"
#include "batchcol/scene.hpp"
#include "engine/src/ray_bvh.hpp"
#include "engine/src/ray_wide_bvh.hpp"
#include "engine/src/ray_wide_traverse.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

namespace batchcol {
namespace {

using testing::Rng;
using testing::uniform;

bool has_isa(int isa) { return wide_traverse_for(isa) != nullptr; }

// A stand-in for the scene's leaf tests: a ray "hits" a leaf at its exact box entry plus a per-leaf offset (so never
// before the box, as an object inside it), and the limit falls to that hit, rounded to float (the offsets, >= 0.01,
// exceed the rounding: the float limit stays above the exact entry, as wide_limit() keeps it above a hit).
struct Hits {
  const broadphase::AabbSoa* boxes;
  const RayBvh* bvh;
  std::vector<double> offset;  // per leaf
  double value(const double o[3], const double d[3], std::uint32_t leaf) const {
    const std::uint32_t i = bvh->leaf_object()[leaf];
    const double lo[3] = {boxes->min_x[i], boxes->min_y[i], boxes->min_z[i]};
    const double hi[3] = {boxes->max_x[i], boxes->max_y[i], boxes->max_z[i]};
    return testing::exact_box_entry(o, d, lo, hi) + offset[leaf];
  }
};

struct Lane {
  double o[3], d[3];
  std::vector<std::uint32_t> seen;  // leaves in reporting order
  double best = INFINITY;  // the least hit accepted (<= the limit when reported), and its leaf (ties: lower)
  std::uint32_t best_leaf = 0xffffffffu;
  void report(const Hits* hits, std::uint32_t leaf, float& limit) {
    seen.push_back(leaf);
    if (hits == nullptr) return;
    const double v = hits->value(o, d, leaf);
    if (!(v <= double(limit))) return;
    if (v < best || (v == best && leaf < best_leaf)) best = v, best_leaf = leaf;
    limit = std::min(limit, static_cast<float>(v));
  }
};

struct PacketContext {
  Lane* lanes;
  const Hits* hits;
};

void record_lane(void* context, unsigned lane, std::uint32_t leaf, float& limit) {
  PacketContext& c = *static_cast<PacketContext*>(context);
  c.lanes[lane].report(c.hits, leaf, limit);
}

struct OneContext {
  Lane* lane;
  const Hits* hits;
};

bool record_one(void* context, std::uint32_t leaf, float& limit) {
  OneContext& c = *static_cast<OneContext*>(context);
  c.lane->report(c.hits, leaf, limit);
  return true;
}

// Random neighbouring rays through a random tree, in packets of 1 to kWidePacketLanes rays of one octant, 1 to
// 2 kWidePacketStreams + 1 packets a call (more packets than walk at once: a finished packet's place is taken by the
// next): with the limit never lowered each lane reports exactly the leaves the one-ray traversal reports (as sets:
// the order is the packet's); with the limit lowered at each "hit" (Hits), each lane's least hit and its leaf are the
// one-ray traversal's.
TEST(RayWidePacket, EachLaneReachesTheLeavesItReachesAlone) {
  Rng rng(31);
  broadphase::AabbSoa boxes;
  const std::size_t n = 3000;
  boxes.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    float* lo[3] = {&boxes.min_x[i], &boxes.min_y[i], &boxes.min_z[i]};
    float* hi[3] = {&boxes.max_x[i], &boxes.max_y[i], &boxes.max_z[i]};
    for (int k = 0; k < 3; ++k) {
      const double c = uniform(rng, -10, 10), h = uniform(rng, 0.0, 0.6);
      *lo[k] = static_cast<float>(c - h), *hi[k] = static_cast<float>(c + h);
    }
  }
  RayBvh bvh;
  bvh.build(boxes);
  WideBvh wide;
  wide.collapse(bvh, boxes);
  Hits hits{&boxes, &bvh, {}};
  for (std::size_t leaf = 0; leaf < n; ++leaf)
    hits.offset.push_back(leaf % 5 == 0 ? 0.01 : uniform(rng, 0.01, 2.0));  // equal offsets: ties between leaves
  int lowered = 0, calls_beyond_streams = 0;
  for (int isa = 0; isa <= 2; ++isa) {
    if (!has_isa(isa)) continue;
    SCOPED_TRACE(::testing::Message() << "isa " << isa);
    const WideTraverse one = wide_traverse_for(isa);
    const WidePacketTraverse packet = wide_packet_traverse_for(isa);
    ASSERT_NE(packet, nullptr);
    for (int round = 0; round < 400; ++round) {
      // Neighbouring rays (a packet's rays come from one cell of the cast order): origins near a point, directions
      // near one, all in its octant; packets of 1 to kWidePacketLanes of them.
      const unsigned packets_in_call = 1 + unsigned(round % (2 * kWidePacketStreams + 1));
      std::vector<WidePacket> packets;
      unsigned count = 0;
      for (unsigned p = 0; p < packets_in_call; ++p) {
        const unsigned lanes_in_packet = 1 + unsigned((round + 7 * p) % kWidePacketLanes);
        packets.push_back({count, lanes_in_packet});
        count += lanes_in_packet;
      }
      calls_beyond_streams += packets_in_call > kWidePacketStreams;
      const double base_o[3] = {uniform(rng, -14, 14), uniform(rng, -14, 14), uniform(rng, -14, 14)};
      double base_d[3] = {uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1)};
      if (round % 11 == 0) base_d[round % 3] = 0.0;  // a zero component: infinite reciprocal, grazing slabs
      for (const Hits* h : {static_cast<const Hits*>(nullptr), static_cast<const Hits*>(&hits)}) {
        std::vector<Lane> lanes(count), alone(count);
        std::vector<WideRay> rays(count);
        std::vector<const WideRay*> ptr(count);
        std::vector<float> limits(count);
        for (unsigned l = 0; l < count; ++l) {
          for (int k = 0; k < 3; ++k) {
            lanes[l].o[k] = base_o[k] + uniform(rng, -1.5, 1.5);
            lanes[l].d[k] =
                base_d[k] == 0.0 ? 0.0 : std::copysign(std::fabs(base_d[k]) + uniform(rng, 0.0, 0.3), base_d[k]);
            alone[l].o[k] = lanes[l].o[k], alone[l].d[k] = lanes[l].d[k];
          }
          rays[l] = make_wide_ray(lanes[l].o, lanes[l].d);
          ptr[l] = &rays[l];
          limits[l] = l % 3 == 2 ? 20.0f : INFINITY;
        }
        PacketContext pc{lanes.data(), h};
        packet(wide.nodes().data(), ptr.data(), limits.data(), packets.data(), packets_in_call, &record_lane, &pc);
        for (unsigned l = 0; l < count; ++l) {
          OneContext oc{&alone[l], h};
          one(wide.nodes().data(), rays[l], l % 3 == 2 ? 20.0f : INFINITY, &record_one, &oc);
          if (h == nullptr) {
            std::vector<std::uint32_t> a = alone[l].seen, b = lanes[l].seen;
            std::sort(a.begin(), a.end()), std::sort(b.begin(), b.end());
            ASSERT_EQ(a, b) << "round " << round << " lane " << l;
          } else {
            ASSERT_EQ(alone[l].best_leaf, lanes[l].best_leaf) << "round " << round << " lane " << l;
            ASSERT_EQ(alone[l].best, lanes[l].best) << "round " << round << " lane " << l;
            lowered += alone[l].best_leaf != 0xffffffffu;
          }
        }
      }
    }
  }
  EXPECT_GT(lowered, 300);
  EXPECT_GT(calls_beyond_streams, 100);
}

// A scene of the shapes whose closest hits are order free (exact kernels: spheres, capsules, boxes, cylinders,
// cones, ellipsoids, inflated spheres and capsules) and a ground halfspace, every 7th object duplicated at the same
// pose (the same t, the lower slot wins) and every 5th ray starting inside an object (t = 0 for every object it
// starts in). The ordered cast (a batch of >= 4096 rays on a tree of >= 1 MiB, cast in packets) against the same rays
// in batches of 1000 (input order, one ray at a time): the same bits.
TEST(RayWidePacket, OrderFreeSceneCastInPacketsGivesTheBitsOfOneRayAtATime) {
  Rng rng(32);
  auto table = std::make_shared<ShapeTable>();
  for (ShapeType type : {ShapeType::sphere, ShapeType::capsule, ShapeType::box, ShapeType::cylinder,
                         ShapeType::cone, ShapeType::ellipsoid})
    for (int v = 0; v < 3; ++v) table->add(testing::random_shape(rng, type, 0.05, 0.3));
  table->add(testing::random_shape(rng, ShapeType::sphere, 0.05, 0.3).inflated(0.02));
  table->add(testing::random_shape(rng, ShapeType::capsule, 0.05, 0.3).inflated(0.02));
  const std::uint32_t bounded = static_cast<std::uint32_t>(table->size());
  const std::uint32_t ground = table->add(Shape::halfspace(Eigen::Vector3d::UnitZ(), 0.0));
  Scene scene(table);
  std::vector<Eigen::Vector3d> centres;
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3d t(uniform(rng, -8, 8), uniform(rng, -8, 8), uniform(rng, -8, 8));
    const Pose pose{t, testing::random_rotation(rng)};
    const std::uint32_t shape = static_cast<std::uint32_t>(i % bounded);
    scene.add(shape, pose);
    if (i % 7 == 0) scene.add(shape, pose);
    centres.push_back(t);
  }
  scene.add(ground, Pose::from_translation(Eigen::Vector3d(0, 0, -9)));
  RayBatch rays;
  for (int i = 0; i < 9000; ++i) {
    const Eigen::Vector3d o = i % 5 == 0 ? centres[std::size_t(i) % centres.size()]
                                         : Eigen::Vector3d(uniform(rng, -11, 11), uniform(rng, -11, 11),
                                                           uniform(rng, -11, 11));
    const Eigen::Vector3d target(uniform(rng, -8, 8), uniform(rng, -8, 8), uniform(rng, -8, 8));
    const double t_max = i % 3 == 0 ? uniform(rng, 0.5, 3.0) : std::numeric_limits<double>::infinity();
    rays.add(o, (target - o).normalized() * (i % 4 == 0 ? 2.5 : 1.0), t_max);
  }
  const InstructionSet sets[] = {InstructionSet::scalar, InstructionSet::avx2, InstructionSet::avx512};
  for (int isa = 0; isa <= 2; ++isa) {
    if (!has_isa(isa)) continue;
    for (int threads : {1, 2}) {
      SCOPED_TRACE(::testing::Message() << "isa " << isa << ", " << threads << " threads");
      RaySceneIndex index;
      index.update(scene, threads);
      RayOptions o;
      o.threads = threads;
      o.isa = sets[isa];
      RayResults whole;
      index.cast(rays, o, whole);
      ASSERT_TRUE(testing::cast_in_parts_matches(index, rays, o, whole));
      int hits = 0, at_zero = 0;
      for (std::size_t i = 0; i < rays.size(); ++i) {
        hits += whole.hit[i];
        at_zero += whole.hit[i] && whole.t[i] == 0.0;
      }
      EXPECT_GT(hits, 3000);
      EXPECT_GT(at_zero, 1000);  // rays from inside objects: ties at t = 0
    }
  }
}

}  // namespace
}  // namespace batchcol
