// Runs the built `batchcol` binary on files in a per-test temporary folder: the fixture shared by the CLI tests.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

namespace batchcol::testing {

namespace fs = std::filesystem;

struct RunResult {
  int exit_code = -1;
  std::string out, err;
};

inline std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

inline void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good());
}

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
#ifndef BATCHCOL_CLI_PATH
    GTEST_SKIP() << "the batchcol CLI is not built (BATCHCOL_BUILD_TOOLS=OFF)";
#endif
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / ("batchcol_" + std::string(info->test_suite_name()) + "_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    if (!dir_.empty()) fs::remove_all(dir_, ec);
  }

  // Runs `batchcol <args>` (args are already shell-quoted where needed) capturing stdout and stderr.
  RunResult run(const std::string& args) const {
#ifdef BATCHCOL_CLI_PATH
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string command =
        "'" + std::string(BATCHCOL_CLI_PATH) + "' " + args + " >'" + out.string() + "' 2>'" + err.string() + "'";
    const int status = std::system(command.c_str());
    RunResult result;
    result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    result.out = read_text(out);
    result.err = read_text(err);
    return result;
#else
    (void)args;
    return {};
#endif
  }

  std::string file(const std::string& name, const std::string& text) const {
    write_text(dir_ / name, text);
    return "'" + (dir_ / name).string() + "'";
  }

  fs::path dir_;
};

}  // namespace batchcol::testing
