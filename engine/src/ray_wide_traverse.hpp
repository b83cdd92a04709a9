// Closest-first traversal of the 16-wide BVH (ray_wide_bvh.hpp) for one ray, with one float SIMD slab test per node
// (all 16 child boxes at once on AVX-512, in two 8-lane halves on AVX2 and the baseline). The loop is compiled for
// AVX-512, AVX2 and the baseline (ray_wide_traverse.cpp) and picked by select_wide_traverse(isa) (RayOptions::isa,
// `batchcol rays --isa`); every version does the same IEEE operations lane by lane, so the visiting order, and hence
// every answer, is the same on every instruction set.
//
// Conservative float test (no box the exact ray segment reaches is ever rejected), after Ize, "Robust BVH ray
// traversal", JCGT 2013, adapted to a double ray: per axis the slab plane the ray enters through ("near": lo when
// the direction component is >= 0, else hi) and the one it leaves through ("far") are fixed by the sign, and the
// ray's origin is rounded to float towards the side that makes the computed near parameter smaller and the far one
// larger (o_near, o_far). What remains are three roundings per parameter (the subtraction, the product, the float
// reciprocal), a relative error below 3 * 2^-24 each way when no value is subnormal, so
//   near_computed <= near (1 + d) <= far (1 + d) <= far_computed (1 + d) / (1 - d),
// and scaling the far side by kFarScale = 1 + 2^-20 (> (1 + d) / (1 - d) plus the product's own rounding) keeps every
// box the exact ray reaches; kFarSlack = 2^-120 covers subnormal parameters (absolute errors below 2^-149). The
// limit (best hit so far, or t_max) is compared after the same widening. A direction component of exactly 0 gives
// an infinite reciprocal: (plane - origin) * inf is +-inf (outside / inside the slab) or NaN when the origin lies on
// the plane; NaN lanes lose the ordered max/min below, which treats the slab as containing the ray (conservative).
// Rays with a component outside [2^-60, 2^60] (or an origin beyond 2^60) would leave float's range: the caller
// traverses those in double with the binary tree (wide_ray_supported()).
#pragma once

#include "ray_wide_bvh.hpp"

#include <cstddef>
#include <cstdint>

namespace batchcol {

constexpr float kFarScale = 1.0f + 0x1p-20f;
constexpr float kFarSlack = 0x1p-120f;

// Leaf ball filter (optional, `balls`): most leaves a ray reaches miss their object, and the caller's exact double
// filter (the object's bounding ball) rejects them after a call per leaf. With `balls` set (4 floats per leaf: centre
// and radius, from make_leaf_ball()) the traversal rejects such leaves itself, in float, without the call; it only
// rejects a leaf when the ray's line passes the centre farther than the radius plus kBallMargin of the lengths
// involved (|o|_1, |c|_1, |c - o|_1). The float distance is within ~8 * 2^-24 of those lengths (origin, centre and
// unit direction rounded to float, a cross product, squares), so a leaf the double filter keeps (radius widened by
// 1e-12 of the same lengths) is never rejected, on any instruction set; leaves are visited in the same order either
// way, so results are bitwise the same with or without it. Overflow gives inf / NaN, which never rejects; the radius
// is at least 2^-60, so its square stays a normal float.
constexpr float kBallMargin = 0x1p-16f;  // 32 times the error bound above

struct WideRay {
  float o_near[3], o_far[3], inv[3];
  float ball_o[3], ball_d[3];  // origin and unit direction rounded to float
  float ball_margin;           // kBallMargin * |o|_1, rounded up
  // Bit k: the direction's component k is negative (-0 included), so the ray enters a slab of axis k through its hi
  // plane: which loop of the traversal runs (one per octant, the near / far planes fixed offsets in it).
  std::uint32_t octant = 0;
  const float* balls = nullptr;  // per leaf (Morton rank): x, y, z, radius; nullptr: every leaf is visited
  std::uint32_t ball_stride = 4;  // floats from one leaf's ball to the next (the balls sit in the leaf records)
  bool prefetch = false;  // request a pushed child's lines early (worth it when the nodes do not fit the L2)
};

/// The float ball of a leaf whose exact filter is the ball (c, bound): centre rounded to float, radius covering bound
/// and the margin of the centre's length (see above); +inf (never rejects) when bound is not a positive finite number.
void make_leaf_ball(const double c[3], double bound, float out[4]);

/// True when the float test is safe for this ray (see above); o and d are the ray's origin and direction.
bool wide_ray_supported(const double o[3], const double d[3]);
WideRay make_wide_ray(const double o[3], const double d[3]);

/// What WideRaySetup found for a ray: invalid (detail::ray_is_valid() false), valid but outside the float test's
/// range (wide_ray_supported() false: the binary tree in double), or valid and supported (its WideRay is written).
enum : std::uint8_t { kWideRayInvalid = 0, kWideRayBinary = 1, kWideRaySupported = 2 };
/// A batch of rays as structure of arrays (origin, direction, t_max), read from index `begin` on.
struct WideRayInput {
  const double* o[3];
  const double* d[3];
  const double* t_max;
};
/// The setup of n <= 8 consecutive rays at once: status[l] for ray begin + l and, for kWideRaySupported, out[l]
/// bitwise equal to make_wide_ray() (balls nullptr, no prefetch). The scalar setup costs ~260 instructions and ~4
/// mispredicted branches a ray (the rounding direction and the sign are random data); lanes and masks do not branch.
using WideRaySetup = void (*)(const WideRayInput& in, std::size_t begin, std::size_t n, WideRay* out,
                              std::uint8_t* status);
constexpr std::size_t kWideRaySetupLanes = 8;
/// The setup for this processor, and per instruction set for the tests (0 baseline, 1 AVX2 (also on AVX-512
/// processors); nullptr for others and when the processor lacks it).
WideRaySetup select_wide_ray_setup();
WideRaySetup select_wide_ray_setup(int isa);  // at most `isa` (AVX-512 processors run the AVX2 setup)
WideRaySetup wide_ray_setup_for(int isa);

/// A ray as the ordered cast keeps it (one cache line): origin, direction, t_max; `pad` is read with the rest.
struct alignas(64) WideRayRecord {
  double o[3], d[3], t_max, pad;
};
/// The setup of n <= 8 records given by address (the ordered cast reads its records in cast order, scattered):
/// the same status and WideRay bits as a WideRaySetup of the same rays.
using WideRecordSetup = void (*)(const WideRayRecord* const* records, std::size_t n, WideRay* out,
                                 std::uint8_t* status);
/// As wide_ray_setup_for() / select_wide_ray_setup(isa).
WideRecordSetup wide_record_setup_for(int isa);
WideRecordSetup select_wide_record_setup(int isa);

/// The float limit the traversal compares with for a double limit t: t (1 + 2^-20) rounded up to float.
/// Inline: the scene cast calls it after every hit (a call cost ~30 instructions, 1.2% of a ray on 10k hulls).
float wide_limit_round_up(double x);  // round_up(): the next float at or above x, for x < 0 and NaN
inline float wide_limit(double t) {
  const double x = t * double(kFarScale);
  if (!(x >= 0.0)) return wide_limit_round_up(x);
  // Limits are t >= 0 (t_max or a hit): round_up() without its branches, which were mispredicted about once in three
  // calls (a hit moves the limit). For f >= +0 the next float up has the next bit pattern (0 -> the smallest
  // subnormal, FLT_MAX -> +inf, as next_up()); f = -0 (x = -0) and f = +inf are never below x. The same bits.
  const float f = static_cast<float>(x);
  std::uint32_t u;
  __builtin_memcpy(&u, &f, sizeof u);
  u += double(f) < x ? 1u : 0u;
  float r;
  __builtin_memcpy(&r, &u, sizeof r);
  return r;
}

/// Called for every leaf (Morton rank) whose box the ray reaches, nearest box first; returns false to stop the
/// traversal, and may lower `limit` (a wide_limit()).
using WideLeafVisit = bool (*)(void* context, std::uint32_t leaf, float& limit);
using WideTraverse = void (*)(const WideNode* nodes, const WideRay& ray, float limit, WideLeafVisit visit,
                              void* context);
/// Packets: up to kWidePacketLanes rays of one direction octant (the same WideRay::octant, balls and prefetch) walk
/// the tree together (ray_wide_packet.inl): each node is loaded once for the rays that reach it. A call takes any
/// number of packets of one octant, as slices of its arrays (packet p: the lanes packets[p].first .. + n), and walks
/// up to kWidePacketStreams of them at once, a step of each in turn. Lane i's leaves are reported as visit(context,
/// i, leaf, limits[i]), which may lower limits[i]; nearest box first by the smallest entry over its packet's lanes,
/// so a lane may see its leaves in another order, and more of them, than alone (closest hits only, and only where an
/// object's hit does not depend on the limit it is tested with).
/// 32 lanes: on 100k mixed objects x 1M ordered rays (AVX-512, 2 threads, casts alternating in one process) packets of
/// 8 / 16 / 32 / 64 rays gave 1.05x / 1.14x / 1.26-1.28x / 1.21-1.22x the one-ray loop's rays/s (medians of 8 pairs).
constexpr unsigned kWidePacketLanes = 32;
/// Packets walked at once: 100k mixed objects x 1M rays (rays --runs 9 --frames 1, 2 threads, AVX-512, farm-bench
/// -n 5 on a loaded 2-core VM, whole-process CPU seconds): one at a time 1.24x those of 4, 8 0.98x those of 4
/// (rays/s 1.07x), 16 1.01x those of 8.
constexpr unsigned kWidePacketStreams = 8;
struct WidePacket {
  unsigned first, n;  // 1 <= n <= kWidePacketLanes
};
using WidePacketVisit = void (*)(void* context, unsigned lane, std::uint32_t leaf, float& limit);
using WidePacketTraverse = void (*)(const WideNode* nodes, const WideRay* const* rays, float* limits,
                                    const WidePacket* packets, unsigned count, WidePacketVisit visit, void* context);
/// As select_wide_traverse(isa) / wide_traverse_for(isa).
WidePacketTraverse select_wide_packet_traverse(int isa);
WidePacketTraverse wide_packet_traverse_for(int isa);

/// The traversal for this processor (reads the CPU's features; no state is kept), and the one of instruction set
/// `isa` (0 baseline, 1 AVX2, 2 AVX-512) or the next lower one this processor runs.
WideTraverse select_wide_traverse();
WideTraverse select_wide_traverse(int isa);
/// The traversal of one instruction set, for the tests: 0 baseline, 1 AVX2, 2 AVX-512; nullptr when the processor
/// lacks it.
WideTraverse wide_traverse_for(int isa);

}  // namespace batchcol
