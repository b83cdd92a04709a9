// `batchcol query --derivatives`: the derivative columns, and bad derivative options as exit code 2.
#include "tools/cli_runner.hpp"

#include <sstream>
#include <utility>
#include <vector>

namespace batchcol::testing {
namespace {

// Two spheres of radius 0.1 on the x axis, 0.5 apart: the distance gradient w.r.t. b is (1, 0, 0, 0, 0, 0).
constexpr const char* kSpheres = R"({"shapes": [{"type": "sphere", "radius": 0.1}],
  "pairs": [{"a": 0, "b": 0, "pose_b": {"translation": [0.5, 0, 0]}}], "query": "witness"})";

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  for (std::string f; std::getline(in, f, ',');) fields.push_back(f);
  return fields;
}

using DerivativesCli = CliTest;

/// The header's column names and the first row's values of CSV output.
std::pair<std::vector<std::string>, std::vector<std::string>> first_row(const std::string& csv) {
  std::stringstream lines(csv);
  std::string header, row;
  std::getline(lines, header);
  std::getline(lines, row);
  return {split(header), split(row)};
}

TEST_F(DerivativesCli, AnalyticAddsTheDerivativeColumns) {
  const RunResult r = run("query " + file("b.json", kSpheres) + " --derivatives analytic");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto [names, values] = first_row(r.out);
  ASSERT_EQ(names.size(), 14u + 1 + 12 + 6 * 18);  // the results, d_status, 2 gradients, 6 Jacobians
  ASSERT_EQ(values.size(), names.size());
  EXPECT_EQ(names[14], "d_status");
  EXPECT_EQ(values[14], "smooth");
  EXPECT_EQ(names[21], "g_b0");
  EXPECT_EQ(values[21], "1");
  EXPECT_EQ(values[15], "-1");  // g_a0
}

TEST_F(DerivativesCli, GradientsOnlyStopAfterTheGradientColumns) {
  const RunResult r = run("query " + file("b.json", kSpheres) + " --derivatives analytic --gradients-only");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto [names, values] = first_row(r.out);
  ASSERT_EQ(names.size(), 14u + 1 + 12);  // the results, d_status, 2 gradients
  ASSERT_EQ(values.size(), names.size());
  EXPECT_EQ(values[14], "smooth");
  EXPECT_EQ(values[21], "1");   // g_b0
  EXPECT_EQ(values[15], "-1");  // g_a0
  for (const std::string flags : {"--derivatives smoothed1 --gradients-only", "--gradients-only"}) {
    const RunResult bad = run("query " + file("b.json", kSpheres) + " " + flags);
    EXPECT_EQ(bad.exit_code, 2) << flags;
    EXPECT_NE(bad.err.find(flags == "--gradients-only" ? "--gradients-only" : "jacobians"), std::string::npos)
        << flags << ": " << bad.err;
    EXPECT_TRUE(bad.out.empty()) << flags;
  }
}

TEST_F(DerivativesCli, SmoothedZeroAddsTheSmoothedValuesToJson) {
  const fs::path out = dir_ / "d.json";
  const RunResult r = run("query " + file("b.json", kSpheres) +
                          " --derivatives smoothed0 --samples 8 --noise 0.01 --seed 3 --out '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string json = read_text(out);
  EXPECT_NE(json.find("\"d_status\":\"smooth\""), std::string::npos);
  EXPECT_NE(json.find("\"s_distance\":"), std::string::npos);
}

TEST_F(DerivativesCli, BadDerivativeOptionsExitWithTwo) {
  const std::string batch = file("b.json", kSpheres);
  for (const auto& [flags, message] : std::vector<std::pair<std::string, std::string>>{
           {"--derivatives smoothed1 --samples 0", "samples"},
           {"--derivatives smoothed0 --noise 0", "noise"},
           {"--derivatives smoothed0 --noise -1", "noise"},
           {"--derivatives fancy", "--derivatives"},
           {"--derivatives analytic --query distance", "level"}}) {
    const RunResult r = run("query " + batch + " " + flags);
    EXPECT_EQ(r.exit_code, 2) << flags;
    EXPECT_NE(r.err.find(message), std::string::npos) << flags << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << flags;
  }
}

TEST_F(DerivativesCli, BenchTimesDerivatives) {
  RunResult r = run("bench --case sphere-ellipsoid --pairs 50 --runs 5 --min-run-ms 0 --no-peers --json "
                    "--derivatives smoothed1 --samples 4");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"derivatives\""), std::string::npos);
  EXPECT_NE(r.out.find("\"smoothed1\""), std::string::npos);
  r = run("bench --case sphere-ellipsoid --pairs 50 --no-peers --derivatives smoothed0 --samples 0");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("samples"), std::string::npos) << r.err;
  r = run("bench --case sphere-ellipsoid --pairs 50 --no-peers --derivatives analytic --query boolean");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--query"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace batchcol::testing
