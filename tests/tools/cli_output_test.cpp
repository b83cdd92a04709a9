// `--out` under hostile file-system conditions (issue #16, item 13): the temporary file is created exclusively with a
// unique name, so neither a symlink or FIFO at the old fixed name `X.tmp` nor a concurrent run can redirect,
// block or mix the output.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tools/cli_runner.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <sys/wait.h>

namespace {

namespace fs = std::filesystem;
using batchcol::testing::read_text;
using batchcol::testing::RunResult;
using batchcol::testing::write_text;

// n pairs of unit spheres 3 m apart: each batch size gives a CSV with its own number of rows.
std::string sphere_batch(int n) {
  std::string pairs;
  for (int i = 0; i < n; ++i) {
    pairs += std::string(i ? "," : "") + R"({"a":0,"b":0,"pose_b":{"translation":[3,0,0]}})";
  }
  return R"({"shapes":[{"type":"sphere","radius":1}],"pairs":[)" + pairs + "]}";
}

class CliOutput : public batchcol::testing::CliTest {
 protected:
  // Files in the test folder whose names end in ".tmp" (a temporary left behind).
  std::vector<std::string> leftover_temporaries() const {
    std::vector<std::string> found;
    for (const auto& entry : fs::directory_iterator(dir_)) {
      const std::string name = entry.path().filename().string();
      if (name.size() > 4 && name.compare(name.size() - 4, 4, ".tmp") == 0) found.push_back(name);
    }
    return found;
  }
};

TEST_F(CliOutput, SymlinkAtTheOldTemporaryNameIsNotFollowed) {
  const fs::path out = dir_ / "results.csv", victim = dir_ / "victim.txt";
  write_text(victim, "precious\n");
  fs::create_symlink(victim, dir_ / "results.csv.tmp");
  const RunResult r = run("query " + file("batch.json", sphere_batch(2)) + " --out '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(read_text(victim), "precious\n");
  const std::string written = read_text(out);
  EXPECT_EQ(std::count(written.begin(), written.end(), '\n'), 3) << written;
}

TEST_F(CliOutput, FifoAtTheOldTemporaryNameDoesNotBlock) {
#ifdef BATCHCOL_CLI_PATH
  const fs::path out = dir_ / "results.csv";
  ASSERT_EQ(::mkfifo((dir_ / "results.csv.tmp").c_str(), 0600), 0);
  const std::string batch = file("batch.json", sphere_batch(1));
  // `timeout` turns the hang of the old fixed-name temporary into exit status 124 instead of a stuck test.
  const std::string command = "timeout 60 '" + std::string(BATCHCOL_CLI_PATH) + "' query " + batch + " --out '" +
                              out.string() + "' >/dev/null 2>&1";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  const std::string written = read_text(out);
  EXPECT_EQ(std::count(written.begin(), written.end(), '\n'), 2) << written;
#endif
}

TEST_F(CliOutput, ConcurrentRunsWithTheSameOutLeaveOneCompleteResult) {
#ifdef BATCHCOL_CLI_PATH
  const fs::path out = dir_ / "results.csv";
  // Four runs of different sizes at once: the file must end as exactly one run's full output, never a mix.
  const std::vector<int> sizes = {2000, 3000, 4000, 5000};
  std::vector<std::string> expected;
  std::string command = "(";
  for (int n : sizes) {
    const std::string batch = file("batch" + std::to_string(n) + ".json", sphere_batch(n));
    const fs::path alone = dir_ / ("alone" + std::to_string(n) + ".csv");
    ASSERT_EQ(run("query " + batch + " --out '" + alone.string() + "'").exit_code, 0);
    expected.push_back(read_text(alone));
    command += "'" + std::string(BATCHCOL_CLI_PATH) + "' query " + batch + " --out '" + out.string() +
               "' >/dev/null 2>&1 || echo failed >>'" + (dir_ / "failures").string() + "' & ";
  }
  command += "wait)";
  ASSERT_EQ(std::system(command.c_str()), 0);
  EXPECT_FALSE(fs::exists(dir_ / "failures")) << read_text(dir_ / "failures");
  const std::string written = read_text(out);
  EXPECT_THAT(expected, ::testing::Contains(written)) << written.size() << " bytes";
  EXPECT_TRUE(leftover_temporaries().empty()) << leftover_temporaries().front();
#endif
}

TEST_F(CliOutput, FailedRunLeavesNoTemporary) {
  const fs::path out = dir_ / "results.csv";
  const RunResult r = run("query " + file("bad.json", R"({"shapes":[],"pairs":[{"a":0,"b":0}]})") + " --out '" +
                          out.string() + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(fs::exists(out));
  EXPECT_TRUE(leftover_temporaries().empty()) << leftover_temporaries().front();
}

}  // namespace
