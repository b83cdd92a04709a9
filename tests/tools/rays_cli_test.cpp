// `batchcol rays`: JSON report fields in scene and shape modes, hits written with --out (one row per ray, or per hit
// for --query all) and identical for 1 and 2 threads, the Embree comparison under --peers (or a clean refusal when
// Embree was not built in), and exit code 2 with a message naming the flag for bad input.
#include "tools/cli_runner.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace batchcol::testing {
namespace {

using nlohmann::json;

class RaysCli : public CliTest {
 protected:
  json run_json(const std::string& args) {
    const RunResult r = run("rays " + args + " --json");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return json::parse(r.out);
  }
};

constexpr const char* kSmall = "--objects 300 --rays 3000 --runs 1 --frames 2 --seed 3";

TEST_F(RaysCli, SceneReportHasTheRequiredFields) {
  for (const char* shapes : {"hull", "mixed"}) {
    SCOPED_TRACE(shapes);
    const json j = run_json(std::string(kSmall) + " --threads 2 --hull-vertices 40 --shapes " + shapes);
    EXPECT_EQ(j["objects"], 300);
    EXPECT_EQ(j["rays"], 3000);
    EXPECT_EQ(j["query"], "closest");
    // --fill 1.2 (default): a ray crossing the scene meets 1.2 objects on average, 1 - e^-1.2 = 0.70 hit something
    // (less for the mixed shapes, which fill less of their 0.5 m radius).
    EXPECT_GT(j["hit_fraction"].get<double>(), 0.3);
    EXPECT_LT(j["hit_fraction"].get<double>(), 0.9);
    for (const char* key : {"build_ms", "refit_ms", "cast_ms", "rays_per_s"})
      EXPECT_GT(j["batchcol"][key].get<double>(), 0.0) << key;
  }
}

TEST_F(RaysCli, OutWritesOneRowPerRayAndTheSameForAnyThreadCount) {
  const std::string a = (dir_ / "a.csv").string(), b = (dir_ / "b.csv").string();
  run_json(std::string(kSmall) + " --threads 1 --out '" + a + "'");
  run_json(std::string(kSmall) + " --threads 2 --out '" + b + "'");
  const std::string text = read_text(a);
  EXPECT_EQ(text, read_text(b));
  EXPECT_EQ(text.rfind("ray,status,hit,t,object_slot,object_generation,n_x,n_y,n_z\n", 0), 0u);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 3001);
  EXPECT_NE(text.find("\n0,ok,"), std::string::npos);
}

// --isa picks the traversal's and lane kernels' instruction set, reported as "isa"; every set this CPU runs writes
// the same hits, for closest (the Morton-ordered cast on this scene) and all (input order).
TEST_F(RaysCli, EveryInstructionSetWritesTheSameHits) {
  const bool has[3] = {true, __builtin_cpu_supports("avx2") != 0,
                       __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                           __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw")};
  const char* names[3] = {"scalar", "avx2", "avx512"};
  for (const char* query : {"closest", "all"}) {
    std::string reference;
    for (int isa = 0; isa < 3; ++isa) {
      if (!has[isa]) continue;
      SCOPED_TRACE(std::string(query) + " " + names[isa]);
      const std::string path = (dir_ / (std::string(names[isa]) + ".csv")).string();
      const json j = run_json("--objects 4000 --hull-vertices 40 --rays 6000 --runs 1 --frames 1 --seed 5 --query " +
                              std::string(query) + " --isa " + names[isa] + " --out '" + path + "'");
      EXPECT_EQ(j["isa"], names[isa]);
      const std::string text = read_text(path);
      if (isa == 0) {
        reference = text;
      } else {
        EXPECT_TRUE(text == reference);  // not EXPECT_EQ: a 6000-row diff would flood the log
      }
    }
    // Rays do hit: closest writes a row per ray, all a row per hit (~0.7 of 6000 rays hit something).
    EXPECT_GT(std::count(reference.begin(), reference.end(), '\n'), 3000);
    if (query == std::string("closest")) {
      EXPECT_NE(reference.find(",ok,1,"), std::string::npos);
    }
  }
  const json shape = run_json("--mode shape --rays 2000 --runs 1 --isa scalar");
  EXPECT_EQ(shape["isa"], "scalar");
}

TEST_F(RaysCli, AllQueryWritesOneRowPerHit) {
  const std::string path = (dir_ / "all.csv").string();
  const json j = run_json(std::string(kSmall) + " --query all --out '" + path + "'");
  const std::string text = read_text(path);
  EXPECT_EQ(text.rfind("ray,t,object_slot,object_generation,n_x,n_y,n_z\n", 0), 0u);
  const auto rows = std::count(text.begin(), text.end(), '\n') - 1;
  EXPECT_EQ(rows, j["all_hit_rows"].get<long>());
  // Every ray that hits has at least one row, and some rays cross several objects.
  EXPECT_GE(rows, static_cast<long>(j["hit_fraction"].get<double>() * 3000));
}

TEST_F(RaysCli, PeersCompareWithEmbreeOrRefuseCleanly) {
  const RunResult r = run(std::string("rays ") + kSmall + " --threads 2 --hull-vertices 40 --peers --json");
  if (r.exit_code == 2) {  // built without Embree
    EXPECT_NE(r.err.find("--peers needs Embree"), std::string::npos) << r.err;
    return;
  }
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json j = json::parse(r.out);
  const json& e = j["embree"];
  EXPECT_EQ(e["triangles"].get<long>() > 300 * 40, true);
  const long hits = static_cast<long>(std::lround(j["hit_fraction"].get<double>() * 3000));
  EXPECT_EQ(e["same_hit_or_miss"], 3000);
  EXPECT_EQ(e["same_object"].get<long>(), hits);
  EXPECT_GE(e["t_within_1e-6_relative"].get<long>(), hits - hits / 100);
  EXPECT_GT(e["build_ms"].get<double>(), 0.0);
}

TEST_F(RaysCli, ShapeModeReportsEveryShapeAndPrecision) {
  const json j = run_json("--mode shape --rays 5000 --runs 1 --hull-vertices 60");
  for (const char* shape : {"sphere", "box", "capsule", "hull"})
    for (const char* precision : {"double", "float"}) {
      SCOPED_TRACE(std::string(shape) + " " + precision);
      EXPECT_GT(j[shape][precision]["rays_per_s"].get<double>(), 0.0);
      EXPECT_GT(j[shape][precision]["hit_fraction"].get<double>(), 0.1);
    }
}

TEST_F(RaysCli, BadFlagsExitWithCode2AndAClearMessage) {
  const struct {
    const char* args;
    const char* message;
  } cases[] = {
      {"--objects 0", "--objects must be in [1, 2^31)"},
      {"--rays -1", "--rays must be in [1, 2^31)"},
      {"--query nearest", "--query nearest: unknown (valid: closest, any, all)"},
      {"--shapes blobs", "--shapes blobs: unknown"},
      {"--mode cone", "--mode cone: unknown"},
      {"--threads -2", "--threads must be >= 0"},
      {"--fill nan", "--fill must be a finite number > 0"},
      {"--hull-vertices 3", "--hull-vertices must be >= 4"},
      {"--rays ten", "--rays"},
      {"--mode shape --rays 10 --out x.csv", "--out is only available with --mode scene"},
      {"--isa sse9", "--isa sse9: unknown instruction set (valid: auto, scalar, avx2, avx512)"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    const RunResult r = run(std::string("rays ") + c.args);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(r.err.rfind("batchcol: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace batchcol::testing

namespace batchcol::testing {
namespace {

// Rays given in a batch file ("rays": shape, pose, origin, direction, t_max) are cast against their posed shapes.
TEST_F(RaysCli, BatchFileRaysAreCastAndWritten) {
  const std::string path = file("rays.json", R"({
    "shapes": [{"type": "sphere", "radius": 1.0}, {"type": "box", "half_extents": [1, 2, 3]}],
    "rays": [
      {"shape": 0, "pose": {"translation": [10, 0, 0]}, "origin": [0, 0, 0], "direction": [2, 0, 0]},
      {"shape": 1, "origin": [0, 0, 10], "direction": [0, 0, -1], "t_max": 5},
      {"shape": 1, "origin": [0, 0, 10], "direction": [0, 0, -1], "t_max": 8}
    ]})");
  const std::string out = (dir_ / "hits.csv").string();
  const json j = run_json("--batch " + path + " --out '" + out + "'");
  EXPECT_EQ(j["rays"], 3);
  EXPECT_EQ(j["hits"], 2);
  EXPECT_EQ(read_text(out), "ray,status,hit,t,object_slot,object_generation,n_x,n_y,n_z\n"
                            "0,ok,1,4.5,,,-1,0,0\n"
                            "1,ok,0,,,,,,\n"  // no hit: the six value columns are empty
                            "2,ok,1,7,,,0,0,1\n");
}

TEST_F(RaysCli, BadRaysInABatchFileExitWithCode2NamingTheRay) {
  const struct {
    const char* ray;
    const char* message;
  } cases[] = {
      {R"({"shape": 0, "origin": [0, 0, 0], "direction": [0, 0, 0]})", "/rays/0/direction: the direction must not be zero"},
      {R"({"shape": 0, "origin": [0, 0, 0], "direction": [1, 0, 0], "t_max": -1})", "/rays/0/t_max"},
      {R"({"shape": 3, "origin": [0, 0, 0], "direction": [1, 0, 0]})", "/rays/0/shape"},
      {R"({"shape": 0, "origin": [0, 0], "direction": [1, 0, 0]})", "/rays/0/origin"},
      {R"({"shape": 0, "origin": [0, 0, 0], "direction": [1, 0, 0], "colour": 1})", "unknown key 'colour'"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.ray);
    const std::string path =
        file("bad.json", std::string(R"({"shapes": [{"type": "sphere", "radius": 1.0}], "rays": [)") + c.ray + "]}");
    const RunResult r = run("rays --batch " + path);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace batchcol::testing

namespace batchcol::testing {
namespace {

// Rows of a CSV text (header included), split at commas.
std::vector<std::vector<std::string>> csv_rows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    rows.emplace_back();
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) rows.back().push_back(cell);
    if (!line.empty() && line.back() == ',') rows.back().push_back("");
  }
  return rows;
}

// Four objects whose hits have closed forms: a unit sphere at (5, 0, 0); a box of half extents (1, 2, 3) at
// (0, 0, 10) turned 90 degrees about z (world half extents (2, 1, 3): top face z = 13); a cube of half side 1 as a
// convex hull at (0, 10, 0), turned about z by a rotation matrix (faces y = 9 and y = 11); a sphere of radius 0.5 at
// (0, 0, -5).
constexpr const char* kSceneFile = R"({
  "shapes": [{"type": "sphere", "radius": 1}, {"type": "box", "half_extents": [1, 2, 3]},
             {"type": "convex", "vertices": [[-1, -1, -1], [1, -1, -1], [-1, 1, -1], [1, 1, -1],
                                             [-1, -1, 1], [1, -1, 1], [-1, 1, 1], [1, 1, 1]]},
             {"type": "sphere", "radius": 0.5}],
  "objects": [
    {"shape": 0, "pose": {"translation": [5, 0, 0]}},
    {"shape": 1, "pose": {"translation": [0, 0, 10], "quaternion": [0.7071067811865476, 0, 0, 0.7071067811865476]}},
    {"shape": 2, "pose": {"translation": [0, 10, 0], "rotation": [[0, -1, 0], [1, 0, 0], [0, 0, 1]]}},
    {"shape": 3, "pose": {"translation": [0, 0, -5]}}
  ],
  "rays": [
    {"origin": [0, 0, 0], "direction": [2, 0, 0]},
    {"origin": [0, 0, 20], "direction": [0, 0, -1], "t_max": 5},
    {"origin": [0, 0, 20], "direction": [0, 0, -1], "t_max": 8},
    {"origin": [5, 0, 0], "direction": [0, 3, 0]},
    {"origin": [0, 20, 0], "direction": [0, -1, 0]},
    {"origin": [0, 0, 20], "direction": [0, 0, -1]}
  ]})";

struct ExpectedHit {
  int ray;
  double t;
  int object;
  double n[3];
};

// Closed forms (t in units of |direction|): ray 0 meets the sphere's x = 4 at t = 4 / 2; ray 1 stops (t_max 5)
// before the box top (t = 20 - 13 = 7), ray 2 reaches it; ray 3 starts inside the sphere (t = 0, normal -d/|d|);
// ray 4 meets the cube's face y = 11 at t = 9; ray 5 the box top at t = 7 and then (query all) the small sphere's
// top z = -4.5 at t = 24.5.
const ExpectedHit kClosest[] = {{0, 2.0, 0, {-1, 0, 0}}, {2, 7.0, 1, {0, 0, 1}}, {3, 0.0, 0, {0, -1, 0}},
                                {4, 9.0, 2, {0, 1, 0}}, {5, 7.0, 1, {0, 0, 1}}};
const ExpectedHit kAll[] = {{0, 2.0, 0, {-1, 0, 0}}, {2, 7.0, 1, {0, 0, 1}}, {3, 0.0, 0, {0, -1, 0}},
                            {4, 9.0, 2, {0, 1, 0}}, {5, 7.0, 1, {0, 0, 1}}, {5, 24.5, 3, {0, 0, 1}}};

TEST_F(RaysCli, SceneFileClosestHitsMatchTheClosedForms) {
  const std::string path = file("scene.json", kSceneFile), out = (dir_ / "hits.csv").string();
  const json j = run_json("--scene " + path + " --runs 1 --frames 2 --threads 2 --out '" + out + "'");
  EXPECT_EQ(j["objects"], 4);
  EXPECT_EQ(j["rays"], 6);
  EXPECT_EQ(j["shapes"], "file");
  EXPECT_EQ("'" + j["scene_file"].get<std::string>() + "'", path);  // file() quotes the path for the shell
  EXPECT_DOUBLE_EQ(j["hit_fraction"].get<double>(), 5.0 / 6.0);
  const auto rows = csv_rows(read_text(out));
  ASSERT_EQ(rows.size(), 7u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"ray", "status", "hit", "t", "object_slot", "object_generation", "n_x",
                                               "n_y", "n_z"}));
  EXPECT_EQ(rows[2], (std::vector<std::string>{"1", "ok", "0", "", "", "", "", "", ""}));  // stopped by t_max
  for (const ExpectedHit& e : kClosest) {
    SCOPED_TRACE(e.ray);
    const auto& row = rows[static_cast<std::size_t>(e.ray) + 1];
    ASSERT_EQ(row.size(), 9u);
    EXPECT_EQ(row[0], std::to_string(e.ray));
    EXPECT_EQ(row[1], "ok");
    EXPECT_EQ(row[2], "1");
    EXPECT_NEAR(std::stod(row[3]), e.t, 1e-12);
    EXPECT_EQ(row[4], std::to_string(e.object));  // object k of the file is slot k
    EXPECT_EQ(row[5], "0");
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(std::stod(row[6 + static_cast<std::size_t>(k)]), e.n[k], 1e-12);
  }
  // The refit frames moved the objects; the cast is still against the file's poses, and any thread count gives
  // the same bytes.
  const std::string one = (dir_ / "one.csv").string();
  run_json("--scene " + path + " --runs 1 --frames 1 --threads 1 --out '" + one + "'");
  EXPECT_EQ(read_text(one), read_text(out));
}

TEST_F(RaysCli, SceneFileAllQueryListsEveryObjectCrossed) {
  const std::string path = file("scene.json", kSceneFile), out = (dir_ / "all.csv").string();
  const json j = run_json("--scene " + path + " --runs 1 --query all --out '" + out + "'");
  EXPECT_EQ(j["all_hit_rows"], 6);
  const auto rows = csv_rows(read_text(out));
  ASSERT_EQ(rows.size(), 7u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"ray", "t", "object_slot", "object_generation", "n_x", "n_y", "n_z"}));
  for (std::size_t k = 0; k < 6; ++k) {
    const ExpectedHit& e = kAll[k];
    SCOPED_TRACE(k);
    EXPECT_EQ(rows[k + 1][0], std::to_string(e.ray));
    EXPECT_NEAR(std::stod(rows[k + 1][1]), e.t, 1e-12);
    EXPECT_EQ(rows[k + 1][2], std::to_string(e.object));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(std::stod(rows[k + 1][4 + static_cast<std::size_t>(c)]), e.n[c], 1e-12);
  }
}

TEST_F(RaysCli, SceneFileAnyQueryFindsEveryHittingRay) {
  const std::string path = file("scene.json", kSceneFile), out = (dir_ / "any.csv").string();
  run_json("--scene " + path + " --runs 1 --query any --out '" + out + "'");
  const auto rows = csv_rows(read_text(out));
  ASSERT_EQ(rows.size(), 7u);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(rows[i + 1][2], i == 1 ? "0" : "1") << i;
}

TEST_F(RaysCli, SceneFilePeersCompareWithEmbree) {
  const std::string path = file("scene.json", kSceneFile);
  const RunResult r = run("rays --scene " + path + " --runs 1 --peers --json");
  if (r.exit_code == 2) {  // built without Embree
    EXPECT_NE(r.err.find("--peers needs Embree"), std::string::npos) << r.err;
    return;
  }
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json e = json::parse(r.out)["embree"];
  EXPECT_EQ(e["same_hit_or_miss"], 6);
  EXPECT_EQ(e["same_object"], 5);
  // Ray 3 starts inside the sphere: Embree reports the exit point, not t = 0; the flat faces agree to 1e-6.
  EXPECT_GE(e["t_within_1e-6_relative"].get<int>(), 3);
}

TEST_F(RaysCli, BadSceneFilesExitWithCode2NamingTheFieldAndWriteNothing) {
  const std::string shapes = R"("shapes": [{"type": "sphere", "radius": 1}])";
  const std::string ray = R"({"origin": [0, 0, 0], "direction": [1, 0, 0]})";
  const struct {
    std::string text;
    const char* message;
  } cases[] = {
      {"{" + shapes + R"(, "objects": [{"shape": 0}], "rays": [{"origin": [0, 0, 0], "direction": [0, 0, 0]}]})",
       "/rays/0/direction: the direction must not be zero"},
      {"{" + shapes + R"(, "objects": [{"shape": 0}], "rays": [)" + ray +
           R"(, {"origin": [0, 0, 0], "direction": [1, 0, 0], "t_max": -2}]})",
       "/rays/1/t_max: must be >= 0"},
      {"{" + shapes + R"(, "objects": [{"shape": 0}], "rays": [{"origin": [0, 0, 0], "direction": [1, 0, 0], "shape": 0}]})",
       "/rays/0/shape: the rays of a file with \"objects\" are cast against the objects"},
      {"{" + shapes + R"(, "objects": [{"shape": 1}], "rays": [)" + ray + "]}", "/objects/0/shape: shape index 1 is out of range"},
      {"{" + shapes + R"(, "objects": [{"shape": 0, "pose": {"quaternion": [2, 0, 0, 0]}}], "rays": [)" + ray + "]}",
       "/objects/0/pose/quaternion"},
      {"{" + shapes + R"(, "objects": [{"shape": 0}], "rays": [)" + ray + "], \"lights\": 1}", "/lights: unknown key 'lights'"},
      {"{" + shapes + R"(, "objects": [{"shape": 0}], "rays": [)" + ray, "line 1, column"},  // truncated JSON
      {"{" + shapes + R"(, "rays": [{"shape": 0, "origin": [0, 0, 0], "direction": [1, 0, 0]}]})",
       "the file has no \"objects\""},
      {"{" + shapes + R"(, "objects": [{"shape": 0}]})", "the file has no \"rays\""},
      {"{" + shapes + R"(, "objects": [{"shape": 0}], "rays": []})", "the file has no \"rays\""},
  };
  const std::string out = (dir_ / "hits.csv").string();
  for (const auto& c : cases) {
    SCOPED_TRACE(c.text);
    write_text(dir_ / "bad.json", c.text);
    write_text(out, "old\n");  // an earlier result must survive a failed run untouched
    const RunResult r = run("rays --scene '" + (dir_ / "bad.json").string() + "' --runs 1 --out '" + out + "'");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(r.err.rfind("batchcol: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_EQ(read_text(out), "old\n");
  }
}

TEST_F(RaysCli, SceneFlagRefusesGeneratorFlagsAndOtherModes) {
  const std::string path = file("scene.json", kSceneFile);
  const struct {
    std::string args;
    const char* message;
  } cases[] = {
      {"--scene " + path + " --objects 10", "--objects"},
      {"--scene " + path + " --rays 10", "--rays"},
      {"--scene " + path + " --shapes mixed", "--shapes"},
      {"--scene " + path + " --batch " + path, "--batch"},
      {"--scene " + path + " --mode shape", "--scene casts against a scene: it cannot be used with --mode shape"},
      {"--batch " + path, "the file has \"objects\", so its rays are scene rays: cast them with --scene"},
      {"--scene " + (dir_ / "missing.json").string(), "missing.json: no such file"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    const RunResult r = run("rays " + c.args);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.out, "");
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace batchcol::testing
