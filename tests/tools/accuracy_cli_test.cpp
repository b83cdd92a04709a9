// Runs `batchcol accuracy` (the built binary) on small sweeps: the CSV has one row per configuration with every
// column, double GJK at tolerance 1e-10 meets the sphere-sphere closed form to 1e-9, the closed-form references
// agree with the tight GJK/EPA reference, bad flags exit 2 without writing, --no-plots and a python without
// matplotlib write no figures, and tools/plot_accuracy.py makes PNG and SVG figures when matplotlib is installed.
#include <gtest/gtest.h>

#include "tools/cli_runner.hpp"

#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

using batchcol::testing::read_text;
using batchcol::testing::RunResult;

const std::vector<std::string> kColumns = {
    "case", "regime", "solver", "precision", "tolerance", "query", "pairs", "threads", "reference", "witness_measure",
    "pairs_per_second", "ns_per_pair", "distance_error_median", "distance_error_p99", "distance_error_max",
    "distance_relative_error_max", "witness_error_median", "witness_error_p99", "witness_error_max",
    "normal_error_median", "normal_error_p99", "normal_error_max", "iterations_mean", "iterations_max",
    "scored_pairs", "not_converged", "non_finite", "reference_check"};

std::vector<std::string> split(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::stringstream in(line);
  for (std::string item; std::getline(in, item, sep);) out.push_back(item);
  return out;
}

// Rows of a CSV as column name -> text.
std::vector<std::map<std::string, std::string>> read_csv(const fs::path& path, std::vector<std::string>* header) {
  std::stringstream in(read_text(path));
  std::string line;
  std::getline(in, line);
  *header = split(line, ',');
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    const auto fields = split(line, ',');
    EXPECT_EQ(fields.size(), header->size()) << line;
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < fields.size() && i < header->size(); ++i) row[(*header)[i]] = fields[i];
    rows.push_back(row);
  }
  return rows;
}

double number(const std::map<std::string, std::string>& row, const std::string& column) {
  const auto it = row.find(column);
  if (it == row.end()) {
    ADD_FAILURE() << "no column " << column;
    return 0;
  }
  char* end = nullptr;
  const double v = std::strtod(it->second.c_str(), &end);
  EXPECT_TRUE(end != it->second.c_str() && *end == '\0') << column << " = '" << it->second << "'";
  return v;
}

std::vector<fs::path> files_with_extension(const fs::path& dir, const std::string& ext) {
  std::vector<fs::path> out;
  if (!fs::is_directory(dir)) return out;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() == ext) out.push_back(e.path());
  }
  return out;
}

bool debian_python_has_matplotlib() {
  return std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") == 0;
}

class AccuracyCli : public batchcol::testing::CliTest {
 protected:
  std::string out_dir() const { return (dir_ / "report").string(); }
};

TEST_F(AccuracyCli, CsvHasOneRowPerConfigurationWithEveryColumn) {
  const RunResult r = run("accuracy --case sphere-box --regime close,overlap --tolerances 1e-3,1e-10 --pairs 100 "
                          "--threads 2 --no-plots --out '" + out_dir() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::vector<std::string> header;
  const auto rows = read_csv(fs::path(out_dir()) / "accuracy.csv", &header);
  EXPECT_EQ(header, kColumns);
  ASSERT_EQ(rows.size(), 2u * 3u * 2u * 2u);  // regimes x solvers x precisions x tolerances
  std::set<std::string> configurations;
  for (const auto& row : rows) {
    configurations.insert(row.at("regime") + " " + row.at("solver") + " " + row.at("precision") + " " +
                          row.at("tolerance"));
    EXPECT_EQ(row.at("case"), "sphere-box");
    EXPECT_EQ(row.at("query"), row.at("regime") == "overlap" ? "penetration" : "witness");
    EXPECT_EQ(row.at("reference"), "analytic");
    EXPECT_EQ(number(row, "pairs"), 100);
    EXPECT_EQ(number(row, "scored_pairs"), 100);
    EXPECT_EQ(number(row, "non_finite"), 0);
    EXPECT_GT(number(row, "pairs_per_second"), 0);
    EXPECT_GE(number(row, "iterations_max"), number(row, "iterations_mean"));
    EXPECT_LE(number(row, "distance_error_median"), number(row, "distance_error_p99"));
    EXPECT_LE(number(row, "distance_error_p99"), number(row, "distance_error_max"));
    // A tolerance is a certified bound on the distance error (above the float floor of ~1e-6 m at this scale).
    const double floor = row.at("precision") == "float" ? 1e-5 : 1e-12;
    EXPECT_LE(number(row, "distance_error_max"), std::max(number(row, "tolerance"), floor)) << row.at("solver");
  }
  EXPECT_EQ(configurations.size(), rows.size()) << "a configuration appears twice";
  const std::string summary = read_text(fs::path(out_dir()) / "summary.md");
  EXPECT_NE(summary.find("| sphere-box | overlap |"), std::string::npos) << summary;
  EXPECT_NE(summary.find("Cheapest configuration"), std::string::npos) << summary;
  EXPECT_TRUE(files_with_extension(out_dir(), ".png").empty()) << "--no-plots wrote a PNG";
  EXPECT_TRUE(files_with_extension(out_dir(), ".svg").empty()) << "--no-plots wrote an SVG";
  EXPECT_TRUE(files_with_extension(out_dir(), ".tmp").empty()) << "a temporary file was left behind";
}

TEST_F(AccuracyCli, DoubleGjkMatchesTheSphereSphereClosedForm) {
  const RunResult r = run("accuracy --case sphere-sphere --regime all --solvers gjk --precisions double "
                          "--tolerances 1e-10 --pairs 300 --no-plots --out '" + out_dir() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::vector<std::string> header;
  const auto rows = read_csv(fs::path(out_dir()) / "accuracy.csv", &header);
  ASSERT_EQ(rows.size(), 3u);
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("reference"), "analytic");
    EXPECT_EQ(row.at("witness_measure"), "points");
    EXPECT_EQ(number(row, "scored_pairs"), 300);
    EXPECT_LE(number(row, "distance_error_max"), 1e-9) << row.at("regime");
    EXPECT_LE(number(row, "witness_error_max"), 1e-9) << row.at("regime");
    EXPECT_LE(number(row, "normal_error_max"), 1e-8) << row.at("regime");
  }
}

// The closed forms written for the accuracy reference (tools/cli/accuracy_closed_forms.cpp) against the engine's
// GJK/EPA at tolerance 1e-12, on the bench's pairs of every regime.
TEST_F(AccuracyCli, ClosedFormReferencesAgreeWithTheTightSolver) {
  for (const std::string c : {"sphere-capsule", "sphere-box", "sphere-cylinder", "sphere-cone", "capsule-capsule"}) {
    const std::string out = (dir_ / c).string();
    const RunResult r = run("accuracy --case " + c + " --regime all --solvers gjk --precisions double "
                            "--tolerances 1e-10 --pairs 200 --no-plots --out '" + out + "'");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::vector<std::string> header;
    const auto rows = read_csv(fs::path(out) / "accuracy.csv", &header);
    ASSERT_EQ(rows.size(), 3u) << c;
    for (const auto& row : rows) {
      EXPECT_EQ(row.at("reference"), "analytic") << c << " " << row.at("regime");
      EXPECT_LE(number(row, "reference_check"), 1e-10) << c << " " << row.at("regime");
      EXPECT_LE(number(row, "distance_error_max"), 1e-9) << c << " " << row.at("regime");
    }
  }
}

// Polytope witnesses are not unique: they are scored by their distance to the shapes' surfaces.
TEST_F(AccuracyCli, PolytopeWitnessesAreScoredOnTheSurfaces) {
  const RunResult r = run("accuracy --case box-convex8 --regime close --solvers nesterov --precisions double "
                          "--tolerances 1e-2,1e-10 --pairs 200 --no-plots --out '" + out_dir() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::vector<std::string> header;
  const auto rows = read_csv(fs::path(out_dir()) / "accuracy.csv", &header);
  ASSERT_EQ(rows.size(), 2u);
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("reference"), "gjk-1e-12");
    EXPECT_EQ(row.at("witness_measure"), "surface");
    EXPECT_EQ(number(row, "scored_pairs"), 200);
    if (row.at("tolerance") == "1e-10") { EXPECT_LE(number(row, "witness_error_max"), 1e-9); }
  }
}

// Without a closed form, gjk double at 1e-12 is the reference itself (error 0 by construction): the summary must
// not count it as the configuration that meets the double target.
TEST_F(AccuracyCli, SummaryIgnoresTheReferenceConfiguration) {
  const RunResult r = run("accuracy --case box-convex8 --regime close --solvers gjk --precisions double "
                          "--tolerances 1e-12 --pairs 100 --no-plots --out '" + out_dir() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::vector<std::string> header;
  const auto rows = read_csv(fs::path(out_dir()) / "accuracy.csv", &header);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(number(rows[0], "distance_error_max"), 0.0);  // the reference against itself
  const std::string summary = read_text(fs::path(out_dir()) / "summary.md");
  EXPECT_NE(summary.find("| box-convex8 | close | - | - |"), std::string::npos) << summary;
  EXPECT_NE(summary.find("0 of 1 case/regime combinations"), std::string::npos) << summary;
}

TEST_F(AccuracyCli, BadFlagsExitTwoAndWriteNothing) {
  const std::string out = " --out '" + out_dir() + "'";
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"accuracy --case sphere-sphere --no-plots", "--out"},
      {"accuracy --case sphere-banana --no-plots" + out, "banana"},
      {"accuracy --case sphere --no-plots" + out, "TYPE-TYPE"},
      {"accuracy --regime near --no-plots" + out, "near"},
      {"accuracy --tolerances 1e-3,abc --no-plots" + out, "abc"},
      {"accuracy --tolerances 0 --no-plots" + out, "--tolerances"},
      {"accuracy --tolerances=-1e-3 --no-plots" + out, "--tolerances"},
      {"accuracy --tolerances 1e-3,,1e-4 --no-plots" + out, "empty"},
      {"accuracy --solvers gjk,frank --no-plots" + out, "frank"},
      {"accuracy --precisions half --no-plots" + out, "half"},
      {"accuracy --pairs 0 --no-plots" + out, "--pairs"},
      {"accuracy --runs 2 --no-plots" + out, "--runs"},
      {"accuracy --threads -1 --no-plots" + out, "--threads"},
      {"accuracy --plot-script /nonexistent/plot.py" + out, "/nonexistent/plot.py"},
  };
  for (const auto& [args, mention] : bad) {
    const RunResult r = run(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("batchcol: error: ", 0), 0u) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(mention), std::string::npos) << args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(out_dir())) << args << " created the output folder";
  }
  // --out naming an existing file: refused before the sweep, the file is untouched.
  const std::string file = (dir_ / "taken.txt").string();
  batchcol::testing::write_text(file, "keep me\n");
  const RunResult r = run("accuracy --case sphere-sphere --no-plots --out '" + file + "'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("not a directory"), std::string::npos) << r.err;
  EXPECT_EQ(read_text(file), "keep me\n");
}

TEST_F(AccuracyCli, PythonWithoutMatplotlibKeepsTheCsvAndWarns) {
  // /bin/false stands for a python that cannot import matplotlib; --no-install keeps apt-get out of the test.
  const RunResult r = run("accuracy --case sphere-sphere --regime close --solvers gjk --precisions double "
                          "--tolerances 1e-6 --pairs 50 --python /bin/false --no-install --out '" + out_dir() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("apt-get install -y python3-matplotlib"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(fs::path(out_dir()) / "accuracy.csv"));
  EXPECT_TRUE(fs::exists(fs::path(out_dir()) / "summary.md"));
  EXPECT_TRUE(files_with_extension(out_dir(), ".png").empty());
}

TEST_F(AccuracyCli, PlotsArePngAndSvg) {
  if (!debian_python_has_matplotlib()) {
    GTEST_SKIP() << "/usr/bin/python3 cannot import matplotlib (apt-get install -y python3-matplotlib)";
  }
  const RunResult r = run("accuracy --case sphere-box --regime all --solvers gjk,nesterov --tolerances 1e-3,1e-8 "
                          "--pairs 50 --out '" + out_dir() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const std::string name : {"speed_vs_error_distant", "speed_vs_error_close", "speed_vs_error_overlap",
                                 "iterations", "iterations_vs_tolerance"}) {
    const std::string png = read_text(fs::path(out_dir()) / (name + ".png"));
    EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << name;
    const std::string svg = read_text(fs::path(out_dir()) / (name + ".svg"));
    EXPECT_NE(svg.find("<svg"), std::string::npos) << name;
    EXPECT_NE(svg.find("nesterov"), std::string::npos) << name << ": no legend entry for nesterov";
  }
  EXPECT_TRUE(files_with_extension(out_dir(), ".tmp").empty());
}

TEST_F(AccuracyCli, PlotScriptRejectsACsvWithoutItsColumns) {
  if (!debian_python_has_matplotlib()) {
    GTEST_SKIP() << "/usr/bin/python3 cannot import matplotlib (apt-get install -y python3-matplotlib)";
  }
  const fs::path script = fs::path(BATCHCOL_TEST_DATA_DIR) / ".." / ".." / "tools" / "plot_accuracy.py";
  const fs::path csv = dir_ / "bad.csv";
  batchcol::testing::write_text(csv, "case,regime\nsphere-box,close\n");
  const std::string command = "/usr/bin/python3 '" + script.string() + "' '" + csv.string() + "' '" + dir_.string() +
                              "' 2>'" + (dir_ / "err.txt").string() + "'";
  const int status = std::system(command.c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << status;
  EXPECT_NE(read_text(dir_ / "err.txt").find("missing columns"), std::string::npos) << read_text(dir_ / "err.txt");
  EXPECT_TRUE(files_with_extension(dir_, ".png").empty());
}

}  // namespace
