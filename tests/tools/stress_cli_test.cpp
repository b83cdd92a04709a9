// `batchcol stress`: JSON report fields, verification against brute force (whole scene and sub-volume), every
// distribution, thread-count independence, peers on the same boxes, and clean errors for bad flags.
#include "tools/cli_runner.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace batchcol::testing {
namespace {

using nlohmann::json;

class StressCli : public CliTest {
 protected:
  json run_json(const std::string& args) {
    const RunResult r = run("stress " + args + " --json");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err, "") << "no progress bar when stderr is not a terminal";
    return json::parse(r.out);
  }
};

TEST_F(StressCli, JsonReportHasTheRequiredFieldsAndVerifies) {
  const json j = run_json("--objects 3000 --steps 3 --threads 2 --query witness --seed 5");
  for (const char* key : {"objects", "steps", "threads", "broadphase_ms_median", "narrowphase_ms_median",
                          "total_ms_median", "candidate_pairs", "colliding_pairs", "peak_rss_mb", "verified",
                          "aabb_ms_median", "sap_ms_median", "sap_rebuild_ms_median", "sap_update_ms_median",
                          "sap_bytes_per_object"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["objects"], 3000);
  EXPECT_EQ(j["steps"], 3);
  EXPECT_EQ(j["threads"], 2);
  EXPECT_EQ(j["verified"], true);
  EXPECT_EQ(j["verified_scope"], "whole scene");
  EXPECT_EQ(j["verified_objects"], 3000);
  EXPECT_EQ(j["incremental"], true);  // steps after the first update the broad phase
  EXPECT_GT(j["candidate_pairs"].get<double>(), 0);
  EXPECT_LE(j["colliding_pairs"].get<double>(), j["candidate_pairs"].get<double>());
  EXPECT_GT(j["colliding_pairs"].get<double>(), 0);
  // --density is the expected number of AABB overlaps per object (estimated from the objects' own boxes).
  const double overlaps = j["aabb_overlaps_per_object"].get<double>();
  EXPECT_GT(overlaps, 0.25);
  EXPECT_LT(overlaps, 0.6);
  EXPECT_GT(j["peak_rss_mb"].get<double>(), 1.0);
  EXPECT_GE(j["total_ms_median"].get<double>(), j["narrowphase_ms_median"].get<double>());
}

TEST_F(StressCli, EveryDistributionVerifies) {
  for (const char* d : {"uniform", "clustered", "layered"}) {
    SCOPED_TRACE(d);
    const json j = run_json(std::string("--objects 4000 --steps 2 --distribution ") + d + " --density 1.5");
    EXPECT_EQ(j["verified"], true);
    EXPECT_GT(j["candidate_pairs"].get<double>(), 1000);
  }
}

TEST_F(StressCli, LargeScenesVerifyOnASubVolume) {
  const json j = run_json("--objects 30000 --steps 1 --move 0.1");
  EXPECT_EQ(j["verified_scope"], "sub-volume");
  EXPECT_EQ(j["verified"], true);
  EXPECT_GT(j["verified_objects"].get<double>(), 500);
  EXPECT_GT(j["verified_pairs"].get<double>(), 50);
}

TEST_F(StressCli, SamePairsForOneAndTwoThreads) {
  const json one = run_json("--objects 5000 --steps 3 --threads 1 --distribution clustered");
  const json two = run_json("--objects 5000 --steps 3 --threads 2 --distribution clustered");
  EXPECT_EQ(one["candidate_pairs"], two["candidate_pairs"]);
  EXPECT_EQ(one["colliding_pairs"], two["colliding_pairs"]);
}

TEST_F(StressCli, PeersReportTheSamePairsOnTheSameBoxes) {
  const json j = run_json("--objects 2000 --steps 2 --peers");
  ASSERT_TRUE(j.contains("peers"));
  std::size_t peers = 0;
  for (const json& p : j["peers"]) {
    ++peers;
    SCOPED_TRACE(p["name"].get<std::string>());
    EXPECT_GT(p["rebuild_ms"].get<double>(), 0);
    EXPECT_GT(p["update_ms"].get<double>(), 0);
    // FCL reports exact box overlaps (touching included) like ours; Bullet's rebuild too (its fattened boxes only
    // appear after an update).
    EXPECT_EQ(p["rebuild_pairs"], j["candidate_pairs"]);
  }
  EXPECT_EQ(peers + j["peers_missing"].size(), 3u);
}

TEST_F(StressCli, BadFlagsExitWithCode2AndAClearMessage) {
  const struct {
    const char* args;
    const char* message;
  } cases[] = {
      {"--objects 0", "--objects must be >= 1"},
      {"--objects -5", "--objects must be >= 1"},
      {"--density nan", "--density must be a finite number >= 1e-6"},
      {"--density -1", "--density must be a finite number >= 1e-6"},
      {"--density 0", "--density must be a finite number >= 1e-6"},
      {"--density 1e-300", "--density must be a finite number >= 1e-6 (got 1e-300)"},  // was an internal message
      {"--steps 0", "--steps must be >= 1"},
      {"--move -0.1", "--move must be a finite number in [0, 1]"},
      {"--threads -2", "--threads must be between 0 (all cores) and 1024"},
      {"--threads 1025", "--threads must be between 0 (all cores) and 1024"},  // issue #16: 1e7 crashed TBB
      {"--move 1e300", "--move must be a finite number in [0, 1] (got 1e+300)\n"},  // not 301 digits
      {"--distribution spiral", "--distribution spiral: unknown"},
      {"--query penetration", "--query penetration: unknown"},
      {"--objects ten", "--objects"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    const RunResult r = run(std::string("stress ") + c.args);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(r.err.rfind("batchcol: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
  }
}

TEST_F(StressCli, TextReportNamesTheStages) {
  const RunResult r = run("stress --objects 1500 --steps 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* word : {"aabb", "sap", "narrow", "candidates", "colliding", "peak RSS", "verified: yes"})
    EXPECT_NE(r.out.find(word), std::string::npos) << word << "\n" << r.out;
}

}  // namespace
}  // namespace batchcol::testing
