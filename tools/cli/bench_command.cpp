// `batchcol bench`: times collide() on generated pairs of one shape-type pair per case, in one distance regime,
// reports throughput and the error against the double-precision reference, and times FCL, Bullet and Coal (when found
// at configure time) on the same pairs and thread count. --isa picks the instruction set of the SIMD kernels (auto: the
// best this CPU runs); closed forms run in SIMD lanes for sphere/capsule pairs and box-box boolean, per pair for
// the other closed-form types.
#include "cli/atomic_output.hpp"
#include "testkit/bench_pairs.hpp"
#include "cli/bench_peers.hpp"
#include "cli/bench_timing.hpp"
#include "cli/commands.hpp"

#include <batchcol/batch.hpp>
#include <batchcol/derivatives.hpp>
#include <batchcol/io.hpp>

#include <nlohmann/json.hpp>
#include <tbb/info.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace batchcol::cli {

using testkit::BenchCase;
using testkit::BenchPairs;
using testkit::Regime;
using testkit::make_bench_pairs;
using testkit::parse_bench_cases;
using testkit::parse_regime;
namespace {

struct BenchSettings {
  std::string cases = "all", regime = "close", query = "witness", precision = "double", solver = "automatic";
  std::string isa = "auto", save_pairs;
  int threads = 0, runs = 5;
  double min_run_ms = 20;  // calls per timed run: enough for this many milliseconds (bench_timing.hpp)
  std::size_t pairs = 100000;
  std::uint64_t seed = 20240603;
  bool json = false, no_peers = false;
  std::string derivatives;  // empty: time collide(); else differentiate() with this method (issue #18)
  DerivativeOptions derivative_options;
  bool gradients_only = false;  // DerivativeOptions::jacobians = false
};

struct CaseResult {
  BenchCase bench_case;
  double ns_per_pair = 0, pairs_per_second = 0;
  double error_median = 0, error_max = 0;
  std::size_t error_pairs = 0, disagreements = 0;
  double reference_min = 0, reference_max = 0;
  double iterations_mean = 0;  // GJK iterations plus EPA expansions per pair (0 for closed forms)
  int calls_per_run = 1;
  std::string note, kernel;
  PeerReport peers;
};

void save_pairs(const BenchPairs& p, const std::string& path) {
  using nlohmann::json;
  json shapes = json::array(), pairs = json::array();
  const auto vec = [](const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); };
  for (const Shape& s : p.shapes.shapes()) {
    json j = {{"type", to_string(s.type)}};
    switch (s.type) {
      case ShapeType::sphere: j["radius"] = s.size.x(); break;
      case ShapeType::capsule:
      case ShapeType::cylinder:
      case ShapeType::cone: j["radius"] = s.size.x(); j["half_length"] = s.size.y(); break;
      case ShapeType::box: j["half_extents"] = vec(s.size); break;
      case ShapeType::ellipsoid: j["radii"] = vec(s.size); break;
      default: {
        json v = json::array();
        for (const auto& x : s.hull->vertices) v.push_back(vec(x));
        j["vertices"] = v;
      }
    }
    shapes.push_back(j);
  }
  for (std::size_t i = 0; i < p.pairs.size(); ++i) {
    const auto pose = [&](const Pose& q) {
      return json{{"translation", vec(q.translation)},
                  {"quaternion", json::array({q.rotation.w(), q.rotation.x(), q.rotation.y(), q.rotation.z()})}};
    };
    pairs.push_back({{"a", p.pairs.shape_a[i]}, {"pose_a", pose(p.pairs.pose_a(i))}, {"b", p.pairs.shape_b[i]},
                     {"pose_b", pose(p.pairs.pose_b(i))}});
  }
  write_file_atomically(path, [&](std::ostream& out) { out << json{{"shapes", shapes}, {"pairs", pairs}}.dump(1) << '\n'; });
}

CaseResult run_case(const BenchCase& bench_case, std::size_t case_index, const BenchSettings& s,
                    const QueryOptions& options, Regime regime, int threads) {
  CaseResult out;
  out.bench_case = bench_case;
  const BenchPairs p = make_bench_pairs(bench_case, regime, s.pairs, s.seed + 7919 * case_index, threads);
  if (!s.save_pairs.empty()) save_pairs(p, s.save_pairs);
  out.reference_min = *std::min_element(p.reference.begin(), p.reference.end());
  out.reference_max = *std::max_element(p.reference.begin(), p.reference.end());

  out.kernel = kernel_for(p.shapes[p.pairs.shape_a[0]], p.shapes[p.pairs.shape_b[0]], options);
  PairResults results;
  const double min_run_seconds = s.min_run_ms * 1e-3;
  DerivativeResults derivatives;
  DerivativeOptions d = s.derivative_options;
  if (!s.derivatives.empty()) d.method = parse_derivative_method(s.derivatives);
  d.jacobians = !s.gradients_only;
  const auto call = [&] {
    if (s.derivatives.empty()) collide(p.shapes, p.pairs, options, results);
    else differentiate(p.shapes, p.pairs, options, d, results, derivatives);
  };
  const CallTiming timing = time_calls(call, s.runs, min_run_seconds);
  out.calls_per_run = timing.calls_per_run;
  const double median = timing.seconds_per_call;
  const double n = double(p.pairs.size());
  out.ns_per_pair = median * 1e9 / n;
  out.pairs_per_second = median > 0 ? n / median : 0.0;

  std::vector<double> errors;
  double iterations = 0;
  for (std::size_t i = 0; i < results.size(); ++i) {
    iterations += results.iterations[i];
    out.disagreements += (results.collide[i] != 0) != (p.reference[i] <= options.margin) ? 1 : 0;
    if (options.level != QueryLevel::boolean && std::isfinite(results.distance[i])) {
      errors.push_back(std::abs(results.distance[i] - p.reference[i]));
    }
  }
  out.error_pairs = errors.size();
  out.iterations_mean = iterations / n;
  out.error_median = median_of(errors);
  out.error_max = errors.empty() ? 0.0 : *std::max_element(errors.begin(), errors.end());
  if (options.level == QueryLevel::boolean) {
    out.note = "boolean query computes no distance: error fields are 0, see collide_disagreements";
  } else if (errors.empty()) {
    out.note = "no pair has a distance at this query level (overlapping pairs need --query penetration): "
               "error fields are 0";
  }
  if (!s.no_peers) out.peers = time_peers(bench_case, p, options.level, threads, s.runs, min_run_seconds);
  return out;
}

nlohmann::json to_json(const CaseResult& r, const BenchSettings& s, const QueryOptions& o, Regime regime, int threads) {
  nlohmann::json peers = nlohmann::json::array();
  for (const PeerTiming& t : r.peers.timings) {
    peers.push_back({{"name", t.name}, {"query", t.query}, {"ns_per_pair", t.ns_per_pair},
                     {"error_max", t.error_max}, {"ratio", r.ns_per_pair > 0 ? t.ns_per_pair / r.ns_per_pair : 0.0},
                     {"pairs_answered", t.handled}, {"calls_per_run", t.calls_per_run}, {"collide_disagreements", t.disagreements}});
  }
  nlohmann::json j = {{"case", r.bench_case.name()}, {"regime", to_string(regime)}, {"query", to_string(o.level)},
                      {"precision", s.precision}, {"solver", to_string(resolve_solver(o.solver, o.level, r.bench_case.a.type, r.bench_case.b.type))},
                      {"solver_requested", to_string(o.solver)}, {"threads", threads},
                      {"pairs", s.pairs}, {"isa", to_string(o.isa)}, {"kernel", r.kernel}, {"pairs_per_second", r.pairs_per_second},
                      {"ns_per_pair", r.ns_per_pair}, {"error_median", r.error_median}, {"error_max", r.error_max},
                      {"error_pairs", r.error_pairs}, {"collide_disagreements", r.disagreements},
                      {"reference_min", r.reference_min}, {"reference_max", r.reference_max}, {"iterations_mean", r.iterations_mean},
                      {"timed_runs", s.runs}, {"calls_per_run", r.calls_per_run}, {"min_run_ms", s.min_run_ms}, {"peers", peers}, {"peers_missing", r.peers.notes}};
  if (!r.note.empty()) j["note"] = r.note;
  if (!s.derivatives.empty())
    j["derivatives"] = {{"method", s.derivatives}, {"samples", s.derivative_options.samples},
                        {"noise", s.derivative_options.noise}, {"jacobians", !s.gradients_only}};
  return j;
}

void print_table(const std::vector<CaseResult>& results, const BenchSettings& s, const QueryOptions& o, Regime regime,
                 int threads) {
  std::printf("instruction set: %s (closed forms: SIMD lanes for sphere/capsule pairs and box-box boolean, per pair "
              "otherwise)\n",
              to_string(o.isa));
  std::printf("regime %s, query %s, precision %s, solver %s%s, threads %d, pairs %zu, median of %d runs after 1 "
              "warm-up, calls per run enough for %g ms\n",
              to_string(regime), to_string(o.level), s.precision.c_str(), to_string(resolve_solver(o.solver, o.level)),
              o.solver == Solver::automatic ? " (automatic)" : "", threads, s.pairs, s.runs, s.min_run_ms);
  if (!s.derivatives.empty())
    std::printf("timing differentiate() with derivatives %s%s (samples %d, noise %g), peers time plain queries\n",
                s.derivatives.c_str(), s.gradients_only ? ", distance gradients only" : "",
                s.derivative_options.samples, s.derivative_options.noise);
  std::printf("error: |distance - reference| (double, tol 1e-12, gjk, closed forms off); ratio = peer ns / batchcol ns\n");
  const bool boolean = o.level == QueryLevel::boolean;
  std::printf("%-22s %-11s %6s %10s %11s %10s %10s", "case", "kernel", "iters", "ns/pair", "pairs/s",
              boolean ? "disagree" : "err_med", boolean ? "" : "err_max");
  std::printf("   %-s\n", "peers: name ns/pair ratio err_max|disagree");
  for (const CaseResult& r : results) {
    std::printf("%-22s %-11s %6.2f %10.1f %11.4g ", r.bench_case.name().c_str(), r.kernel.c_str(), r.iterations_mean,
                r.ns_per_pair, r.pairs_per_second);
    if (boolean) std::printf("%10zu %10s", r.disagreements, "");
    else std::printf("%10.2e %10.2e", r.error_median, r.error_max);
    for (const PeerTiming& t : r.peers.timings) {
      std::printf("   %s %.1f %.2fx ", t.name.c_str(), t.ns_per_pair, r.ns_per_pair > 0 ? t.ns_per_pair / r.ns_per_pair : 0.0);
      if (boolean) std::printf("%zu", t.disagreements);
      else std::printf("%.2e", t.error_max);
    }
    std::printf("\n");
  }
  std::vector<std::string> notes;
  for (const CaseResult& r : results) {
    if (!r.note.empty()) notes.push_back(r.note);
    notes.insert(notes.end(), r.peers.notes.begin(), r.peers.notes.end());
  }
  std::sort(notes.begin(), notes.end());
  notes.erase(std::unique(notes.begin(), notes.end()), notes.end());
  for (const std::string& n : notes) std::printf("note: %s\n", n.c_str());
}

int run_bench(const BenchSettings& s) {
  const std::vector<BenchCase> cases = parse_bench_cases(s.cases);
  const Regime regime = parse_regime(s.regime);
  // Checked here, not with CLI::Range, which lets NaN through (every comparison with it is false).
  if (!(s.min_run_ms >= 0.0 && s.min_run_ms <= 10000.0))
    throw InputError("--min-run-ms " + std::to_string(s.min_run_ms) + ": must be a number of milliseconds in [0, 10000]");
  if (!s.save_pairs.empty() && cases.size() != 1) throw InputError("--save-pairs needs a single --case");
  QueryOptions options;
  options.level = parse_query_level(s.query);
  options.precision = parse_precision(s.precision);
  options.solver = parse_solver(s.solver);
  options.threads = s.threads;
  if (s.isa != "auto") {
    if (s.isa != "scalar" && s.isa != "avx2" && s.isa != "avx512")
      throw InputError("--isa " + s.isa + ": unknown instruction set (valid: auto, scalar, avx2, avx512)");
    options.isa = parse_instruction_set(s.isa);
  }
  options.isa = resolve_instruction_set(options.isa);  // InputError when this CPU cannot run it
  validate(options);
  if (s.gradients_only && s.derivatives.empty()) throw InputError("--gradients-only needs --derivatives analytic");
  if (!s.derivatives.empty()) {  // bad derivative options fail before any pair is generated
    DerivativeOptions d = s.derivative_options;
    d.method = parse_derivative_method(s.derivatives);
    d.jacobians = !s.gradients_only;
    validate(d);
    if (options.level < QueryLevel::witness) throw InputError("--derivatives needs --query witness or penetration");
  }
  const int threads = s.threads > 0 ? s.threads : tbb::info::default_concurrency();

  std::vector<CaseResult> results;
  for (std::size_t i = 0; i < cases.size(); ++i) results.push_back(run_case(cases[i], i, s, options, regime, threads));

  if (s.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const CaseResult& r : results) out.push_back(to_json(r, s, options, regime, threads));
    std::cout << (s.cases == "all" ? out : out[0]).dump(2) << '\n';
  } else {
    print_table(results, s, options, regime, threads);
  }
  std::cout.flush();
  if (!std::cout) throw InputError("writing to standard output failed");
  return 0;
}

}  // namespace

Command add_bench_command(CLI::App& parent) {
  auto s = std::make_shared<BenchSettings>();
  CLI::App* app = parent.add_subcommand(
      "bench", "Time collide() per shape-type pair and distance regime against the double reference and the peers "
               "(FCL, Bullet, Coal)");
  app->add_option("--case", s->cases, "TYPE-TYPE (sphere, capsule, box, cylinder, cone, ellipsoid, convex8, "
                                      "convex250, convex940) or all")
      ->capture_default_str();
  app->add_option("--regime", s->regime, "distant (0.1-1 m), close (1e-4-1e-2 m) or overlap (depth 1e-4-1e-2 m)")
      ->capture_default_str();
  app->add_option("--query", s->query, "boolean, distance, witness or penetration")->capture_default_str();
  app->add_option("--precision", s->precision, "double or float")->capture_default_str();
  app->add_option("--solver", s->solver, "gjk, nesterov, polyak or automatic (polyak for boolean except gjk for capsule-box/-cylinder/-cone, box-cylinder/-cone and cone-cone; polyak for ellipsoid-ellipsoid, -cylinder, -cone and -convex at every level; else gjk)")->capture_default_str();
  app->add_option("--threads", s->threads, "Worker threads (0 = all cores)")
      ->check(CLI::Range(0, kMaxThreads))
      ->capture_default_str();
  app->add_option("--pairs", s->pairs, "Pairs per case")
      ->check(CLI::Range(std::size_t{1}, std::size_t{1} << 32))
      ->capture_default_str();
  app->add_option("--runs", s->runs, "Timed runs (the median is reported)")->check(CLI::Range(5, 1000))->capture_default_str();
  app->add_option("--min-run-ms", s->min_run_ms,
                  "Calls per timed run: as many as last this long (grown from 1 after the warm-up, at most 100000); "
                  "the median time per call is reported (0: one call per run)")
      ->capture_default_str();
  app->add_option("--isa", s->isa, "auto, scalar, avx2 or avx512 (auto: the best this CPU runs)")->capture_default_str();
  app->add_option("--seed", s->seed, "Seed of the pair generator")->capture_default_str();
  app->add_option("--save-pairs", s->save_pairs, "Write the generated pairs as a batch file (single --case)");
  app->add_flag("--no-peers", s->no_peers, "Do not time the peers (FCL, Bullet, Coal)");
  app->add_option("--derivatives", s->derivatives, "Time differentiate() instead: analytic, smoothed0 or smoothed1");
  app->add_option("--samples", s->derivative_options.samples, "Samples per pair of the smoothed derivatives");
  app->add_option("--noise", s->derivative_options.noise, "Relative noise of the smoothed derivatives");
  app->add_flag("--gradients-only", s->gradients_only, "With --derivatives analytic: time the distance gradients only");
  app->add_flag("--json", s->json, "Print JSON (one object, an array for --case all)");
  return {app, [s] { return run_bench(*s); }};
}

}  // namespace batchcol::cli
