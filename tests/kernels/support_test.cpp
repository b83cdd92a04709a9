// Support functions against the extent formula h(d) = max <x, d> written from the shape definitions
// (tests/support/generators.cpp), and hill climbing on large hulls against a linear scan.
#include "batchcol/errors.hpp"
#include "kernels/support.hpp"
#include "shape_table_access.hpp"  // engine/src: OwnedShapeView
#include "support/generators.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace batchcol::kernels {
namespace {

TEST(Support, EveryCoreReachesItsExtent) {
  batchcol::testing::Rng rng(31);
  for (ShapeType t : batchcol::testing::bounded_shape_types())
    for (int trial = 0; trial < 200; ++trial) {
      const Shape s = batchcol::testing::random_shape(rng, t);
      const OwnedShapeView view(s);
      const ShapeCore<double> core = make_core<double>(view.view);
      Eigen::Vector3d d = batchcol::testing::random_unit_vector(rng);
      if (trial % 10 == 0) d = Eigen::Vector3d::Unit(trial % 3);  // axis directions hit the tie branches
      SupportHint hint;
      const Eigen::Vector3d p = support(core, d, hint);
      // extent() includes the swept radius, the core support does not.
      EXPECT_NEAR(p.dot(d) + core.radius, batchcol::testing::extent(s, d), 1e-12) << to_string(t);
    }
}

TEST(Support, HillClimbingOnLargeHullsEqualsALinearScan) {
  batchcol::testing::Rng rng(32);
  for (int n : {40, 250, 940, 3000}) {
    const Shape s = Shape::convex(batchcol::testing::random_hull_points(rng, n, 0.05, 0.4));
    ASSERT_GE(s.hull->vertices.size(), kHillClimbMinVertices);
    const OwnedShapeView view(s);
      const ShapeCore<double> core = make_core<double>(view.view);
    SupportHint hint;  // kept across queries, as inside one GJK run
    for (int q = 0; q < 2000; ++q) {
      const Eigen::Vector3d d = batchcol::testing::random_unit_vector(rng);
      double best = -1e300;
      for (const auto& v : s.hull->vertices) best = std::max(best, v.dot(d));
      EXPECT_EQ(support(core, d, hint).dot(d), best) << n << " vertices, query " << q;
    }
  }
}

TEST(Support, ClimbsFromTheDirectionTableEqualALinearScan) {
  // A fresh hint starts each climb from the hull's direction table (start_cell), as every pair's first support
  // does; directions on cube-face and cell boundaries, axes and zero components included.
  batchcol::testing::Rng rng(34);
  for (int n : {40, 250, 940}) {
    const Shape s = Shape::convex(batchcol::testing::random_hull_points(rng, n, 0.05, 0.4));
    ASSERT_EQ(s.hull->start_vertices.size(), kHullStartCells);
    const OwnedShapeView view(s);
      const ShapeCore<double> core = make_core<double>(view.view);
    for (int q = 0; q < 3000; ++q) {
      Eigen::Vector3d d = batchcol::testing::random_unit_vector(rng);
      if (q % 7 == 0) d = Eigen::Vector3d::Unit(q % 3) * (q % 2 ? -1.0 : 1.0);
      if (q % 11 == 0) d[q % 3] = 0.0;
      if (q % 13 == 0) d = Eigen::Vector3d(1.0, 1.0, q % 2 ? -1.0 : 1.0);  // three-way tie of the face choice
      double best = -1e300;
      for (const auto& v : s.hull->vertices) best = std::max(best, v.dot(d));
      SupportHint hint;  // fresh
      EXPECT_EQ(support(core, d, hint).dot(d), best) << n << " vertices, query " << q;
      EXPECT_NE(hint.vertex, kNoHullVertex);
    }
  }
}

TEST(Support, HandBuiltHullsGetTheirSearchStructures) {
  // A hull built by hand (vertices and faces only, as a user or an unpickled Python table gives it) gets its
  // adjacency, neighbour blocks and direction table from Shape::convex, so its supports climb like a qhull hull's;
  // an adjacency that contradicts the faces is refused, naming the field.
  batchcol::testing::Rng rng(35);
  const Shape full = Shape::convex(batchcol::testing::random_hull_points(rng, 300, 0.05, 0.4));
  auto bare = std::make_shared<ConvexHull>();
  bare->vertices = full.hull->vertices;
  bare->faces = full.hull->faces;
  bare->face_normals = full.hull->face_normals;
  bare->centroid = full.hull->centroid;
  bare->radius = full.hull->radius;
  const Shape rebuilt = Shape::convex(bare);
  EXPECT_EQ(rebuilt.hull->neighbors, full.hull->neighbors);
  EXPECT_EQ(rebuilt.hull->neighbor_block_xyz, full.hull->neighbor_block_xyz);
  EXPECT_EQ(rebuilt.hull->start_vertices, full.hull->start_vertices);
  EXPECT_EQ(Shape::convex(full.hull).hull, full.hull);  // a complete hull is shared, not copied
  const OwnedShapeView full_view(full), rebuilt_view(rebuilt);
  const ShapeCore<double> a = make_core<double>(full_view.view), b = make_core<double>(rebuilt_view.view);
  for (int q = 0; q < 500; ++q) {
    const Eigen::Vector3d d = batchcol::testing::random_unit_vector(rng);
    SupportHint ha, hb;
    EXPECT_EQ(support(a, d, ha), support(b, d, hb)) << "query " << q;
  }
  auto wrong = std::make_shared<ConvexHull>(*full.hull);
  std::swap(wrong->neighbors.front(), wrong->neighbors.back());
  try {
    Shape::convex(wrong);
    ADD_FAILURE() << "an adjacency that contradicts the faces was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("hull neighbors"), std::string::npos) << e.what();
  }
  auto out_of_range = std::make_shared<ConvexHull>(*bare);
  out_of_range->faces.front()[1] = std::uint32_t(bare->vertices.size());
  EXPECT_THROW(Shape::convex(out_of_range), InputError);
}

TEST(Support, PureCellsGiveTheLinearScansVertexWithoutAClimb) {
  // A cell flagged kHullPureCell returns its vertex without a climb: every direction in it, in double and in
  // float, must get the linear scan's first maximiser (index and point), directions near the cell's edges
  // included; and a flag the table's builder did not set is not trusted (the table is rebuilt).
  batchcol::testing::Rng rng(36);
  for (int n : {250, 940}) {
    const Shape s = Shape::convex(batchcol::testing::random_hull_points(rng, n, 0.05, 0.4));
    const ConvexHull& h = *s.hull;
    const OwnedShapeView view(s);
    const ShapeCore<double> core = make_core<double>(view.view);
    const ShapeCore<float> core_f = make_core<float>(view.view);
    int pure = 0, checked = 0;
    for (std::uint32_t e : h.start_vertices) pure += (e & kHullPureCell) != 0;
    EXPECT_GT(pure, int(kHullStartCells) / 20) << n << " vertices";
    for (int q = 0; q < 20000; ++q) {
      const Eigen::Vector3d d = batchcol::testing::random_unit_vector(rng);
      const std::uint32_t c = start_cell(d);
      ASSERT_NE(c, kNoHullVertex);
      if (!(h.start_vertices[c] & kHullPureCell)) continue;
      ++checked;
      std::uint32_t best = 0;
      for (std::uint32_t i = 1; i < h.vertices.size(); ++i)
        if (h.vertices[i].dot(d) > h.vertices[best].dot(d)) best = i;
      SupportHint hint;
      EXPECT_EQ(support(core, d, hint), h.vertices[best]) << n << " vertices, query " << q;
      EXPECT_EQ(hint.vertex, best);
      const Eigen::Vector3f df = d.cast<float>();
      if (start_cell(df) != c) continue;
      std::uint32_t best_f = 0;
      for (std::uint32_t i = 1; i < h.vertices.size(); ++i)
        if (h.vertices[i].cast<float>().dot(df) > h.vertices[best_f].cast<float>().dot(df)) best_f = i;
      SupportHint hint_f;
      EXPECT_EQ(support(core_f, df, hint_f), Eigen::Vector3f(h.vertices[best_f].cast<float>())) << n << " vertices, float query " << q;
    }
    EXPECT_GT(checked, 1000) << n << " vertices";
    // A flag set on a cell that is not pure: the hull is not shared as complete, its table is rebuilt.
    auto forged = std::make_shared<ConvexHull>(h);
    std::uint32_t c = 0;
    while (h.start_vertices[c] & kHullPureCell) ++c;
    forged->start_vertices[c] |= kHullPureCell;
    const Shape fixed = Shape::convex(forged);
    EXPECT_NE(fixed.hull, forged);
    EXPECT_EQ(fixed.hull->start_vertices, h.start_vertices);
  }
}

/// The linear scan's first maximiser of hull_dot (the support's own dot product, in T) over every vertex.
template <class T> std::uint32_t scan_vertex(const HullView& h, const Vec3<T>& d) {
  std::uint32_t best = 0;
  for (std::uint32_t i = 1; i < h.vertex_count; ++i)
    if (hull_dot(h, i, d) > hull_dot(h, best, d)) best = i;
  return best;
}

TEST(Support, CandidateListsGiveTheLinearScansVertex) {
  // A cell's entry in the candidate table answers with its vertex (pure cells) or the first maximum over its
  // list: it must be the linear scan's first maximiser, index for index, in double and in float, for random directions, for
  // directions on and just across cell edges and corners, and for the hull's face normals and edge bisectors
  // (two or three vertices tie there in exact arithmetic, so the first-maximum rule decides).
  batchcol::testing::Rng rng(37);
  for (int n : {40, 250, 940}) {
    const Shape s = Shape::convex(batchcol::testing::random_hull_points(rng, n, 0.05, 0.4));
    const ConvexHull& h = *s.hull;
    const OwnedShapeView view(s);
    const HullView& hv = *view.view.hull;
    ASSERT_NE(hv.cell_candidates, nullptr);
    int listed = 0;
    for (std::uint32_t c = 0; c < kHullStartCells; ++c) {
      const std::uint32_t e = h.cell_candidates[c], count = e & 15u;
      if (h.start_vertices[c] & kHullPureCell) {
        EXPECT_EQ(e, (h.start_vertices[c] & ~kHullPureCell) << 4 | 1u);
      }
      if (count == 1) {
        EXPECT_LT(e >> 4, h.vertices.size());
      }
      listed += count > 1;
      if (count <= 1) continue;
      for (std::uint32_t i = 0; i < count; ++i) {
        EXPECT_LT(h.cell_candidates[(e >> 4) + i], h.vertices.size());
        if (i > 0) {
          EXPECT_LT(h.cell_candidates[(e >> 4) + i - 1], h.cell_candidates[(e >> 4) + i]) << "ascending";
        }
      }
    }
    EXPECT_GT(listed, n >= 250 ? int(kHullStartCells) / 5 : 20) << n << " vertices";
    std::vector<Eigen::Vector3d> dirs;
    for (int q = 0; q < 20000; ++q) dirs.push_back(batchcol::testing::random_unit_vector(rng));
    for (std::size_t f = 0; f < h.faces.size(); ++f) {
      dirs.push_back(h.face_normals[f]);
      const std::uint32_t* v = h.faces[f].data();
      for (int e = 0; e < 3; ++e) {  // the bisector of the edge's two faces is roughly this: ties of two vertices
        const Eigen::Vector3d m = 0.5 * (h.vertices[v[e]] + h.vertices[v[(e + 1) % 3]]) - h.centroid;
        const Eigen::Vector3d edge = h.vertices[v[(e + 1) % 3]] - h.vertices[v[e]];
        dirs.push_back(m - edge * (m.dot(edge) / edge.squaredNorm()));
      }
    }
    for (int q = 0; q < 4000; ++q) {  // on a cell's edge or corner in the cube map, or 1e-7 of a cell beside it
      const Eigen::Vector3d r = batchcol::testing::random_unit_vector(rng);
      const int axis = q % 3;
      Eigen::Vector3d d = r / std::abs(r[axis]);
      for (int k : {1, 2}) {
        const double t = std::round((d[(axis + k) % 3] + 1.0) * kHullStartGrid / 2) * 2 / kHullStartGrid - 1.0;
        if (q % 2 == 0 || k == 1) d[(axis + k) % 3] = t + (q % 4 == 3 ? 1e-7 / kHullStartGrid : 0.0);
      }
      dirs.push_back(d);
    }
    int checked = 0, checked_f = 0;
    for (const Eigen::Vector3d& d : dirs) {
      const std::uint32_t c = start_cell(d);
      if (c == kNoHullVertex) continue;
      const std::uint32_t got = cell_vertex(hv, c, d);
      if (got != kNoHullVertex) {
        ++checked;
        EXPECT_EQ(got, scan_vertex(hv, d)) << n << " vertices, d " << d.transpose();
        SupportHint hint;
        hull_support(hv, d, hint);
        EXPECT_EQ(hint.vertex, got);
      }
      const Eigen::Vector3f df = d.cast<float>();
      const std::uint32_t cf = start_cell(df), got_f = cell_vertex(hv, cf, df);
      if (got_f == kNoHullVertex) continue;
      ++checked_f;
      EXPECT_EQ(got_f, scan_vertex(hv, df)) << n << " vertices, float d " << df.transpose();
    }
    EXPECT_GT(checked, 2000) << n << " vertices";
    EXPECT_GT(checked_f, 2000) << n << " vertices";
    // A list short of one vertex is not trusted: the hull is not shared as complete, its lists are rebuilt.
    auto forged = std::make_shared<ConvexHull>(h);
    std::uint32_t c = 0;
    while ((h.cell_candidates[c] & 15u) < 2) ++c;
    forged->cell_candidates[c] -= 1;
    const Shape fixed = Shape::convex(forged);
    EXPECT_NE(fixed.hull, forged);
    EXPECT_EQ(fixed.hull->cell_candidates, h.cell_candidates);
    // The float copies the float lookups read are the vertices rounded to float, and a view whose entries name
    // vertices it does not have (a hand-built HullView) gets no vertex from them: the climb answers instead.
    ASSERT_EQ(h.vertex_floats.size(), 3 * h.vertices.size());
    for (std::size_t i = 0; i < h.vertices.size(); ++i)
      for (int k = 0; k < 3; ++k) ASSERT_EQ(h.vertex_floats[3 * i + k], static_cast<float>(h.vertices[i][k]));
    std::uint32_t one = 0;
    while ((h.cell_candidates[one] & 15u) != 1) ++one;
    const std::uint32_t list_end = (h.cell_candidates[c] >> 4) + (h.cell_candidates[c] & 15u);
    HullView shrunk = hv;
    const Eigen::Vector3d any(0.3, -0.5, 0.8);  // (cell_vertex() takes the cell as given)
    shrunk.vertex_count = h.cell_candidates[list_end - 1];  // the list's largest index is now out of range
    EXPECT_EQ(cell_vertex(shrunk, c, any), kNoHullVertex);
    EXPECT_EQ(cell_vertex(shrunk, c, Eigen::Vector3f(any.cast<float>())), kNoHullVertex);
    shrunk.vertex_count = h.cell_candidates[one] >> 4;
    EXPECT_EQ(cell_vertex(shrunk, one, any), kNoHullVertex);
    shrunk.vertex_count = hv.vertex_count;
    EXPECT_NE(cell_vertex(shrunk, c, any), kNoHullVertex);
    EXPECT_EQ(cell_vertex(shrunk, one, any), h.cell_candidates[one] >> 4);
  }
}

TEST(Support, TinyDirectionsHaveNoCell) {
  // Below ~8 / max the cell arithmetic overflows (u * k with k = inf) and would name a cell d is not in: no cell,
  // so no pure cell is trusted (the climb starts from the hint or vertex 0).
  EXPECT_EQ(start_cell(Eigen::Vector3d(1e-310, -0.7e-310, 0.2e-310)), kNoHullVertex);
  EXPECT_EQ(start_cell(Eigen::Vector3f(1e-39f, 0.5e-39f, -0.9e-39f)), kNoHullVertex);
  EXPECT_NE(start_cell(Eigen::Vector3d(1e-300, -0.7e-300, 0.2e-300)), kNoHullVertex);
  EXPECT_NE(start_cell(Eigen::Vector3f(1e-37f, 0.5e-37f, -0.9e-37f)), kNoHullVertex);
}

TEST(Support, StartCellIsDefinedForEveryDirectionAndRefusesNone) {
  EXPECT_EQ(start_cell(Eigen::Vector3d(0, 0, 0)), kNoHullVertex);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(start_cell(Eigen::Vector3d(nan, nan, nan)), kNoHullVertex);
  batchcol::testing::Rng rng(35);
  for (int q = 0; q < 10000; ++q) {
    const Eigen::Vector3d d = batchcol::testing::random_unit_vector(rng) * std::pow(10.0, (q % 40) - 20);
    EXPECT_LT(start_cell(d), kHullStartCells);
    EXPECT_LT(start_cell(Eigen::Vector3f(d.cast<float>())), kHullStartCells);
  }
  // The six axis directions land on six different faces.
  std::set<std::uint32_t> faces;
  for (int a = 0; a < 3; ++a)
    for (double sign : {1.0, -1.0}) faces.insert(start_cell(Eigen::Vector3d(Eigen::Vector3d::Unit(a) * sign)) /
                                                 (kHullStartGrid * kHullStartGrid));
  EXPECT_EQ(faces.size(), 6u);
}

TEST(Support, FloatCoresStayWithinFloatRounding) {
  batchcol::testing::Rng rng(33);
  for (ShapeType t : batchcol::testing::bounded_shape_types())
    for (int trial = 0; trial < 100; ++trial) {
      const Shape s = batchcol::testing::random_shape(rng, t);
      const Eigen::Vector3d d = batchcol::testing::random_unit_vector(rng);
      SupportHint h1, h2;
      const OwnedShapeView view(s);
      const Eigen::Vector3d pd = support(make_core<double>(view.view), d, h1);
      const Eigen::Vector3f pf = support(make_core<float>(view.view), Eigen::Vector3f(d.cast<float>()), h2);
      EXPECT_NEAR(pf.cast<double>().dot(d), pd.dot(d), 1e-6) << to_string(t);
    }
}

}  // namespace
}  // namespace batchcol::kernels
