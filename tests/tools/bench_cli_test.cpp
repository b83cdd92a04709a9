// Runs `batchcol bench` (the built binary): JSON output and its fields, the close regime's reference distances
// (re-checked through the public API on the pairs the bench saves), and the exit codes of refused flags.
#include "batchcol/batchcol.hpp"

#include <gtest/gtest.h>

#include "tools/cli_runner.hpp"
#include <nlohmann/json.hpp>

#include <cmath>
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

using batchcol::testing::read_text;
using batchcol::testing::RunResult;

class BenchCli : public batchcol::testing::CliTest {};

bool cpu_runs(const char* isa) {
  try {
    batchcol::resolve_instruction_set(batchcol::parse_instruction_set(isa));
    return true;
  } catch (const batchcol::InputError&) {
    return false;
  }
}

TEST_F(BenchCli, JsonHasTheDocumentedFields) {
  const RunResult r = run("bench --case sphere-sphere --regime close --pairs 2000 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);  // throws (fails the test) on invalid JSON
  ASSERT_TRUE(j.is_object()) << r.out;
  for (const char* key : {"case", "regime", "query", "precision", "solver", "threads", "pairs", "kernel",
                          "pairs_per_second", "ns_per_pair", "error_median", "error_max", "peers"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["case"], "sphere-sphere");
  EXPECT_EQ(j["regime"], "close");
  EXPECT_EQ(j["kernel"], "closed form");  // sphere-sphere is analytic
  EXPECT_EQ(j["isa"], batchcol::to_string(batchcol::resolve_instruction_set()));
  EXPECT_EQ(j["pairs"], 2000);
  EXPECT_GT(j["pairs_per_second"].get<double>(), 0.0);
  EXPECT_GT(j["ns_per_pair"].get<double>(), 0.0);
  EXPECT_LE(j["error_max"].get<double>(), 1e-6);
  ASSERT_TRUE(j["peers"].is_array());
  for (const auto& peer : j["peers"]) {
    for (const char* key : {"name", "ns_per_pair", "error_max", "ratio"}) EXPECT_TRUE(peer.contains(key)) << key;
  }
}

// Each timed run makes as many calls as lasted --min-run-ms during calibration: 2000 sphere pairs take
// microseconds, so a 50 ms run needs many calls; 0 times single calls. Peers are timed the same way.
TEST_F(BenchCli, TimedRunsRepeatCheapCallsUntilTheMinimumRunTime) {
  const RunResult longer = run("bench --case sphere-sphere --query boolean --pairs 2000 --runs 5 --min-run-ms 50 --json");
  ASSERT_EQ(longer.exit_code, 0) << longer.err;
  const nlohmann::json j = nlohmann::json::parse(longer.out);
  EXPECT_EQ(j["min_run_ms"], 50.0);
  EXPECT_GT(j["calls_per_run"].get<int>(), 1);
  // The timed runs last about the minimum: at least a quarter of it (ctest runs tests two at a time, so the
  // calibration and the timed runs may see different loads).
  const double run_ms = j["calls_per_run"].get<int>() * j["ns_per_pair"].get<double>() * 2000 * 1e-6;
  EXPECT_GE(run_ms, 12.5);
  for (const auto& peer : j["peers"]) EXPECT_GT(peer["calls_per_run"].get<int>(), 1) << peer["name"];

  const RunResult single = run("bench --case sphere-sphere --query boolean --pairs 2000 --runs 5 --min-run-ms 0 --json");
  ASSERT_EQ(single.exit_code, 0) << single.err;
  const nlohmann::json k = nlohmann::json::parse(single.out);
  EXPECT_EQ(k["calls_per_run"], 1);
  for (const auto& peer : k["peers"]) EXPECT_EQ(peer["calls_per_run"], 1) << peer["name"];
}

// Coal is optional: when the build found it, the bench times it four ways on the same pairs (coal::collide or
// coal::distance, GJK called directly, plain and Nesterov) and every row answers every pair like the reference
// (close pairs, 1e-4..1e-2 m apart: no boolean disagreement, distances within 1e-6 m at Coal tolerance 1e-8);
// otherwise no Coal row appears and the output says how to enable it.
TEST_F(BenchCli, CoalRowsAnswerEveryPairWhenCoalWasFound) {
  for (const std::string query : {"boolean", "witness"}) {
    const RunResult r = run("bench --case cylinder-convex8 --regime close --query " + query +
                            " --pairs 300 --runs 5 --min-run-ms 0 --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    bool coal_missing = false;
    for (const auto& note : j["peers_missing"]) coal_missing |= note.get<std::string>().rfind("Coal not found", 0) == 0;
    std::vector<std::string> coal_rows;
    for (const auto& peer : j["peers"]) {
      const std::string name = peer["name"];
      if (name.rfind("Coal", 0) != 0) continue;
      coal_rows.push_back(name);
      EXPECT_EQ(peer["pairs_answered"], 300) << name;
      if (query == "boolean") EXPECT_EQ(peer["collide_disagreements"], 0) << name;
      else EXPECT_LE(peer["error_max"].get<double>(), 1e-6) << name;
      EXPECT_GT(peer["ns_per_pair"].get<double>(), 0.0) << name;
    }
    if (coal_missing) {
      EXPECT_TRUE(coal_rows.empty());
      continue;
    }
    const std::vector<std::string> expected = {query == "boolean" ? "Coal collide" : "Coal distance",
                                               "Coal GJK direct", "Coal Nesterov direct"};
    EXPECT_EQ(coal_rows, expected) << query;
  }
}

TEST_F(BenchCli, TextOutputNamesTheKernelAndInstructionSet) {
  const RunResult r = run("bench --case box-cone --regime overlap --query penetration --pairs 200 --no-peers --isa scalar");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("instruction set: scalar"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("box-cone               gjk"), std::string::npos) << r.out;
}

// The close regime puts every pair at a reference distance in [1e-4, 1e-2] m; checked here independently of the
// bench's own numbers, on the batch file it saves, with closed forms on (the bench's reference has them off).
TEST_F(BenchCli, ClosePairsHaveReferenceDistancesInRange) {
  for (const std::string c : {"sphere-sphere", "box-convex8", "cylinder-ellipsoid"}) {
    const fs::path saved = dir_ / (c + ".json");
    const RunResult r = run("bench --case " + c + " --regime close --pairs 300 --no-peers --json --save-pairs '" +
                            saved.string() + "'");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const batchcol::BatchFile batch = batchcol::load_batch_file(saved.string());
    ASSERT_EQ(batch.pairs.size(), 300u);
    batchcol::QueryOptions o;
    o.level = batchcol::QueryLevel::penetration;
    o.solver = batchcol::Solver::gjk;
    o.tolerance = 1e-12;
    o.max_iterations = 1000;
    batchcol::PairResults res;
    batchcol::collide(batch.shapes, batch.pairs, o, res);
    for (std::size_t i = 0; i < res.size(); ++i) {
      EXPECT_GE(res.distance[i], 1e-4 * (1 - 1e-6)) << c << " pair " << i;
      EXPECT_LE(res.distance[i], 1e-2 * (1 + 1e-6)) << c << " pair " << i;
    }
  }
}

// Every set this CPU runs gives the same errors (the kernels are bitwise equal); a set it lacks exits 2.
TEST_F(BenchCli, EveryInstructionSetThisCpuRunsAgreesAndOthersExitWith2) {
  std::string first_error;
  for (const char* isa : {"scalar", "avx2", "avx512"}) {
    const RunResult r = run(std::string("bench --case ellipsoid-convex8 --pairs 300 --no-peers --json --isa ") + isa);
    if (!cpu_runs(isa)) {
      EXPECT_EQ(r.exit_code, 2) << isa;
      EXPECT_NE(r.err.find("not supported by this CPU"), std::string::npos) << r.err;
      EXPECT_TRUE(r.out.empty()) << r.out;
      continue;
    }
    ASSERT_EQ(r.exit_code, 0) << isa << ": " << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["isa"], isa);
    EXPECT_EQ(j["kernel"], "gjk");
    const std::string errors = j["error_median"].dump() + " " + j["error_max"].dump();
    if (first_error.empty()) first_error = errors;
    EXPECT_EQ(errors, first_error) << isa;
  }
}

TEST_F(BenchCli, BadFlagsExitWith2) {
  for (const char* args : {"bench --case sphere-torus", "bench --case sphere", "bench --regime near",
                           "bench --pairs 0", "bench --query everything", "bench --isa sse9",
                           "bench --min-run-ms -1", "bench --min-run-ms nan"}) {
    const RunResult r = run(args);
    EXPECT_EQ(r.exit_code, 2) << args;
    EXPECT_EQ(r.err.rfind("batchcol: error: ", 0), 0u) << args << ": " << r.err;
  }
}

}  // namespace
