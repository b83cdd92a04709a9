// Error messages stay one bounded line whatever the input holds (issue #16, item 14): file names and arguments with
// newlines or escape sequences are printed escaped; numbers are printed with enough digits to show the problem.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "batchcol/io.hpp"
#include "tools/cli_runner.hpp"

#include <algorithm>
#include <string>

namespace batchcol {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

class CliMessages : public testing::CliTest {
 protected:
  static void expect_one_line(const testing::RunResult& r) {
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_THAT(r.err, StartsWith("batchcol: error: "));
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << "a raw escape sequence reached the terminal";
  }
};

TEST_F(CliMessages, FileNamesWithControlCharactersAreEscaped) {
  // $'...' is bash syntax; std::system runs /bin/sh, so the name is built by printf.
  const testing::RunResult r = run("query \"$(printf 'no\\nsuch\\033[31m.json')\"");
  expect_one_line(r);
  EXPECT_THAT(r.err, HasSubstr("no\\nsuch\\x1b[31m.json: no such file"));
}

TEST_F(CliMessages, UnknownSubcommandIsEscapedAndCut) {
  const testing::RunResult r = run("\"$(printf 'x\\ny')\"");
  expect_one_line(r);
  EXPECT_THAT(r.err, HasSubstr("unknown subcommand 'x\\ny'"));
  const testing::RunResult long_name = run(std::string(5000, 'q'));
  expect_one_line(long_name);
  EXPECT_LT(long_name.err.size(), 300u);
  EXPECT_THAT(long_name.err, HasSubstr("...(5000 bytes)"));
}

TEST_F(CliMessages, ThreadsBeyondTheLimitAreRefused) {
  const std::string batch = file("b.json", R"({"shapes":[{"type":"sphere","radius":1}],"pairs":[{"a":0,"b":0}]})");
  for (const char* threads : {"1025", "10000000", "100000000"}) {
    const testing::RunResult r = run("query " + batch + " --threads " + threads);
    expect_one_line(r);
    EXPECT_THAT(r.err, HasSubstr("--threads"));
  }
  EXPECT_EQ(run("query " + batch + " --threads 1024").exit_code, 0);
}

TEST(Messages, RejectedQuaternionNormIsPrintedWithItsDigits) {
  try {
    parse_batch_json(R"({"shapes":[{"type":"sphere","radius":1}],"pairs":[{"a":0,"b":0,)"
                     R"("pose_a":{"quaternion":[1.0000011,0,0,0]}}]})",
                     "b.json", ".");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("its norm is 1.0000011"));  // was "its norm is 1"
  }
  try {
    parse_batch_json(R"({"shapes":[{"type":"sphere","radius":1}],"pairs":[{"a":0,"b":0,)"
                     R"("pose_a":{"quaternion":[1e200,0,0,0]}}]})",
                     "b.json", ".");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("its norm is 1e+200"));  // was "inf"
  }
}

}  // namespace
}  // namespace batchcol
