// The hull clipping loop (kernels/rays/ray_convex_planes.*) compiled for each instruction set gives the baseline
// build's bits: enter, exit, entry face and the parallel-outside flag, in double and float, on random hulls and on
// a box-shaped hull whose axis-aligned faces meet axis-parallel rays (denominators exactly 0) and origins on planes.
#include "shape_table_access.hpp"  // engine/src: hull_view, OwnedShapeView
#include "support/generators.hpp"

#include "kernels/rays/ray_polytopes.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

namespace batchcol {
namespace {

using testing::Rng;
using testing::uniform;
namespace kr = kernels::rays;

template <class T> bool same(const kr::PlaneClip<T>& a, const kr::PlaneClip<T>& b) {
  return std::memcmp(&a.enter, &b.enter, sizeof(T)) == 0 && std::memcmp(&a.exit, &b.exit, sizeof(T)) == 0 &&
         a.face == b.face && a.outside == b.outside;
}

template <class T> void check_hull(const Shape& hull, Rng& rng, int rays, int& compared, int& entered, int& parallel) {
  const kr::HullPlanes<T> p = kr::make_hull_planes<T>(hull_view(*hull.hull));
  const double r = hull.bounding_radius();
  for (int i = 0; i < rays; ++i) {
    Eigen::Vector3d o = 2.0 * r * testing::random_unit_vector(rng);
    Eigen::Vector3d d = uniform(rng, 0.0, 0.8 * r) * testing::random_unit_vector(rng) - o;
    if (i % 4 == 0) d = Eigen::Vector3d::Zero(), d[i % 3] = i % 8 == 0 ? 1.0 : -1.0;  // axis-parallel
    if (i % 5 == 0) o[(i / 5) % 3] = 0.5;  // on the box hull's face planes
    const T oa[3] = {T(o.x()), T(o.y()), T(o.z())}, da[3] = {T(d.x()), T(d.y()), T(d.z())};
    const auto ref = kr::clip_planes_for(0);
    const kr::PlaneClip<T> base = [&] {
      if constexpr (std::is_same_v<T, double>) return ref.d(p.nx.data(), p.ny.data(), p.nz.data(), p.c.data(), p.nx.size(), oa, da);
      else return ref.f(p.nx.data(), p.ny.data(), p.nz.data(), p.c.data(), p.nx.size(), oa, da);
    }();
    entered += base.enter > -kr::infinity<T>() && base.enter <= base.exit && !base.outside;
    parallel += base.outside;
    for (int isa = 1; isa <= 2; ++isa) {
      const auto v = kr::clip_planes_for(isa);
      if (!v.d) continue;
      kr::PlaneClip<T> got;
      if constexpr (std::is_same_v<T, double>) got = v.d(p.nx.data(), p.ny.data(), p.nz.data(), p.c.data(), p.nx.size(), oa, da);
      else got = v.f(p.nx.data(), p.ny.data(), p.nz.data(), p.c.data(), p.nx.size(), oa, da);
      EXPECT_TRUE(same(got, base)) << "isa " << isa << " ray " << i << ": enter " << got.enter << " vs " << base.enter
                                   << ", exit " << got.exit << " vs " << base.exit << ", face " << got.face << " vs "
                                   << base.face;
      ++compared;
    }
    // The dispatcher picks one of them, for the processor and for every cap: the same bits again.
    const kr::PlaneClip<T> picked = kr::clip_planes(p.nx.data(), p.ny.data(), p.nz.data(), p.c.data(), p.nx.size(), oa, da);
    EXPECT_TRUE(same(picked, base));
    for (int cap = 0; cap <= 2; ++cap) {
      const kr::PlaneClip<T> capped =
          kr::clip_planes(p.nx.data(), p.ny.data(), p.nz.data(), p.c.data(), p.nx.size(), oa, da, cap);
      EXPECT_TRUE(same(capped, base)) << "cap " << cap;
    }
  }
}

TEST(RayConvexPlanes, EveryInstructionSetGivesTheSameBits) {
  Rng rng(41);
  std::vector<Shape> hulls;
  for (int n : {8, 30, 120, 250}) hulls.push_back(Shape::convex(testing::random_hull_points(rng, n, 0.3, 1.0)));
  std::vector<Eigen::Vector3d> corners;
  for (int k = 0; k < 8; ++k) corners.emplace_back(k & 1 ? 0.5 : -0.5, k & 2 ? 0.5 : -0.5, k & 4 ? 0.5 : -0.5);
  hulls.push_back(Shape::convex(corners));
  int compared = 0, entered = 0, parallel = 0;
  for (const Shape& h : hulls) {
    check_hull<double>(h, rng, 2000, compared, entered, parallel);
    check_hull<float>(h, rng, 2000, compared, entered, parallel);
  }
  if (__builtin_cpu_supports("avx2")) {
    EXPECT_GT(compared, 10000);
  }
  EXPECT_GT(entered, 5000);  // the rays do cross the hulls
  EXPECT_GT(parallel, 50);   // and the parallel-outside branch is exercised
}

TEST(RayConvexPlanes, TheCapPicksEachSetsOwnLoop) {
  // RayOptions::isa (`batchcol rays --isa`) reaches the hulls' clipping through ray_isa_index() and clip_planes(...,
  // isa): each cap runs its own set's loop when the processor has it, else the next lower one, never a higher one.
  const auto expect_same = [](const kr::ClipPlaneVariants& a, const kr::ClipPlaneVariants& b, const char* what) {
    EXPECT_EQ(a.d, b.d) << what;
    EXPECT_EQ(a.f, b.f) << what;
  };
  ASSERT_NE(kr::clip_planes_for(0).d, nullptr);
  expect_same(kr::select_clip_planes(0), kr::clip_planes_for(0), "cap 0");
  expect_same(kr::select_clip_planes(-1), kr::clip_planes_for(0), "cap -1");
  if (kr::clip_planes_for(1).d != nullptr) {
    expect_same(kr::select_clip_planes(1), kr::clip_planes_for(1), "cap 1");
    EXPECT_NE(kr::select_clip_planes(1).d, kr::select_clip_planes(0).d);
  }
  if (kr::clip_planes_for(2).d != nullptr) {
    expect_same(kr::select_clip_planes(2), kr::clip_planes_for(2), "cap 2");
    expect_same(kr::select_clip_planes(3), kr::clip_planes_for(2), "cap 3");
    EXPECT_NE(kr::select_clip_planes(2).d, kr::select_clip_planes(1).d);
  } else {
    expect_same(kr::select_clip_planes(2), kr::select_clip_planes(1), "cap 2 without AVX-512");
  }
}

}  // namespace
}  // namespace batchcol
