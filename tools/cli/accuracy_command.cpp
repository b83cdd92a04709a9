// `batchcol accuracy`: for each shape-pair case and distance regime of `batchcol bench` (the same seeded pairs),
// sweeps solver x precision x tolerance through collide() and measures pairs/s and the error against a tight
// double reference (analytic where a closed form exists). Writes DIR/accuracy.csv and DIR/summary.md atomically,
// then the plots (tools/plot_accuracy.py). Issue 5, part 1.
#include "cli/accuracy_measure.hpp"
#include "cli/accuracy_plots.hpp"
#include "cli/accuracy_progress.hpp"
#include "cli/accuracy_report.hpp"
#include "cli/atomic_output.hpp"
#include "cli/commands.hpp"

#include <batchcol/io.hpp>

#include <tbb/info.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace batchcol::cli {
namespace {

struct AccuracySettings {
  std::string cases = "all", regimes = "all", solvers = "gjk,nesterov,polyak", precisions = "float,double";
  std::string tolerances = "1e-2,1e-3,1e-4,1e-5,1e-6,1e-7,1e-8,1e-9,1e-10,1e-11,1e-12";
  std::string out;
  std::size_t pairs = 2000;
  int threads = 0, runs = 3, max_iterations = 1000;
  std::uint64_t seed = 20240603;  // the bench's default: the same pairs as `batchcol bench`
  bool no_plots = false, no_install = false;
  PlotSettings plot;
};

std::vector<std::string> split_list(const std::string& flag, const std::string& text) {
  std::vector<std::string> items;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    const auto first = item.find_first_not_of(" \t"), last = item.find_last_not_of(" \t");
    if (first == std::string::npos) throw InputError(flag + " " + text + ": empty item in the comma-separated list");
    items.push_back(item.substr(first, last - first + 1));
  }
  if (items.empty()) throw InputError(flag + ": empty list");
  return items;
}

std::vector<double> parse_tolerances(const std::string& text) {
  std::vector<double> out;
  for (const std::string& item : split_list("--tolerances", text)) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (end != item.c_str() + item.size() || !std::isfinite(v) || !(v > 0)) {
      throw InputError("--tolerances " + text + ": '" + item + "' is not a finite number > 0");
    }
    out.push_back(v);
  }
  return out;
}

std::vector<Regime> parse_regimes(const std::string& text) {
  if (text == "all") return {Regime::distant, Regime::close, Regime::overlap};
  std::vector<Regime> out;
  for (const std::string& item : split_list("--regime", text)) out.push_back(parse_regime(item));
  return out;
}

std::vector<SweepPoint> sweep_points(const AccuracySettings& s) {
  std::vector<SweepPoint> points;
  const auto tolerances = parse_tolerances(s.tolerances);
  for (const std::string& solver : split_list("--solvers", s.solvers)) {
    for (const std::string& precision : split_list("--precisions", s.precisions)) {
      for (double tolerance : tolerances) {
        points.push_back({parse_solver(solver), parse_precision(precision), tolerance});
      }
    }
  }
  return points;
}

// Creates DIR (and parents) and checks that a file can be written there, before the long sweep.
void prepare_output_dir(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec)) throw InputError("--out " + dir + ": exists and is not a directory");
  fs::create_directories(dir, ec);
  if (ec) throw InputError("--out " + dir + ": cannot create the directory: " + ec.message());
  const std::string probe = (fs::path(dir) / ".batchcol-write-check").string();
  write_file_atomically(probe, [](std::ostream& out) { out << "ok\n"; });
  fs::remove(probe, ec);
}

std::string command_line(const AccuracySettings& s) {
  std::string c = "batchcol accuracy --case " + s.cases + " --regime " + s.regimes + " --pairs " +
                  std::to_string(s.pairs) + " --threads " + std::to_string(s.threads);
  const AccuracySettings defaults;
  if (s.solvers != defaults.solvers) c += " --solvers " + s.solvers;
  if (s.precisions != defaults.precisions) c += " --precisions " + s.precisions;
  if (s.tolerances != defaults.tolerances) c += " --tolerances " + s.tolerances;
  if (s.seed != defaults.seed) c += " --seed " + std::to_string(s.seed);
  if (s.runs != defaults.runs) c += " --runs " + std::to_string(s.runs);
  if (s.max_iterations != defaults.max_iterations) c += " --max-iterations " + std::to_string(s.max_iterations);
  return c + " --out " + s.out;
}

int run_accuracy(const AccuracySettings& s) {
  // Every flag is checked before anything is written or measured.
  const std::vector<BenchCase> cases = parse_bench_cases(s.cases);
  const std::vector<Regime> regimes = parse_regimes(s.regimes);
  const std::vector<SweepPoint> points = sweep_points(s);
  const int threads = s.threads > 0 ? s.threads : tbb::info::default_concurrency();
  const MeasureSettings measure_settings{threads, s.runs, s.max_iterations};
  PlotSettings plot = s.plot;
  plot.install = !s.no_install;
  const bool plots = !s.no_plots && prepare_plotting(plot);
  prepare_output_dir(s.out);

  std::vector<AccuracyRow> rows;
  ProgressBar progress(cases.size() * regimes.size() * points.size());
  for (std::size_t c = 0; c < cases.size(); ++c) {
    for (Regime regime : regimes) {
      const std::string where = cases[c].name() + " " + to_string(regime);
      progress.update(rows.size(), where + ": placing pairs");
      const CaseData data = prepare_case(cases[c], regime, s.pairs, s.seed + 7919 * c, threads);
      for (const SweepPoint& p : points) {
        progress.update(rows.size(), where + " " + to_string(p.solver) + " " + to_string(p.precision));
        rows.push_back(measure(data, p, measure_settings));
      }
    }
  }
  progress.finish();

  namespace fs = std::filesystem;
  const std::string csv = (fs::path(s.out) / "accuracy.csv").string();
  const std::string summary = (fs::path(s.out) / "summary.md").string();
  write_file_atomically(csv, [&](std::ostream& out) { write_accuracy_csv(rows, out); });
  const SummaryContext context{command_line(s), s.pairs, threads, s.runs, s.max_iterations};
  write_file_atomically(summary, [&](std::ostream& out) { write_accuracy_summary(rows, context, out); });
  std::cout << "wrote " << csv << " (" << rows.size() << " configurations) and " << summary << "\n";
  if (plots) {
    run_plot_script(plot, csv, s.out);
    std::cout << "wrote the plots into " << s.out << "\n";
  }
  std::cout.flush();
  if (!std::cout) throw InputError("writing to standard output failed");
  return 0;
}

}  // namespace

Command add_accuracy_command(CLI::App& parent) {
  auto s = std::make_shared<AccuracySettings>();
  s->plot.script = default_plot_script();
  CLI::App* app = parent.add_subcommand(
      "accuracy", "Speed vs error of every solver x precision x tolerance per case and regime: CSV, summary, plots");
  app->add_option("--case", s->cases, "TYPE-TYPE (as in bench) or all")->capture_default_str();
  app->add_option("--regime", s->regimes, "distant, close, overlap, a comma-separated list, or all")
      ->capture_default_str();
  app->add_option("--solvers", s->solvers, "Comma-separated: gjk, nesterov, polyak")->capture_default_str();
  app->add_option("--precisions", s->precisions, "Comma-separated: float, double")->capture_default_str();
  app->add_option("--tolerances", s->tolerances, "Comma-separated tolerances in metres")->capture_default_str();
  app->add_option("--pairs", s->pairs, "Pairs per case and regime")
      ->check(CLI::Range(std::size_t{1}, std::size_t{1} << 28))
      ->capture_default_str();
  app->add_option("--threads", s->threads, "Worker threads (0 = all cores)")
      ->check(CLI::Range(0, kMaxThreads))
      ->capture_default_str();
  app->add_option("--runs", s->runs, "Timed runs per configuration (the median is reported)")
      ->check(CLI::Range(3, 1000))
      ->capture_default_str();
  app->add_option("--max-iterations", s->max_iterations, "GJK iteration budget per pair")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  app->add_option("--seed", s->seed, "Seed of the pair generator (the bench's)")->capture_default_str();
  app->add_option("--out", s->out, "Output folder (created): accuracy.csv, summary.md, plots")->required();
  app->add_flag("--no-plots", s->no_plots, "Write the CSV and summary only");
  app->add_option("--plot-script", s->plot.script, "The plot script")->capture_default_str();
  app->add_option("--python", s->plot.python, "Python with matplotlib that runs the plot script")->capture_default_str();
  app->add_flag("--no-install", s->no_install, "Never run apt-get for a missing python3-matplotlib");
  return {app, [s] { return run_accuracy(*s); }};
}

}  // namespace batchcol::cli
