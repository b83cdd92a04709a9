// Batch files built to exhaust memory or to garble messages (issue #16, items 5 and 14): the parser streams the
// shapes and pairs arrays element by element, limits nesting to kMaxJsonDepth and each element's DOM to 16 bytes per
// byte of the file, so a hostile file is refused early with peak memory a small multiple of its size; keys, types
// and names in messages are escaped and truncated.
#include "batchcol/io.hpp"
#include "tools/cli_runner.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <malloc.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

namespace batchcol {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

std::string error_of(const std::string& text) {
  try {
    parse_batch_json(text, "batch.json", ".");
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

std::string repeated(const std::string& unit, std::size_t times) {
  std::string out;
  out.reserve(unit.size() * times);
  for (std::size_t i = 0; i < times; ++i) out += unit;
  return out;
}

TEST(BatchLimits, DeepNestingIsRefusedAtTheLimit) {
  const std::string message = error_of(R"({"shapes":[],"pairs":[)" + repeated("[", 1000000));
  EXPECT_THAT(message, HasSubstr("nesting deeper than 16 levels"));
  EXPECT_LT(message.size(), 200u) << "the pointer of a deep array must not be printed whole";
  EXPECT_THAT(error_of(repeated("[", 100) + repeated("]", 100)), HasSubstr("top level: the top level must be an object"));
}

TEST(BatchLimits, EmptyElementsAreRefusedAtTheFirstOne) {
  EXPECT_THAT(error_of(R"({"shapes":[],"pairs":[)" + repeated("{},", 100000) + "{}]}"),
              HasSubstr("batch.json: /pairs/0/a: required field is missing"));
  EXPECT_THAT(error_of(R"({"shapes":[],"pairs":[)" + repeated("[],", 100000) + "[]]}"),
              HasSubstr("batch.json: /pairs/0: expected an object"));
  EXPECT_THAT(error_of(R"({"shapes":[)" + repeated("{},", 100000) + R"({}],"pairs":[]})"),
              HasSubstr("batch.json: /shapes/0/type: required field is missing"));
}

TEST(BatchLimits, OneElementMayNotOutgrowTheFile) {
  // A convex shape whose vertex list holds empty objects: ~80 bytes of DOM per 3 bytes of text.
  const std::string text = R"({"shapes":[{"type":"convex","vertices":[)" + repeated("{},", 400000) + R"({}]}],"pairs":[]})";
  EXPECT_THAT(error_of(text), HasSubstr("/shapes/0: this element would take more than"));
}

TEST(BatchLimits, TopLevelValuesOtherThanShapesAndPairsMustBeScalars) {
  EXPECT_THAT(error_of(R"({"shapes":[],"pairs":[],"query":[)" + repeated("[],", 1000) + "[]]}"),
              HasSubstr("/query: expected a string or a number, got an array"));
  EXPECT_THAT(error_of(R"({"junk":[)" + repeated("{},", 1000) + R"({}],"shapes":[],"pairs":[]})"),
              HasSubstr("/junk: unknown key 'junk'"));
  EXPECT_THAT(error_of(R"({"shapes":{"a":1},"pairs":[]})"), HasSubstr("/shapes: expected an array"));
}

TEST(BatchLimits, PairsBeforeShapesStillHaveTheirIndicesChecked) {
  const BatchFile ok = parse_batch_json(R"({"pairs":[{"a":0,"b":1}],"shapes":[{"type":"sphere","radius":1},)"
                                        R"({"type":"sphere","radius":2}]})",
                                        "batch.json", ".");
  ASSERT_EQ(ok.pairs.size(), 1u);
  EXPECT_EQ(ok.pairs.shape_b[0], 1u);
  EXPECT_THAT(error_of(R"({"pairs":[{"a":0,"b":0},{"a":0,"b":2}],"shapes":[{"type":"sphere","radius":1}]})"),
              HasSubstr("/pairs/1/b: shape index 2 is out of range (the batch has 1 shapes)"));
}

TEST(BatchLimits, UntrustedTextInMessagesIsEscapedAndTruncated) {
  const std::string nasty = std::string("evil\n\x1b[31mred\x07") + '\0' + "tail";
  std::string key_json;
  for (char c : nasty) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned char>(c));
    key_json += buf;
  }
  const std::string unknown_key = error_of(R"({"shapes":[{"type":"sphere","radius":1,")" + key_json + R"(":1}],"pairs":[]})");
  EXPECT_THAT(unknown_key, HasSubstr("unknown key 'evil\\n\\x1b[31mred\\x07\\x00tail'"));
  EXPECT_THAT(unknown_key, Not(HasSubstr("\n")));
  const std::string type = error_of(R"({"shapes":[{"type":")" + key_json + R"("}],"pairs":[]})");
  EXPECT_THAT(type, HasSubstr("unknown shape type 'evil\\n"));
  // A 10 MB key: the message stays short and says how long the key was.
  const std::string long_key = error_of(R"({"shapes":[{"type":"sphere","radius":1,")" + std::string(10000000, 'k') +
                                        R"(":1}],"pairs":[]})");
  EXPECT_LT(long_key.size(), 400u);
  EXPECT_THAT(long_key, HasSubstr("...(10000000 bytes)"));
}

// Peak resident memory of one `batchcol` run, from wait4's rusage of that very child. ru_maxrss survives exec: it
// starts at this test process's resident size at fork() (a vfork-like posix_spawn would give this process's own
// peak), so the big file texts are freed before each run and the freed heap handed back to the system
// (malloc_trim) before the fork: in the whole batchcol_tests binary, the tests before this one left the process at
// ~250 MB resident, and every run read that instead of the CLI's own peak. The resident size at fork is kept in the
// outcome (`inherited_kb`): a peak at or below it says nothing of the CLI, so the test requires it to be small.
class BatchLimitsCli : public testing::CliTest {
 protected:
  struct Outcome {
    int exit_code = -1;
    long peak_kb = 0;
    long inherited_kb = 0;  // this process's resident size at fork(): the floor of peak_kb
  };
  static long resident_kb() {
    long pages = 0, resident = 0;
    if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
      if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
      std::fclose(f);
    }
    return resident * (::sysconf(_SC_PAGESIZE) / 1024);
  }
  Outcome run_measured(const fs::path& batch) {
    Outcome o;
#ifdef BATCHCOL_CLI_PATH
    const std::string err = (dir_ / "stderr.txt").string(), path = batch.string();
    ::malloc_trim(0);
    o.inherited_kb = resident_kb();
    const pid_t pid = ::fork();
    if (pid == 0) {
      const int null = ::open("/dev/null", O_WRONLY), errors = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(null, 1);
      ::dup2(errors, 2);
      ::execl(BATCHCOL_CLI_PATH, "batchcol", "query", path.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    int status = 0;
    rusage usage{};
    ::wait4(pid, &status, 0, &usage);
    o.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    o.peak_kb = usage.ru_maxrss;
#else
    (void)batch;
#endif
    return o;
  }
};

TEST_F(BatchLimitsCli, HostileFilesAreRefusedWithinASmallMultipleOfTheirSize) {
#if defined(__SANITIZE_ADDRESS__)
  // AddressSanitizer's shadow memory and quarantine multiply the CLI's peak (measured 157-243 MB for these 29 MB
  // files under tools/run.sh asan-test): a bound on peak memory means nothing there. The plain build checks it.
  GTEST_SKIP() << "peak-memory bound not meaningful under AddressSanitizer";
#endif
  // 30 MB each: the whole-file DOM took 36x (`{},`), 26x (`[],`) and ~100x (deep `[`) of the file size.
  constexpr std::size_t kUnits = 10'000'000;
  const std::vector<std::pair<std::string, std::function<std::string()>>> files = {
      {"objects.json", [] { return R"({"shapes":[],"pairs":[)" + repeated("{},", kUnits) + "{}]}"; }},
      {"arrays.json", [] { return R"({"shapes":[],"pairs":[)" + repeated("[],", kUnits) + "[]]}"; }},
      {"deep.json", [] { return R"({"shapes":[],"pairs":[)" + std::string(3 * kUnits, '['); }},
      {"query.json", [] { return R"({"shapes":[],"pairs":[],"query":[)" + repeated("{},", kUnits) + "{}]}"; }},
  };
  for (const auto& [name, make] : files) {
    long file_kb = 0;
    {
      const std::string text = make();
      file_kb = static_cast<long>(text.size() / 1024);
      testing::write_text(dir_ / name, text);
    }
    const Outcome o = run_measured(dir_ / name);
    EXPECT_EQ(o.exit_code, 2) << name;
    // The text itself, once, plus the process's own ~20 MB (TBB, assimp, the C++ runtime), with room.
    EXPECT_LT(o.inherited_kb, 64 * 1024) << name << ": this process was " << o.inherited_kb
                                         << " KiB resident at fork, the floor of the child's peak reading";
    EXPECT_LT(o.peak_kb, 2 * file_kb + 64 * 1024) << name << ": peak " << o.peak_kb << " KiB for a " << file_kb
                                                  << " KiB file";
    const std::string err = testing::read_text(dir_ / "stderr.txt");
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err.substr(0, 400);
    EXPECT_LT(err.size(), 400u);
    fs::remove(dir_ / name);
  }
}

}  // namespace
}  // namespace batchcol
