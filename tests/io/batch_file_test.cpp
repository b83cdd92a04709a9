// Batch-file parsing: one valid file covering every shape type and pose form, and one test per kind of bad input
// asserting that the message names the file and the JSON pointer of the offending field.
#include "batchcol/io.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <sys/stat.h>
#include <unistd.h>

namespace batchcol {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const std::string kDataDir = BATCHCOL_TEST_DATA_DIR;

BatchFile parse(const std::string& text) { return parse_batch_json(text, "batch.json", kDataDir); }

// Returns the InputError message of parsing `text` (fails the test when nothing is thrown).
std::string error_of(const std::string& text) {
  try {
    parse(text);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError for: " << text;
  return "";
}

// A batch with one sphere and one box, and the given pair list / extra top-level members.
std::string with_pairs(const std::string& pairs, const std::string& extra = "") {
  return R"({"shapes":[{"type":"sphere","radius":0.5},{"type":"box","half_extents":[1,2,3]}],"pairs":)" + pairs +
         extra + "}";
}

// A batch with the given single shape and no pairs.
std::string with_shape(const std::string& shape) { return R"({"shapes":[)" + shape + R"(],"pairs":[]})"; }

// A fresh directory under the test temp dir, removed with everything in it at the end of the scope.
struct TempDir {
  explicit TempDir(const std::string& name)
      : path(fs::path(testing::TempDir()) / ("batchcol_batch_file_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  fs::path path;
};

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good());
}

void expect_same_shape(const Shape& actual, const Shape& expected) {
  EXPECT_EQ(actual.type, expected.type);
  EXPECT_EQ(actual.size, expected.size);
  EXPECT_EQ(actual.offset, expected.offset);
  EXPECT_EQ(actual.inflation, expected.inflation);
}

TEST(BatchFile, ParsesEveryShapeType) {
  const BatchFile file = parse(R"({
    "shapes": [
      {"type": "box", "half_extents": [0.1, 0.2, 0.3]},
      {"type": "sphere", "radius": 0.25},
      {"type": "capsule", "radius": 0.1, "half_length": 0.4},
      {"type": "cylinder", "radius": 0.2, "half_length": 0.3},
      {"type": "cone", "radius": 0.3, "half_length": 0.5},
      {"type": "ellipsoid", "radii": [0.1, 0.2, 0.3]},
      {"type": "convex", "vertices": [[0,0,0],[1,0,0],[0,1,0],[0,0,1],[0.1,0.1,0.1]]},
      {"type": "mesh", "file": "tetrahedron.ascii.stl"},
      {"type": "triangle", "vertices": [[0,0,0],[1,0,0],[0,1,0]]},
      {"type": "halfspace", "normal": [0, 0, 1], "offset": -0.5},
      {"type": "box", "half_extents": [1, 1, 1], "inflation": 0.05},
      {"type": "mesh", "file": "cube.bin.stl"}
    ],
    "pairs": []
  })");
  ASSERT_EQ(file.shapes.size(), 12u);
  expect_same_shape(file.shapes[0], Shape::box(0.1, 0.2, 0.3));
  expect_same_shape(file.shapes[1], Shape::sphere(0.25));
  expect_same_shape(file.shapes[2], Shape::capsule(0.1, 0.4));
  expect_same_shape(file.shapes[3], Shape::cylinder(0.2, 0.3));
  expect_same_shape(file.shapes[4], Shape::cone(0.3, 0.5));
  expect_same_shape(file.shapes[5], Shape::ellipsoid(0.1, 0.2, 0.3));

  ASSERT_EQ(file.shapes[6].type, ShapeType::convex);
  ASSERT_NE(file.shapes[6].hull, nullptr);
  EXPECT_EQ(file.shapes[6].hull->vertices.size(), 4u);  // the interior point is not a hull vertex

  ASSERT_EQ(file.shapes[7].type, ShapeType::convex);
  ASSERT_NE(file.shapes[7].hull, nullptr);
  EXPECT_EQ(file.shapes[7].hull->vertices.size(), 4u);

  ASSERT_EQ(file.shapes[8].type, ShapeType::triangle);
  EXPECT_EQ(file.shapes[8].triangle[1], Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(file.shapes[8].triangle[2], Eigen::Vector3d(0, 1, 0));

  expect_same_shape(file.shapes[9], Shape::halfspace(Eigen::Vector3d(0, 0, 1), -0.5));
  EXPECT_EQ(file.shapes[9].size, Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(file.shapes[9].offset, -0.5);

  expect_same_shape(file.shapes[10], Shape::box(1, 1, 1).inflated(0.05));
  EXPECT_EQ(file.shapes[10].inflation, 0.05);

  ASSERT_NE(file.shapes[11].hull, nullptr);
  EXPECT_EQ(file.shapes[11].hull->vertices.size(), 8u);
  for (const Eigen::Vector3d& v : file.shapes[11].hull->vertices) EXPECT_EQ(v.cwiseAbs(), Eigen::Vector3d(1, 1, 1));
}

TEST(BatchFile, ParsesEveryPoseForm) {
  const double h = std::sqrt(0.5);
  const BatchFile file = parse(with_pairs(R"([
    {"a": 0, "b": 1},
    {"a": 1, "b": 0, "pose_a": {"translation": [1, 2, 3], "quaternion": [1.0000005, 0, 0, 0]},
                     "pose_b": {"quaternion": [0, 0, 0, 1]}},
    {"a": 0, "b": 0, "pose_a": {"rotation": [[0, -1, 0], [1, 0, 0], [0, 0, 1]], "translation": [0, 0, -1]},
                     "pose_b": {}}
  ])"));
  ASSERT_EQ(file.pairs.size(), 3u);
  EXPECT_EQ(file.pairs.shape_a[0], 0u);
  EXPECT_EQ(file.pairs.shape_b[0], 1u);
  EXPECT_EQ(file.pairs.shape_a[1], 1u);
  EXPECT_EQ(file.pairs.shape_b[1], 0u);

  // Missing poses, translations and rotations are the identity.
  for (const Pose& pose : {file.pairs.pose_a(0), file.pairs.pose_b(0), file.pairs.pose_b(2)}) {
    EXPECT_EQ(pose.translation, Eigen::Vector3d::Zero());
    EXPECT_EQ(pose.rotation.coeffs(), Eigen::Quaterniond::Identity().coeffs());
  }
  EXPECT_EQ(file.pairs.pose_b(1).translation, Eigen::Vector3d::Zero());

  // A quaternion within 1e-6 of unit norm is normalized.
  const Pose a1 = file.pairs.pose_a(1);
  EXPECT_EQ(a1.translation, Eigen::Vector3d(1, 2, 3));
  EXPECT_NEAR(a1.rotation.w(), 1.0, 1e-15);
  EXPECT_NEAR(a1.rotation.norm(), 1.0, 1e-15);
  const Pose b1 = file.pairs.pose_b(1);
  EXPECT_EQ(b1.rotation.coeffs(), Eigen::Quaterniond(0, 0, 0, 1).coeffs());

  // Rows of a 90 degree rotation about z -> quaternion (cos 45, 0, 0, sin 45), up to sign.
  const Pose a2 = file.pairs.pose_a(2);
  EXPECT_EQ(a2.translation, Eigen::Vector3d(0, 0, -1));
  const double sign = a2.rotation.w() < 0 ? -1.0 : 1.0;
  EXPECT_NEAR(sign * a2.rotation.w(), h, 1e-15);
  EXPECT_NEAR(sign * a2.rotation.x(), 0.0, 1e-15);
  EXPECT_NEAR(sign * a2.rotation.y(), 0.0, 1e-15);
  EXPECT_NEAR(sign * a2.rotation.z(), h, 1e-15);
  EXPECT_TRUE((a2.rotation * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-15));
}

TEST(BatchFile, ParsesSettingsAndAppliesThem) {
  const BatchFile file = parse(with_pairs(
      "[]", R"(,"query":"penetration","solver":"polyak","tolerance":1e-6,"precision":"float","margin":0.01)"));
  ASSERT_TRUE(file.query && file.solver && file.tolerance && file.precision && file.margin);
  QueryOptions options;
  options.threads = 3;
  file.apply_to(options);
  EXPECT_EQ(options.level, QueryLevel::penetration);
  EXPECT_EQ(options.solver, Solver::polyak);
  EXPECT_EQ(options.tolerance, 1e-6);
  EXPECT_EQ(options.precision, Precision::float32);
  EXPECT_EQ(options.margin, 0.01);
  EXPECT_EQ(options.threads, 3);
}

TEST(BatchFile, MissingSettingsLeaveOptionsUnchanged) {
  const BatchFile file = parse(with_pairs("[]"));
  EXPECT_FALSE(file.query || file.solver || file.tolerance || file.precision || file.margin);
  QueryOptions options;
  options.level = QueryLevel::boolean;
  options.tolerance = 0.5;
  file.apply_to(options);
  EXPECT_EQ(options.level, QueryLevel::boolean);
  EXPECT_EQ(options.solver, QueryOptions{}.solver);
  EXPECT_EQ(options.tolerance, 0.5);
}

TEST(BatchFile, LoadsFileAndResolvesMeshPathsAgainstItsFolder) {
  const TempDir temp("load");
  const fs::path& dir = temp.path;
  fs::create_directories(dir / "meshes");
  fs::copy_file(fs::path(kDataDir) / "cube.bin.stl", dir / "meshes" / "cube.stl");
  write_text(dir / "batch.json",
             R"({"shapes":[{"type":"mesh","file":"meshes/cube.stl"}],"pairs":[{"a":0,"b":0}],"query":"distance"})");
  const BatchFile file = load_batch_file((dir / "batch.json").string());
  ASSERT_EQ(file.shapes.size(), 1u);
  EXPECT_EQ(file.shapes[0].type, ShapeType::convex);
  EXPECT_EQ(file.pairs.size(), 1u);
  EXPECT_EQ(file.query, QueryLevel::distance);
}

// ---- malformed input -------------------------------------------------------------------------------------------

TEST(BatchFileErrors, MalformedJsonGivesLineAndColumn) {
  const std::string msg = error_of("{\n  \"shapes\": [\n    {\"type\": \"sphere\" \"radius\": 1}\n  ],\n  \"pairs\": []\n}");
  EXPECT_THAT(msg, HasSubstr("batch.json"));
  EXPECT_THAT(msg, HasSubstr("line 3, column 23"));
  EXPECT_THAT(msg, HasSubstr("/shapes/0"));
}

TEST(BatchFileErrors, TruncatedJson) {
  const std::string msg = error_of("{\"shapes\": [\n");
  EXPECT_THAT(msg, HasSubstr("batch.json: line 2"));
  EXPECT_THAT(msg, HasSubstr("invalid JSON"));
}

TEST(BatchFileErrors, EmptyText) { EXPECT_THAT(error_of(""), HasSubstr("batch.json: line 1, column 1")); }

TEST(BatchFileErrors, TrailingGarbage) { EXPECT_THAT(error_of(with_pairs("[]") + " x"), HasSubstr("invalid JSON")); }

TEST(BatchFileErrors, TopLevelNotAnObject) {
  const std::string msg = error_of("[1, 2]");
  EXPECT_THAT(msg, HasSubstr("batch.json: top level"));
  EXPECT_THAT(msg, HasSubstr("must be an object"));
}

TEST(BatchFileErrors, MissingShapes) { EXPECT_THAT(error_of(R"({"pairs":[]})"), HasSubstr("batch.json: /shapes: required")); }

TEST(BatchFileErrors, MissingPairs) {
  EXPECT_THAT(error_of(R"({"shapes":[]})"), HasSubstr("batch.json: /pairs: required"));
}

TEST(BatchFileErrors, ShapesNotAnArray) {
  EXPECT_THAT(error_of(R"({"shapes":{},"pairs":[]})"), HasSubstr("/shapes: expected an array"));
}

TEST(BatchFileErrors, ShapeNotAnObject) { EXPECT_THAT(error_of(with_shape("3")), HasSubstr("/shapes/0: expected an object")); }

TEST(BatchFileErrors, UnknownShapeType) {
  const std::string msg = error_of(with_shape(R"({"type":"spere","radius":1})"));
  EXPECT_THAT(msg, HasSubstr("/shapes/0/type"));
  EXPECT_THAT(msg, HasSubstr("'spere'"));
}

TEST(BatchFileErrors, MissingShapeType) { EXPECT_THAT(error_of(with_shape(R"({"radius":1})")), HasSubstr("/shapes/0/type")); }

TEST(BatchFileErrors, MissingField) {
  EXPECT_THAT(error_of(with_shape(R"({"type":"capsule","radius":1})")), HasSubstr("/shapes/0/half_length: required"));
}

TEST(BatchFileErrors, WrongTypedField) {
  const std::string msg = error_of(with_shape(R"({"type":"sphere","radius":"1.0"})"));
  EXPECT_THAT(msg, HasSubstr("/shapes/0/radius"));
  EXPECT_THAT(msg, HasSubstr("expected a number"));
  EXPECT_THAT(error_of(with_shape(R"({"type":7})")), HasSubstr("/shapes/0/type: expected a string"));
  EXPECT_THAT(error_of(with_shape(R"({"type":"box","half_extents":1})")), HasSubstr("/shapes/0/half_extents"));
  EXPECT_THAT(error_of(with_shape(R"({"type":"mesh","file":3})")), HasSubstr("/shapes/0/file"));
}

TEST(BatchFileErrors, WrongArrayLength) {
  EXPECT_THAT(error_of(with_shape(R"({"type":"box","half_extents":[1,2]})")),
              HasSubstr("/shapes/0/half_extents: expected 3 elements, got 2"));
  EXPECT_THAT(error_of(with_pairs(R"([{"a":0,"b":1,"pose_b":{"translation":[1,2,3,4]}}])")),
              HasSubstr("/pairs/0/pose_b/translation: expected 3 elements"));
  EXPECT_THAT(error_of(with_pairs(R"([{"a":0,"b":1,"pose_a":{"quaternion":[1,0,0]}}])")),
              HasSubstr("/pairs/0/pose_a/quaternion: expected 4 elements"));
  EXPECT_THAT(error_of(with_shape(R"({"type":"triangle","vertices":[[0,0,0],[1,0,0]]})")),
              HasSubstr("/shapes/0/vertices"));
  EXPECT_THAT(error_of(with_shape(R"({"type":"convex","vertices":[[0,0,0],[1,0,0],[0,1,0]]})")),
              HasSubstr("/shapes/0/vertices: expected at least 4 points"));
  EXPECT_THAT(error_of(with_shape(R"({"type":"convex","vertices":[[0,0,0],[1,0,0],[0,1,0],[0,0]]})")),
              HasSubstr("/shapes/0/vertices/3"));
}

TEST(BatchFileErrors, NegativeSize) {
  EXPECT_THAT(error_of(with_shape(R"({"type":"sphere","radius":-1})")), HasSubstr("/shapes/0/radius: must be > 0"));
  EXPECT_THAT(error_of(with_shape(R"({"type":"cone","radius":1,"half_length":-0.5})")),
              HasSubstr("/shapes/0/half_length: must be > 0"));
}

TEST(BatchFileErrors, ZeroSize) {
  EXPECT_THAT(error_of(with_shape(R"({"type":"box","half_extents":[1,0,1]})")),
              HasSubstr("/shapes/0/half_extents/1: must be > 0"));
  EXPECT_THAT(error_of(with_shape(R"({"type":"ellipsoid","radii":[1,1,0]})")), HasSubstr("/shapes/0/radii/2"));
}

TEST(BatchFileErrors, NegativeInflation) {
  EXPECT_THAT(error_of(with_shape(R"({"type":"box","half_extents":[1,1,1],"inflation":-0.1})")),
              HasSubstr("/shapes/0/inflation: must be >= 0"));
}

TEST(BatchFileErrors, NanAsString) {
  const std::string msg = error_of(with_shape(R"({"type":"sphere","radius":"nan"})"));
  EXPECT_THAT(msg, HasSubstr("/shapes/0/radius"));
  EXPECT_THAT(msg, HasSubstr("expected a number"));
}

TEST(BatchFileErrors, OverflowingNumber) {
  const std::string msg = error_of("{\"shapes\":[\n{\"type\":\"sphere\",\"radius\":1e999}],\"pairs\":[]}");
  EXPECT_THAT(msg, HasSubstr("/shapes/0/radius"));
  EXPECT_THAT(msg, HasSubstr("line 2"));
  EXPECT_THAT(error_of(with_pairs(R"([{"a":0,"b":1,"pose_a":{"translation":[0,-1e400,0]}}])")),
              HasSubstr("/pairs/0/pose_a/translation/1"));
}

TEST(BatchFileErrors, NonUnitQuaternion) {
  const std::string msg =
      error_of(with_pairs(R"([{"a":0,"b":1},{"a":0,"b":1,"pose_a":{"quaternion":[1,0,0,0.01]}}])"));
  EXPECT_THAT(msg, HasSubstr("batch.json: /pairs/1/pose_a/quaternion"));
  EXPECT_THAT(msg, HasSubstr("norm"));
  // Just beyond the 1e-6 tolerance.
  EXPECT_THAT(error_of(with_pairs(R"([{"a":0,"b":1,"pose_b":{"quaternion":[1.000002,0,0,0]}}])")),
              HasSubstr("/pairs/0/pose_b/quaternion"));
  EXPECT_THAT(error_of(with_pairs(R"([{"a":0,"b":1,"pose_b":{"quaternion":[0,0,0,0]}}])")),
              HasSubstr("/pairs/0/pose_b/quaternion"));
}

TEST(BatchFileErrors, NonOrthonormalRotation) {
  EXPECT_THAT(error_of(with_pairs(R"([{"a":0,"b":1,"pose_a":{"rotation":[[1,0,0],[0,1,0.01],[0,0,1]]}}])")),
              HasSubstr("/pairs/0/pose_a/rotation: not a rotation matrix"));
}

TEST(BatchFileErrors, ReflectionIsNotARotation) {
  EXPECT_THAT(error_of(with_pairs(R"([{"a":0,"b":1,"pose_b":{"rotation":[[1,0,0],[0,1,0],[0,0,-1]]}}])")),
              HasSubstr("/pairs/0/pose_b/rotation: not a rotation matrix"));
}

TEST(BatchFileErrors, RotationWithWrongShape) {
  EXPECT_THAT(error_of(with_pairs(R"([{"a":0,"b":1,"pose_b":{"rotation":[[1,0,0],[0,1,0]]}}])")),
              HasSubstr("/pairs/0/pose_b/rotation"));
  EXPECT_THAT(error_of(with_pairs(R"([{"a":0,"b":1,"pose_b":{"rotation":[[1,0,0],[0,1,0],[0,1]]}}])")),
              HasSubstr("/pairs/0/pose_b/rotation/2"));
}

TEST(BatchFileErrors, QuaternionAndRotationTogether) {
  EXPECT_THAT(
      error_of(with_pairs(R"([{"a":0,"b":1,"pose_a":{"quaternion":[1,0,0,0],"rotation":[[1,0,0],[0,1,0],[0,0,1]]}}])")),
      HasSubstr("/pairs/0/pose_a: give either"));
}

TEST(BatchFileErrors, PoseNotAnObject) {
  EXPECT_THAT(error_of(with_pairs(R"([{"a":0,"b":1,"pose_a":[0,0,0]}])")), HasSubstr("/pairs/0/pose_a: expected an object"));
}

TEST(BatchFileErrors, ShapeIndexOutOfRange) {
  const std::string msg = error_of(with_pairs(R"([{"a":0,"b":1},{"a":0,"b":2}])"));
  EXPECT_THAT(msg, HasSubstr("batch.json: /pairs/1/b"));
  EXPECT_THAT(msg, HasSubstr("out of range"));
  EXPECT_THAT(error_of(with_pairs(R"([{"a":4294967296,"b":0}])")), HasSubstr("/pairs/0/a"));
}

TEST(BatchFileErrors, NegativeShapeIndex) {
  EXPECT_THAT(error_of(with_pairs(R"([{"a":-1,"b":0}])")), HasSubstr("/pairs/0/a"));
}

TEST(BatchFileErrors, NonIntegerShapeIndex) {
  EXPECT_THAT(error_of(with_pairs(R"([{"a":0,"b":0.5}])")), HasSubstr("/pairs/0/b: expected a shape index"));
  EXPECT_THAT(error_of(with_pairs(R"([{"a":"0","b":0}])")), HasSubstr("/pairs/0/a: expected a shape index"));
}

TEST(BatchFileErrors, MissingShapeIndex) {
  EXPECT_THAT(error_of(with_pairs(R"([{"a":0}])")), HasSubstr("/pairs/0/b: required"));
}

TEST(BatchFileErrors, UnknownQueryLevel) {
  const std::string msg = error_of(with_pairs("[]", R"(,"query":"fast")"));
  EXPECT_THAT(msg, HasSubstr("/query"));
  EXPECT_THAT(msg, HasSubstr("boolean, distance, witness, penetration"));
}

TEST(BatchFileErrors, UnknownSolver) {
  EXPECT_THAT(error_of(with_pairs("[]", R"(,"solver":"epa")")), HasSubstr("/solver: unknown solver 'epa'"));
}

TEST(BatchFileErrors, UnknownPrecision) {
  EXPECT_THAT(error_of(with_pairs("[]", R"(,"precision":"half")")), HasSubstr("/precision: unknown precision 'half'"));
  EXPECT_THAT(error_of(with_pairs("[]", R"(,"precision":32)")), HasSubstr("/precision: expected a string"));
}

TEST(BatchFileErrors, NegativeTolerance) {
  EXPECT_THAT(error_of(with_pairs("[]", R"(,"tolerance":-1e-9)")), HasSubstr("/tolerance: must be >= 0"));
}

TEST(BatchFileErrors, NegativeMargin) {
  EXPECT_THAT(error_of(with_pairs("[]", R"(,"margin":-0.1)")), HasSubstr("/margin: must be >= 0"));
}

TEST(BatchFileErrors, UnknownKeys) {
  EXPECT_THAT(error_of(with_pairs("[]", R"(,"tolerence":1e-6)")), HasSubstr("/tolerence: unknown key 'tolerence'"));
  EXPECT_THAT(error_of(with_shape(R"({"type":"sphere","radius":1,"raduis":2})")),
              HasSubstr("/shapes/0/raduis: unknown key"));
  // A field of another shape type is a mistake too.
  EXPECT_THAT(error_of(with_shape(R"({"type":"sphere","radius":1,"half_length":2})")),
              HasSubstr("/shapes/0/half_length: unknown key"));
  EXPECT_THAT(error_of(with_pairs(R"([{"a":0,"b":1,"pose_a":{"translaton":[0,0,0]}}])")),
              HasSubstr("/pairs/0/pose_a/translaton: unknown key"));
  EXPECT_THAT(error_of(with_pairs(R"([{"a":0,"b":1,"pose_c":{}}])")), HasSubstr("/pairs/0/pose_c: unknown key"));
}

TEST(BatchFileErrors, DuplicateKey) {
  EXPECT_THAT(error_of(with_shape(R"({"type":"sphere","radius":1,"radius":2})")),
              HasSubstr("/shapes/0/radius: duplicate key"));
  EXPECT_THAT(error_of(with_pairs(R"([{"a":0,"b":1},{"a":0,"a":1,"b":1}])")), HasSubstr("/pairs/1/a: duplicate key"));
}

TEST(BatchFileErrors, DegenerateConvexHull) {
  // Coplanar points: the hull code rejects them and the message gets the field's pointer.
  EXPECT_THAT(error_of(with_shape(R"({"type":"convex","vertices":[[0,0,0],[1,0,0],[0,1,0],[1,1,0]]})")),
              HasSubstr("batch.json: /shapes/0/vertices"));
}

TEST(BatchFileErrors, ZeroHalfspaceNormal) {
  EXPECT_THAT(error_of(with_shape(R"({"type":"halfspace","normal":[0,0,0],"offset":1})")),
              HasSubstr("/shapes/0/normal"));
}

TEST(BatchFileErrors, MissingMeshFile) {
  const std::string msg = error_of(with_shape(R"({"type":"mesh","file":"no_such_mesh.stl"})"));
  EXPECT_THAT(msg, HasSubstr("batch.json: /shapes/0/file"));
  EXPECT_THAT(msg, HasSubstr("no_such_mesh.stl"));
}

TEST(BatchFileErrors, MissingBatchFile) {
  const TempDir temp("missing");
  const std::string path = (temp.path / "nothing.json").string();
  try {
    load_batch_file(path);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(path));
    EXPECT_THAT(e.what(), HasSubstr("no such file"));
  }
}

TEST(BatchFileErrors, DirectoryInsteadOfBatchFile) {
  const TempDir temp("directory");
  const std::string path = temp.path.string();
  try {
    load_batch_file(path);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(path));
    EXPECT_THAT(e.what(), HasSubstr("is a directory"));
  }
}

TEST(BatchFileErrors, NonRegularBatchFile) {
  const TempDir temp("fifo");
  const fs::path fifo = temp.path / "batch.json";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  try {
    load_batch_file(fifo.string());  // must not block reading the pipe
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(fifo.string() + ": not a regular file"));
  }
}

TEST(BatchFileErrors, UnreadableBatchFile) {
  if (::geteuid() == 0) GTEST_SKIP() << "root reads files regardless of their permissions";
  const TempDir temp("unreadable");
  const fs::path path = temp.path / "batch.json";
  write_text(path, with_pairs("[]"));
  fs::permissions(path, fs::perms::none);
  try {
    load_batch_file(path.string());
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(path.string() + ": cannot open"));
  }
}

TEST(BatchFileErrors, ErrorInLoadedFileNamesThePath) {
  const TempDir temp("named");
  const fs::path& dir = temp.path;
  write_text(dir / "bad.json", R"({"shapes":[],"pairs":[{"a":0,"b":0}]})");
  try {
    load_batch_file((dir / "bad.json").string());
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr((dir / "bad.json").string() + ": /pairs/0/a"));
  }
}

// ---- meshes ----------------------------------------------------------------------------------------------------

TEST(MeshFile, LoadsAsciiAndBinaryStl) {
  const auto tetrahedron = load_mesh_points(kDataDir + "/tetrahedron.ascii.stl");
  ASSERT_FALSE(tetrahedron.empty());
  for (const auto& p : tetrahedron) EXPECT_TRUE(p.minCoeff() >= 0.0 && p.sum() <= 1.0) << p.transpose();
  const auto cube = load_mesh_points(kDataDir + "/cube.bin.stl");
  ASSERT_FALSE(cube.empty());
  for (const auto& p : cube) EXPECT_EQ(p.cwiseAbs(), Eigen::Vector3d(1, 1, 1));
}

TEST(MeshFile, RejectsMissingEmptyAndDirectory) {
  const TempDir temp("mesh");
  const fs::path& dir = temp.path;
  write_text(dir / "empty.stl", "");
  write_text(dir / "nothing.stl", "solid nothing\nendsolid nothing\n");
  for (const std::string name : {"absent.stl", "empty.stl", "nothing.stl", ""}) {
    const std::string path = (dir / name).string();
    try {
      load_mesh_points(path);
      ADD_FAILURE() << "no InputError for " << path;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr(path));
    }
  }
}

TEST(MeshFile, RejectsNonFiniteCoordinates) {
  const TempDir temp("nonfinite");
  const fs::path& dir = temp.path;
  write_text(dir / "inf.stl",
             "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1e999 0 0\nvertex 0 1 0\nendloop\n"
             "endfacet\nendsolid t\n");
  const std::string path = (dir / "inf.stl").string();
  try {
    load_mesh_points(path);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(path));
  }
}

}  // namespace
}  // namespace batchcol

// Ray scene files: a batch file with "objects" (shape index + pose) whose "rays" are cast against those objects.
// The objects and rays are read in file order whatever the order of the top-level keys; each kind of bad input is an
// InputError naming the JSON pointer of the offending field.
namespace batchcol {
namespace {

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
      {R"([{"origin": [0, 0, 0], "direction": [0, 0, 0]}])", "batch.json: /rays/0/direction: the direction must not be zero"},
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
              HasSubstr("batch.json: /rays/1/shape: required field is missing (rays without a shape need \"objects\""));
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
