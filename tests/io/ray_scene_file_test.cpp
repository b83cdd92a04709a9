// Ray scene files: a batch file with "objects" (shape index + pose) whose "rays" are cast against those objects.
// The objects and rays are read in file order whatever the order of the top-level keys; each kind of bad input is an
// InputError naming the JSON pointer of the offending field.
#include "batchcol/io.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace batchcol {
namespace {

using ::testing::HasSubstr;

BatchFile parse(const std::string& text) { return parse_batch_json(text, "scene.json", "."); }

std::string error_of(const std::string& text) {
  try {
    parse(text);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError for: " << text;
  return "";
}

constexpr const char* kShapes = R"("shapes": [{"type": "sphere", "radius": 1}, {"type": "box", "half_extents": [1, 2, 3]}])";

// A scene file of the two shapes above with the given objects and rays.
std::string scene(const std::string& objects, const std::string& rays) {
  return std::string("{") + kShapes + R"(, "objects": )" + objects + R"(, "rays": )" + rays + "}";
}

constexpr const char* kObject = R"([{"shape": 0}])";
constexpr const char* kRay = R"([{"origin": [0, 0, 0], "direction": [1, 0, 0]}])";

TEST(RaySceneFile, ReadsObjectsAndRaysInFileOrder) {
  const BatchFile f = parse(scene(
      R"([{"shape": 1, "pose": {"translation": [1, 2, 3], "quaternion": [0, 1, 0, 0]}}, {"shape": 0}])",
      R"([{"origin": [0, 0, 0], "direction": [2, 0, 0]}, {"origin": [1, 1, 1], "direction": [0, 0, -1], "t_max": 4}])"));
  EXPECT_TRUE(f.has_objects);
  EXPECT_EQ(f.shapes.size(), 2u);
  ASSERT_EQ(f.objects.size(), 2u);
  EXPECT_EQ(f.objects[0].shape, 1u);
  EXPECT_EQ(f.objects[0].pose.translation, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(f.objects[0].pose.rotation.coeffs(), Eigen::Quaterniond(0, 1, 0, 0).coeffs());
  EXPECT_EQ(f.objects[1].shape, 0u);
  EXPECT_EQ(f.objects[1].pose.translation, Eigen::Vector3d::Zero());  // pose optional: identity
  EXPECT_EQ(f.objects[1].pose.rotation.coeffs(), Eigen::Quaterniond::Identity().coeffs());
  ASSERT_EQ(f.scene_rays.size(), 2u);
  EXPECT_EQ(f.rays.size(), 0u);  // scene rays are not shape-form rays
  EXPECT_EQ(f.scene_rays.direction.x[0], 2.0);
  EXPECT_TRUE(std::isinf(f.scene_rays.t_max[0]));  // t_max optional: +inf
  EXPECT_EQ(f.scene_rays.origin.y[1], 1.0);
  EXPECT_EQ(f.scene_rays.direction.z[1], -1.0);
  EXPECT_EQ(f.scene_rays.t_max[1], 4.0);
  EXPECT_EQ(f.pairs.size(), 0u);  // a scene file needs no pairs
}

TEST(RaySceneFile, KeysMayComeInAnyOrder) {
  // Rays before objects, objects before shapes: the same file.
  const BatchFile a = parse(scene(R"([{"shape": 1}])", kRay));
  const BatchFile b = parse(std::string(R"({"rays": )") + kRay + R"(, "objects": [{"shape": 1}], )" + kShapes + "}");
  EXPECT_EQ(b.objects.size(), 1u);
  EXPECT_EQ(b.objects[0].shape, a.objects[0].shape);
  EXPECT_EQ(b.scene_rays.size(), 1u);
  EXPECT_EQ(b.scene_rays.direction.x[0], a.scene_rays.direction.x[0]);
}

TEST(RaySceneFile, EmptyObjectsStillMakeAScene) {
  const BatchFile f = parse(scene("[]", kRay));
  EXPECT_TRUE(f.has_objects);
  EXPECT_EQ(f.objects.size(), 0u);
  EXPECT_EQ(f.scene_rays.size(), 1u);
  EXPECT_FALSE(parse(std::string("{") + kShapes + R"(, "pairs": []})").has_objects);
}

TEST(RaySceneFileErrors, BadRaysNameTheRay) {
  const struct {
    const char* rays;
    const char* message;
  } cases[] = {
      {R"([{"origin": [0, 0, 0], "direction": [0, 0, 0]}])", "scene.json: /rays/0/direction: the direction must not be zero"},
      // |d|^2 underflows to 0: the kernels would divide by zero, so it counts as zero (as ray_is_valid()).
      {R"([{"origin": [0, 0, 0], "direction": [1e-200, 0, 0]}])", "/rays/0/direction: the direction must not be zero"},
      {R"([{"origin": [0, 0, 0], "direction": [1, 0, 0], "t_max": -1}])", "/rays/0/t_max: must be >= 0"},
      {R"([{"origin": [0, 0, 0], "direction": [1, 0, 0]}, {"origin": [0, 0], "direction": [1, 0, 0]}])",
       "/rays/1/origin: expected 3 elements"},
      {R"([{"direction": [1, 0, 0]}])", "/rays/0/origin: required field is missing"},
      {R"([{"origin": [0, 0, 0], "direction": [1, "x", 0]}])", "/rays/0/direction/1: expected a number"},
      {R"([{"origin": [0, 0, 0], "direction": [1, 0, 0], "colour": 1}])", "/rays/0/colour: unknown key 'colour'"},
      {R"([{"origin": [0, 0, 0], "direction": [1, 0, 0], "t_max": 1e999}])", "/rays/0/t_max"},
      {R"([3])", "/rays/0: expected an object"},
      {R"({"origin": [0, 0, 0]})", "/rays: expected an array"},
      // A scene's rays are cast against the objects: a shape or pose is a mistake, not ignored.
      {R"([{"shape": 0, "origin": [0, 0, 0], "direction": [1, 0, 0]}])",
       "/rays/0/shape: the rays of a file with \"objects\" are cast against the objects"},
      {R"([{"origin": [0, 0, 0], "direction": [1, 0, 0]}, {"pose": {}, "origin": [0, 0, 0], "direction": [1, 0, 0]}])",
       "/rays/1/shape: the rays of a file with \"objects\""},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.rays);
    EXPECT_THAT(error_of(scene(kObject, c.rays)), HasSubstr(c.message));
  }
}

TEST(RaySceneFileErrors, ShapeRaysAreRefusedWhenTheObjectsComeLater) {
  // The kind of the rays is only known at the end of the file here.
  EXPECT_THAT(error_of(std::string("{") + kShapes +
                       R"(, "rays": [{"shape": 0, "origin": [0, 0, 0], "direction": [1, 0, 0]}], "objects": [])" + "}"),
              HasSubstr("/rays/0/shape: the rays of a file with \"objects\" are cast against the objects"));
}

TEST(RaySceneFileErrors, SceneRaysWithoutObjectsNameTheMissingShape) {
  EXPECT_THAT(error_of(std::string("{") + kShapes + R"(, "rays": [{"shape": 0, "origin": [0, 0, 0], "direction": [1, 0, 0]},)"
                                                    R"( {"origin": [0, 0, 0], "direction": [1, 0, 0]}]})"),
              HasSubstr("scene.json: /rays/1/shape: required field is missing (rays without a shape need \"objects\""));
}

TEST(RaySceneFileErrors, BadObjectsNameTheObject) {
  const struct {
    const char* objects;
    const char* message;
  } cases[] = {
      {R"([{"shape": 2}])", "/objects/0/shape: shape index 2 is out of range (the batch has 2 shapes)"},
      {R"([{"shape": 0}, {"shape": -1}])", "/objects/1/shape: shape index -1 is out of range"},
      {R"([{"shape": 0.5}])", "/objects/0/shape: expected a shape index"},
      {R"([{"pose": {}}])", "/objects/0/shape: required field is missing"},
      {R"([{"shape": 0, "pose": {"quaternion": [1, 1, 0, 0]}}])", "/objects/0/pose/quaternion"},
      {R"([{"shape": 0, "pose": {"translation": [0, 0]}}])", "/objects/0/pose/translation: expected 3 elements"},
      {R"([{"shape": 0, "pose": {"scale": 2}}])", "/objects/0/pose/scale: unknown key 'scale'"},
      {R"([{"shape": 0, "colour": 2}])", "/objects/0/colour: unknown key 'colour' (allowed here: shape, pose)"},
      {R"([[0]])", "/objects/0: expected an object"},
      {R"({"shape": 0})", "/objects: expected an array"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.objects);
    EXPECT_THAT(error_of(scene(c.objects, kRay)), HasSubstr(c.message));
  }
}

TEST(RaySceneFileErrors, ObjectIndicesAreCheckedWhenTheShapesComeLater) {
  EXPECT_THAT(error_of(std::string(R"({"objects": [{"shape": 0}, {"shape": 5}], "rays": )") + kRay + ", " + kShapes + "}"),
              HasSubstr("/objects/1/shape: shape index 5 is out of range (the batch has 2 shapes)"));
}

}  // namespace
}  // namespace batchcol
