// Runs the built `batchcol` binary on temporary files and checks exit codes, stderr messages and output.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tools/cli_runner.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::MatchesRegex;
using ::testing::StartsWith;

constexpr const char* kHeader = "pair,status,collide,distance,pa_x,pa_y,pa_z,pb_x,pb_y,pb_z,n_x,n_y,n_z,iterations";

// Two spheres 1 m apart, two overlapping boxes and a sphere resting in a halfspace.
constexpr const char* kValidBatch = R"({
  "shapes": [
    {"type": "sphere", "radius": 0.5},
    {"type": "box", "half_extents": [0.5, 0.5, 0.5]},
    {"type": "halfspace", "normal": [0, 0, 1], "offset": 0}
  ],
  "pairs": [
    {"a": 0, "b": 0, "pose_b": {"translation": [2, 0, 0]}},
    {"a": 1, "b": 1, "pose_b": {"translation": [0.8, 0, 0], "quaternion": [1, 0, 0, 0]}},
    {"a": 2, "b": 0, "pose_b": {"translation": [0, 0, 0.25]}}
  ]
})";

using batchcol::testing::read_text;
using batchcol::testing::RunResult;
using batchcol::testing::write_text;


std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

class Cli : public batchcol::testing::CliTest {};

void expect_error(const RunResult& r, const std::string& fragment) {
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, StartsWith("batchcol: error: "));
  EXPECT_THAT(r.err, HasSubstr(fragment));
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST_F(Cli, ValidBatchWritesCsvHeaderAndOneRowPerPair) {
  const RunResult r = run("query " + file("batch.json", kValidBatch) + " --query penetration");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  const auto lines = lines_of(r.out);
  ASSERT_EQ(lines.size(), 4u) << r.out;
  EXPECT_EQ(lines[0], kHeader);
  for (int i = 0; i < 3; ++i) {
    EXPECT_THAT(lines[1 + i], StartsWith(std::to_string(i) + ",")) << lines[1 + i];
    EXPECT_EQ(std::count(lines[1 + i].begin(), lines[1 + i].end(), ','), 13) << lines[1 + i];
  }
  // Spheres of radius 0.5 with centres 2 m apart: separated by exactly 1 m along +x.
  EXPECT_THAT(lines[1], StartsWith("0,converged,0,1,0.5,0,0,1.5,0,0,1,0,0,"));
  // Unit cubes 0.8 apart overlap by 0.2 along +x; the sphere sinks 0.25 into the halfspace z <= 0.
  EXPECT_THAT(lines[2], MatchesRegex("1,converged,1,(-0\\.2|-0\\.1999999999999999[0-9]*),.*,1,0,0,[0-9]+"));
  EXPECT_THAT(lines[3], MatchesRegex("2,converged,1,-0\\.25,.*"));
}

TEST_F(Cli, FlagsOverrideFileSettings) {
  std::string text = kValidBatch;
  text.insert(text.rfind('}'), R"(, "query": "penetration")");
  const RunResult r = run("query " + file("batch.json", text) + " --query boolean --solver gjk --threads 1");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto lines = lines_of(r.out);
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_THAT(lines[1], StartsWith("0,converged,0,,"));  // boolean: no distance
  EXPECT_THAT(lines[2], StartsWith("1,converged,1,,"));
}

TEST_F(Cli, OutWritesCsvOrJsonByExtension) {
  const std::string batch = file("batch.json", kValidBatch);
  const fs::path csv = dir_ / "results.csv", json = dir_ / "results.json";
  RunResult r = run("query " + batch + " --out '" + csv.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  EXPECT_EQ(lines_of(read_text(csv)).size(), 4u);
  EXPECT_EQ(lines_of(read_text(csv))[0], kHeader);

  r = run("query " + batch + " --out '" + json.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(read_text(json), StartsWith("{\"results\":["));
  EXPECT_THAT(read_text(json), HasSubstr("\"pair\":2,\"status\":\"converged\""));
  EXPECT_FALSE(fs::exists(dir_ / "results.json.tmp"));
}

TEST_F(Cli, UnknownOutputExtensionIsAnError) {
  const fs::path out = dir_ / "results.txt";
  expect_error(run("query " + file("batch.json", kValidBatch) + " --out '" + out.string() + "'"), "results.txt");
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(Cli, MalformedFile) {
  const RunResult r = run("query " + file("bad.json", "{\"shapes\": [\n  {\"type\": \"sphere\",, }\n]}"));
  expect_error(r, "bad.json: line 2");
}

TEST_F(Cli, MissingFile) {
  const std::string path = (dir_ / "absent.json").string();
  expect_error(run("query '" + path + "'"), path + ": no such file");
}

TEST_F(Cli, DirectoryInsteadOfFile) { expect_error(run("query '" + dir_.string() + "'"), "is a directory"); }

TEST_F(Cli, OutOfRangeShapeIndex) {
  expect_error(run("query " + file("bad.json", R"({"shapes":[{"type":"sphere","radius":1}],"pairs":[{"a":0,"b":3}]})")),
               "bad.json: /pairs/0/b: shape index 3 is out of range");
}

TEST_F(Cli, BadInputDoesNotClobberExistingOutput) {
  const fs::path out = dir_ / "results.csv";
  write_text(out, "previous results\n");
  const RunResult r = run("query " + file("bad.json", R"({"shapes":[],"pairs":[{"a":0,"b":0}]})") + " --out '" +
                          out.string() + "'");
  expect_error(r, "/pairs/0/a");
  EXPECT_EQ(read_text(out), "previous results\n");
  EXPECT_FALSE(fs::exists(dir_ / "results.csv.tmp"));
}

TEST_F(Cli, UnwritableOutputIsAnError) {
  const fs::path out = dir_ / "no_such_dir" / "results.csv";
  expect_error(run("query " + file("batch.json", kValidBatch) + " --out '" + out.string() + "'"), "results.csv");
}

TEST_F(Cli, BadFlagValues) {
  const std::string batch = file("batch.json", kValidBatch);
  expect_error(run("query " + batch + " --query fast"), "unknown query level 'fast'");
  expect_error(run("query " + batch + " --solver newton"), "unknown solver 'newton'");
  expect_error(run("query " + batch + " --precision half"), "unknown precision 'half'");
  expect_error(run("query " + batch + " --tolerance -1"), "--tolerance");
  expect_error(run("query " + batch + " --threads x"), "--threads");
  expect_error(run("query " + batch + " --frobnicate"), "frobnicate");
}

TEST_F(Cli, MissingSubcommandOrArgument) {
  EXPECT_EQ(run("").exit_code, 2);
  expect_error(run("query"), "batch");
  expect_error(run("explode"), "explode");
}

TEST_F(Cli, HelpExitsZero) {
  const RunResult r = run("query --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_THAT(r.out, HasSubstr("--solver"));
}

TEST_F(Cli, DemoPrintsThroughput) {
  const RunResult r = run("demo --pairs 2000");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("2000 pairs"));
  EXPECT_THAT(r.out, HasSubstr("pairs/s"));
  // Half of the scene overlaps by construction and the other half is separated.
  EXPECT_THAT(r.out, HasSubstr("colliding: 1000\n"));
}

TEST_F(Cli, DemoRejectsBadPairCount) { expect_error(run("demo --pairs 0"), "--pairs"); }

}  // namespace
