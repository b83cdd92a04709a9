// `batchcol query BATCH.json`: runs a batch file and writes one result row per pair (CSV to stdout, or --out).
#include "cli/atomic_output.hpp"
#include "cli/commands.hpp"

#include <batchcol/batch.hpp>
#include <batchcol/derivatives.hpp>
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
  std::string derivatives;  // empty: none
  DerivativeOptions derivative_options;
  bool gradients_only = false;  // DerivativeOptions::jacobians = false
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
  DerivativeResults derivatives;
  const bool differentiating = !s.derivatives.empty();
  if (s.gradients_only && !differentiating) throw InputError("--gradients-only needs --derivatives analytic");
  if (differentiating) {
    DerivativeOptions d = s.derivative_options;
    d.method = parse_derivative_method(s.derivatives);
    d.jacobians = !s.gradients_only;
    differentiate(batch.shapes, batch.pairs, options, d, results, derivatives);
  } else {
    collide(batch.shapes, batch.pairs, options, results);
  }

  const DerivativeResults* columns = differentiating ? &derivatives : nullptr;
  const auto write = [&](std::ostream& out) {
    if (format == Format::csv) write_results_csv(results, out, columns);
    else write_results_json(results, out, columns);
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

DerivativeMethod parse_derivative_method(const std::string& name) {
  try {
    return batchcol::parse_derivative_method(name);
  } catch (const InputError& error) {  // name the flag the user typed
    throw InputError(std::string("--derivatives: ") + error.what());
  }
}

Command add_query_command(CLI::App& parent) {
  auto s = std::make_shared<QuerySettings>();
  CLI::App* app = parent.add_subcommand("query", "Run the pairs of a batch file and write one result row per pair");
  app->add_option("batch", s->batch_path, "Batch file (JSON)")->required();
  s->query_flag = app->add_option("--query", s->query, "boolean, distance, witness or penetration");
  s->solver_flag = app->add_option("--solver", s->solver, "gjk, nesterov, polyak or automatic (the default: polyak for boolean except gjk for capsule-box/-cylinder/-cone, box-cylinder/-cone and cone-cone; polyak for ellipsoid-ellipsoid, -cylinder, -cone and -convex at every level; else gjk)");
  s->tolerance_flag = app->add_option("--tolerance", s->tolerance, "Distance tolerance in metres")
                          ->check(finite_non_negative());
  s->max_iterations_flag = app->add_option("--max-iterations", s->max_iterations, "GJK iterations per pair")
                               ->check(CLI::Range(1, std::numeric_limits<int>::max()));
  s->precision_flag = app->add_option("--precision", s->precision, "double or float");
  s->margin_flag = app->add_option("--margin", s->margin, "Security margin in metres")
                        ->check(finite_non_negative());
  app->add_option("--threads", s->threads, "Worker threads (0 = all cores)")
      ->check(CLI::Range(0, kMaxThreads));
  app->add_option("--derivatives", s->derivatives,
                  "Also differentiate w.r.t. the poses: analytic, smoothed0 or smoothed1 (needs --query witness or "
                  "penetration; adds the derivative columns)");
  app->add_option("--samples", s->derivative_options.samples, "Samples per pair of the smoothed derivatives (>= 1)");
  app->add_option("--noise", s->derivative_options.noise,
                  "Noise of the smoothed derivatives, relative to the perturbed shape's bounding radius (> 0)");
  app->add_option("--seed", s->derivative_options.seed, "Seed of the smoothed derivatives' samples");
  app->add_flag("--gradients-only", s->gradients_only,
                "With --derivatives analytic: only the distance gradients (no Jacobian columns)");
  app->add_option("--out", s->out, "Output file (.csv or .json); standard output (CSV) when absent");
  return {app, [s] { return run_query(*s); }};
}

}  // namespace batchcol::cli
