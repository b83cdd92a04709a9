// `batchcol rays`: JSON report fields in scene and shape modes, hits written with --out (one row per ray, or per hit
// for --query all) and identical for 1 and 2 threads, the Embree comparison under --peers (or a clean refusal when
// Embree was not built in), and exit code 2 with a message naming the flag for bad input.
#include "tools/cli_runner.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <string>

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
