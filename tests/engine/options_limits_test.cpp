// QueryOptions limits (issue #16, items 1 and 12): a thread count beyond kMaxThreads and an enum value outside
// InstructionSet are whole-call errors (InputError naming the option), for collide() and Scene::collide() alike.
#include <batchcol/batchcol.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <climits>
#include <memory>
#include <string>

namespace batchcol {
namespace {

using ::testing::HasSubstr;

struct Call {
  ShapeTable shapes;
  PairBatch batch;
  Call() {
    shapes.add(Shape::sphere(0.5));
    batch.add(0, Pose::identity(), 0, Pose{Eigen::Vector3d(2, 0, 0), Eigen::Quaterniond::Identity()});
  }
};

std::string message_of(const QueryOptions& options) {
  Call c;
  PairResults r;
  try {
    collide(c.shapes, c.batch, options, r);
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(OptionsLimits, ThreadsAboveTheMaximumAreRejectedBeforeAnyArenaIsMade) {
  for (int threads : {kMaxThreads + 1, 10'000'000, INT_MAX}) {
    QueryOptions o;
    o.threads = threads;
    EXPECT_THAT(message_of(o), HasSubstr("QueryOptions::threads must be between 0 (all cores) and 1024"))
        << threads;
  }
  QueryOptions o;
  o.threads = -1;
  EXPECT_THAT(message_of(o), HasSubstr("QueryOptions::threads"));
}

TEST(OptionsLimits, ThreadsUpToTheMaximumRun) {
  for (int threads : {0, 1, kMaxThreads}) {
    Call c;
    QueryOptions o;
    o.threads = threads;
    PairResults r;
    collide(c.shapes, c.batch, o, r);
    ASSERT_EQ(r.size(), 1u);
    EXPECT_EQ(r.status[0], Status::converged);
    EXPECT_DOUBLE_EQ(r.distance[0], 1.0);
  }
}

TEST(OptionsLimits, SceneRejectsTooManyThreads) {
  auto shapes = std::make_shared<ShapeTable>();
  shapes->add(Shape::sphere(0.5));
  Scene scene(shapes);
  scene.add(0, Pose::identity());
  QueryOptions o;
  o.threads = INT_MAX;
  SceneResults r;
  EXPECT_THROW(scene.collide(o, r), InputError);
}

TEST(OptionsLimits, InstructionSetOutsideTheEnumIsRejected) {
  QueryOptions o;
  o.isa = static_cast<InstructionSet>(9);
  EXPECT_THAT(message_of(o), HasSubstr("QueryOptions::isa is not an InstructionSet"));
  o.isa = static_cast<InstructionSet>(4);
  EXPECT_THAT(message_of(o), HasSubstr("QueryOptions::isa"));
  o.isa = InstructionSet::scalar;
  EXPECT_EQ(message_of(o), "accepted");
}

}  // namespace
}  // namespace batchcol
