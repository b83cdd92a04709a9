// `batchcol query BATCH.json`: runs a batch file and writes one result row per pair (CSV to stdout, or --out).
#include "cli/atomic_output.hpp"
#include "cli/commands.hpp"

#include <batchcol/batch.hpp>
#include <batchcol/io.hpp>

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <memory>
#include <string>

namespace batchcol::cli {
namespace {

// Flags are kept as given; an Option's count() tells whether it overrides the batch file.
struct QuerySettings {
  std::string batch_path, query, solver, precision, out;
  double tolerance = 0.0, margin = 0.0;
  int max_iterations = 0, threads = 0;
  CLI::Option *query_flag = nullptr, *solver_flag = nullptr, *precision_flag = nullptr, *tolerance_flag = nullptr,
              *margin_flag = nullptr, *max_iterations_flag = nullptr;
};

// CLI11's own range check prints its bounds with 300 digits; this one names the rule.
CLI::Validator finite_non_negative() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        const bool ok = !text.empty() && *end == '\0' && std::isfinite(value) && value >= 0.0;
        return ok ? std::string() : "must be a finite number >= 0, got '" + text + "'";
      },
      "NUMBER>=0");
}

enum class Format { csv, json };

Format format_of(const std::string& path) {
  const auto dot = path.rfind('.');
  const std::string extension = dot == std::string::npos ? "" : path.substr(dot);
  if (extension == ".csv") return Format::csv;
  if (extension == ".json") return Format::json;
  throw InputError("--out " + path + ": unknown output format (use a .csv or .json file name)");
}

int run_query(const QuerySettings& s) {
  const Format format = s.out.empty() ? Format::csv : format_of(s.out);
  const BatchFile batch = load_batch_file(s.batch_path);

  QueryOptions options;
  batch.apply_to(options);
  if (s.query_flag->count()) options.level = parse_query_level(s.query);
  if (s.solver_flag->count()) options.solver = parse_solver(s.solver);
  if (s.precision_flag->count()) options.precision = parse_precision(s.precision);
  if (s.tolerance_flag->count()) options.tolerance = s.tolerance;
  if (s.margin_flag->count()) options.margin = s.margin;
  if (s.max_iterations_flag->count()) options.max_iterations = s.max_iterations;
  options.threads = s.threads;
  validate(options);

  PairResults results;
  collide(batch.shapes, batch.pairs, options, results);

  const auto write = [&](std::ostream& out) {
    if (format == Format::csv) write_results_csv(results, out);
    else write_results_json(results, out);
  };
  if (s.out.empty()) {
    write(std::cout);
    std::cout.flush();
    if (!std::cout) throw InputError("writing the results to standard output failed");
  } else {
    write_file_atomically(s.out, write);
  }
  return 0;
}

}  // namespace

Command add_query_command(CLI::App& parent) {
  auto s = std::make_shared<QuerySettings>();
  CLI::App* app = parent.add_subcommand("query", "Run the pairs of a batch file and write one result row per pair");
  app->add_option("batch", s->batch_path, "Batch file (JSON)")->required();
  s->query_flag = app->add_option("--query", s->query, "boolean, distance, witness or penetration");
  s->solver_flag = app->add_option("--solver", s->solver, "gjk, nesterov, polyak or automatic (the default: polyak for boolean, else gjk)");
  s->tolerance_flag = app->add_option("--tolerance", s->tolerance, "Distance tolerance in metres")
                          ->check(finite_non_negative());
  s->max_iterations_flag = app->add_option("--max-iterations", s->max_iterations, "GJK iterations per pair")
                               ->check(CLI::Range(1, std::numeric_limits<int>::max()));
  s->precision_flag = app->add_option("--precision", s->precision, "double or float");
  s->margin_flag = app->add_option("--margin", s->margin, "Security margin in metres")
                        ->check(finite_non_negative());
  app->add_option("--threads", s->threads, "Worker threads (0 = all cores)")
      ->check(CLI::Range(0, kMaxThreads));
  app->add_option("--out", s->out, "Output file (.csv or .json); standard output (CSV) when absent");
  return {app, [s] { return run_query(*s); }};
}

}  // namespace batchcol::cli
