// `batchcol demo`: runs the embedded scene and prints a throughput summary (one warm-up, median of 5 timed runs).
#include "cli/commands.hpp"
#include "testkit/demo_scene.hpp"

#include <batchcol/batch.hpp>
#include <batchcol/io.hpp>

#include <tbb/info.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace batchcol::cli {
namespace {

using testkit::DemoScene;
using testkit::make_demo_scene;

struct DemoSettings {
  std::size_t pairs = 200000;
  int threads = 0;
  std::string query = "witness";
  std::string precision = "double";
};

constexpr int kTimedRuns = 5;

int run_demo(const DemoSettings& settings) {
  QueryOptions options;
  options.level = parse_query_level(settings.query);
  options.precision = parse_precision(settings.precision);
  options.threads = settings.threads;
  validate(options);

  const DemoScene scene = make_demo_scene(settings.pairs);
  PairResults results;
  collide(scene.shapes, scene.pairs, options, results);  // warm-up: page faults, TBB thread start
  std::vector<double> milliseconds;
  for (int run = 0; run < kTimedRuns; ++run) {
    const auto start = std::chrono::steady_clock::now();
    collide(scene.shapes, scene.pairs, options, results);
    const std::chrono::duration<double, std::milli> elapsed = std::chrono::steady_clock::now() - start;
    milliseconds.push_back(elapsed.count());
  }
  std::sort(milliseconds.begin(), milliseconds.end());
  const double median_ms = milliseconds[kTimedRuns / 2];

  std::size_t colliding = 0;
  std::array<std::size_t, 4> status_counts{};
  for (std::size_t i = 0; i < results.size(); ++i) {
    colliding += results.collide[i] ? 1 : 0;
    ++status_counts.at(static_cast<std::size_t>(results.status[i]));
  }
  const int threads = settings.threads > 0 ? settings.threads : tbb::info::default_concurrency();
  std::printf("scene: %zu pairs over %zu shapes (%zu overlapping by construction)\n", scene.pairs.size(),
              scene.shapes.size(), scene.overlapping);
  std::printf("query: %s, solver %s, precision %s, threads %d\n", to_string(options.level),
              to_string(resolve_solver(options.solver, options.level)), to_string(options.precision), threads);
  std::printf("colliding: %zu\n", colliding);
  std::printf("status:");
  for (std::size_t s = 0; s < status_counts.size(); ++s) {
    std::printf("%s %s %zu", s ? "," : "", to_string(static_cast<Status>(s)), status_counts[s]);
  }
  std::printf("\ntime: median %.3f ms of %d runs (after 1 warm-up)\n", median_ms, kTimedRuns);
  const double seconds = median_ms / 1000.0;
  std::printf("throughput: %.4g pairs/s\n", seconds > 0.0 ? static_cast<double>(scene.pairs.size()) / seconds : 0.0);
  return 0;
}

}  // namespace

Command add_demo_command(CLI::App& parent) {
  auto settings = std::make_shared<DemoSettings>();
  CLI::App* app = parent.add_subcommand("demo", "Time collision queries on a built-in scene of random convex pairs");
  app->add_option("--pairs", settings->pairs, "Number of pairs")
      ->check(CLI::Range(std::size_t{1}, std::size_t{1} << 32))
      ->capture_default_str();
  app->add_option("--threads", settings->threads, "Worker threads (0 = all cores)")
      ->check(CLI::Range(0, kMaxThreads))
      ->capture_default_str();
  app->add_option("--query", settings->query, "boolean, distance, witness or penetration")->capture_default_str();
  app->add_option("--precision", settings->precision, "double or float")->capture_default_str();
  return {app, [settings] { return run_demo(*settings); }};
}

}  // namespace batchcol::cli
