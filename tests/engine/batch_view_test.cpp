// collide() on a PairBatchView (caller-owned arrays, as the Python package passes NumPy memory): the same bits as
// on a PairBatch with the same values, from arrays laid out the way NumPy holds an (N, 3) Fortran-order array
// (one allocation, columns back to back); malformed views are InputErrors naming the array.
#include "support/generators.hpp"
#include "support/same_results.hpp"

#include <gtest/gtest.h>

namespace batchcol {
namespace {

using testing::Rng;

struct Columns {  // one block per argument, components back to back (Fortran order)
  std::vector<double> t_a, t_b, q_a, q_b;
};

TEST(PairBatchView, SameBitsAsPairBatchAtEveryLevelFromForeignMemory) {
  Rng rng(7);
  ShapeTable shapes;
  for (ShapeType t : testing::bounded_shape_types()) shapes.add(testing::random_shape(rng, t));
  PairBatch batch;
  const std::size_t n = 3000;
  for (std::size_t i = 0; i < n; ++i) {
    const Pose pa{testing::random_vector(rng), testing::random_rotation(rng)};
    const Pose pb{pa.translation + testing::random_unit_vector(rng) * testing::uniform(rng, 0, 0.5),
                  testing::random_rotation(rng)};
    batch.add(static_cast<std::uint32_t>(rng() % shapes.size()), pa, static_cast<std::uint32_t>(rng() % shapes.size()), pb);
  }
  batch.shape_b[5] = 999;  // an invalid pair is a status on both paths
  Columns c;
  const auto put3 = [](const Vec3Array& v, std::vector<double>& out) {
    for (const auto* comp : {&v.x, &v.y, &v.z}) out.insert(out.end(), comp->begin(), comp->end());
  };
  const auto put4 = [](const QuatArray& q, std::vector<double>& out) {
    for (const auto* comp : {&q.w, &q.x, &q.y, &q.z}) out.insert(out.end(), comp->begin(), comp->end());
  };
  put3(batch.translation_a, c.t_a), put3(batch.translation_b, c.t_b);
  put4(batch.rotation_a, c.q_a), put4(batch.rotation_b, c.q_b);
  const std::vector<std::uint32_t> index_a = batch.shape_a, index_b = batch.shape_b;
  PairBatchView view;
  view.shape_a = {index_a.data(), n};
  view.shape_b = {index_b.data(), n};
  const auto v3 = [n](const std::vector<double>& d) { return Vec3View{{d.data(), n}, {d.data() + n, n}, {d.data() + 2 * n, n}}; };
  const auto q4 = [n](const std::vector<double>& d) {
    return QuatView{{d.data(), n}, {d.data() + n, n}, {d.data() + 2 * n, n}, {d.data() + 3 * n, n}};
  };
  view.translation_a = v3(c.t_a), view.translation_b = v3(c.t_b);
  view.rotation_a = q4(c.q_a), view.rotation_b = q4(c.q_b);
  for (QueryLevel level : {QueryLevel::boolean, QueryLevel::distance, QueryLevel::witness, QueryLevel::penetration}) {
    QueryOptions options;
    options.level = level;
    PairResults want, got;
    collide(shapes, batch, options, want);
    collide(shapes, view, options, got);
    EXPECT_EQ(want.status[5], Status::invalid_input);
    testing::expect_same_results(want, got, to_string(level));
  }
}

TEST(PairBatchView, MismatchedOrMissingArraysAreInputErrorsNamingTheArray) {
  ShapeTable shapes;
  shapes.add(Shape::sphere(0.1));
  PairBatch batch;
  batch.add(0, Pose::identity(), 0, Pose::from_translation({0.5, 0, 0}));
  batch.add(0, Pose::identity(), 0, Pose::from_translation({0.1, 0, 0}));
  PairResults r;
  PairBatchView view = PairBatchView::of(batch);
  view.rotation_b.y.count = 1;
  try {
    collide(shapes, view, QueryOptions{}, r);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "PairBatchView::rotation_b.y has 1 entries, expected 2");
  }
  view = PairBatchView::of(batch);
  view.translation_a.z.ptr = nullptr;
  try {
    collide(shapes, view, QueryOptions{}, r);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "PairBatchView::translation_a.z has 2 entries but no data");
  }
  collide(shapes, PairBatchView::of(batch), QueryOptions{}, r);
  EXPECT_EQ(r.collide, (std::vector<std::uint8_t>{0, 1}));
}

}  // namespace
}  // namespace batchcol
