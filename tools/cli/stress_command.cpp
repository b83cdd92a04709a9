// `batchcol stress`: builds a scene of mixed shapes, steps it with small motions and reports the median time per
// step of each stage (world AABBs, sweep-and-prune, narrow phase), the pair counts, peak memory and `verified`
// (candidate pairs equal brute force, see stress_verify.hpp). It also times a full sweep-and-prune rebuild and an
// incremental update on the last frame's boxes, and with --peers the Bullet/FCL broad phases on the same boxes.
#include "cli/commands.hpp"
#include "testkit/stress_scene.hpp"
#include "testkit/stress_verify.hpp"

#include "broadphase/sweep_and_prune.hpp"
#include "peers/broadphase_peers.hpp"
#include "scene_hooks.hpp"  // engine/src: the scene's last boxes, for the peers

#include <batchcol/io.hpp>
#include <batchcol/scene.hpp>

#include <nlohmann/json.hpp>
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <iostream>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include <sys/resource.h>
#include <unistd.h>

namespace batchcol::cli {

using testkit::StressScene;
using testkit::StressSceneSpec;
using testkit::Verification;
using testkit::make_stress_scene;
using testkit::parse_distribution;
using testkit::step_stress_scene;
using testkit::verify_candidates;
namespace {

struct StressSettings {
  std::int64_t objects = 10000, steps = 10;
  std::string distribution = "uniform", query = "boolean";
  double density = 0.4, move = 0.05;
  int threads = 0;
  std::uint64_t seed = 1;
  bool json = false, peers = false;
};

// Timed repetitions of the standalone sweep-and-prune rebuild/update on the last frame (after one warm-up call).
constexpr int kSapRuns = 7;

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double minimum(const std::vector<double>& v) { return v.empty() ? 0.0 : *std::min_element(v.begin(), v.end()); }

double time_ms(const std::function<void()>& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

// %g: std::to_string(1e300) prints 301 digits, to_string(1e-300) prints 0.000000.
std::string shortest(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

void check(bool ok, const std::string& message) {
  if (!ok) throw InputError(message);
}

void validate(const StressSettings& s) {
  check(s.objects >= 1, "--objects must be >= 1 (got " + std::to_string(s.objects) + ")");
  check(s.objects < (std::int64_t{1} << 31), "--objects must be < 2^31");
  check(s.steps >= 1, "--steps must be >= 1 (got " + std::to_string(s.steps) + ")");
  // Below 1e-6 overlaps per object the scene's world grows without bound (1e-300 placed objects beyond the 1e30 m
  // the scene accepts); such a scene has no pairs to measure anyway.
  check(std::isfinite(s.density) && s.density >= 1e-6, "--density must be a finite number >= 1e-6 (got " +
                                                           shortest(s.density) + ")");
  check(std::isfinite(s.move) && s.move >= 0 && s.move <= 1, "--move must be a finite number in [0, 1] (got " +
                                                                  shortest(s.move) + ")");
  check(s.threads >= 0 && s.threads <= kMaxThreads,
        "--threads must be between 0 (all cores) and " + std::to_string(kMaxThreads));
  check(s.query == "boolean" || s.query == "witness", "--query " + s.query + ": unknown (valid: boolean, witness)");
}

// Draws a progress bar on stderr, only when stderr is a terminal.
class Progress {
 public:
  explicit Progress(std::int64_t total) : total_(total), enabled_(isatty(STDERR_FILENO) == 1) {}
  void show(std::int64_t done) const {
    if (!enabled_) return;
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(kWidth * done / std::max<std::int64_t>(total_, 1));
    std::fprintf(stderr, "\rstress [%.*s%*s] step %lld/%lld", filled, "##############################",
                 kWidth - filled, "", static_cast<long long>(done), static_cast<long long>(total_));
    std::fflush(stderr);
  }
  void finish() const {
    if (enabled_) std::fprintf(stderr, "\r%*s\r", 70, "");
  }

 private:
  std::int64_t total_;
  bool enabled_;
};

struct StageSamples {
  std::vector<double> aabb, bucket, sweep, emit, sap, broadphase, batch, narrow, total, move;
  void add(const SceneTimings& t, double move_ms) {
    aabb.push_back(t.aabb_ms), bucket.push_back(t.sap_bucket_ms), sweep.push_back(t.sap_sweep_ms);
    emit.push_back(t.sap_emit_ms), sap.push_back(t.sap_bucket_ms + t.sap_sweep_ms + t.sap_emit_ms);
    broadphase.push_back(t.broadphase_ms()), batch.push_back(t.batch_ms), narrow.push_back(t.narrowphase_ms);
    total.push_back(t.total_ms), move.push_back(move_ms);
  }
};

struct SapBench {
  double rebuild_ms = 0, update_ms = 0, rebuild_ms_1thread = 0, update_ms_1thread = 0;
  double rebuild_warm_ms = 0, rebuild_warm_ms_1thread = 0;  // rebuild() on a SAP whose buffers exist already
  std::size_t pairs = 0, bytes = 0;
  std::size_t pair_bytes = 0;       // the part of `bytes` that scales with the pairs (pair words, radix scratch)
  std::size_t overflow = 0;         // objects in the update's overflow after the last update
  double copies = 0;                // grid-cell records per object (boxes straddling cells have several)
  bool update_incremental = false;  // every timed update kept the grid
  double update_rebucketed = 0;     // share of the timed updates that re-bucketed every object
};

// Our sweep-and-prune alone on the same two frames as the peers. Rebuild = a fresh structure from scratch (its buffers
// allocated and first touched inside the timing, like the peers' fresh trees); warm rebuild = rebuild() again on the
// same structure (what a scene does after objects were added or removed); update = the frames alternate.
SapBench time_sap(const std::vector<Aabb>& frame, const std::vector<Aabb>& moved, int threads) {
  broadphase::AabbSoa a, b;
  a.assign(frame);
  b.assign(moved);
  SapBench out;
  std::vector<broadphase::CandidatePair> pairs;
  bool first_done = false;
  for (int t : {threads, 1}) {
    tbb::task_arena arena(t);
    arena.execute([&] {
      std::vector<double> rebuild, warm, update;
      for (int r = 0; r <= kSapRuns; ++r) {
        broadphase::SweepAndPrune sap;
        const double ms = time_ms([&] { sap.rebuild(a, {}, pairs); });
        if (r > 0) rebuild.push_back(ms);
        out.pairs = pairs.size();
      }
      broadphase::SweepAndPrune sap;
      for (int r = 0; r <= kSapRuns; ++r) {
        const double ms = time_ms([&] { sap.rebuild(a, {}, pairs); });
        if (r > 0) warm.push_back(ms);
      }
      bool incremental = true;
      int rebucketed = 0;
      for (int r = 0; r <= kSapRuns; ++r) {
        const double ms = time_ms([&] { sap.update(r % 2 == 0 ? b : a, {}, pairs); });
        incremental = incremental && sap.stats().incremental;
        if (r > 0) update.push_back(ms), rebucketed += sap.stats().rebucketed ? 1 : 0;
      }
      if (t == threads && !first_done) {
        out.rebuild_ms = median(rebuild), out.update_ms = median(update), out.update_incremental = incremental;
        out.rebuild_warm_ms = median(warm);
        out.update_rebucketed = static_cast<double>(rebucketed) / kSapRuns;
        out.bytes = sap.memory_bytes(), out.pair_bytes = sap.pair_buffer_bytes();
        out.overflow = sap.stats().overflow;
        out.copies = static_cast<double>(sap.stats().entries) / static_cast<double>(std::max<std::size_t>(1, a.size()));
        first_done = true;
      } else {
        out.rebuild_ms_1thread = median(rebuild), out.update_ms_1thread = median(update);
        out.rebuild_warm_ms_1thread = median(warm);
      }
    });
  }
  return out;
}

int run_stress(const StressSettings& s) {
  validate(s);
  StressSceneSpec spec;
  spec.objects = static_cast<std::size_t>(s.objects);
  spec.distribution = parse_distribution(s.distribution);
  spec.density = s.density;
  spec.move = s.move;
  spec.seed = s.seed;
  QueryOptions options;
  options.level = parse_query_level(s.query);
  options.threads = s.threads;
  options.margin = 0.0;
  const int threads = s.threads > 0 ? s.threads : tbb::info::default_concurrency();

  StressScene scene;
  double setup_ms = 0.0;
  try {
    setup_ms = time_ms([&] { scene = make_stress_scene(spec); });
  } catch (const std::bad_alloc&) {
    throw InputError("--objects " + std::to_string(s.objects) + ": not enough memory for a scene of that many objects");
  }
  SceneResults results;
  StageSamples warm, first;
  const Progress progress(s.steps);
  for (std::int64_t step = 0; step < s.steps; ++step) {
    progress.show(step);
    const double move_ms = step == 0 ? 0.0 : time_ms([&] { step_stress_scene(scene); });
    scene.scene->collide(options, results);
    (step == 0 ? first : warm).add(results.timings, move_ms);
  }
  progress.show(s.steps);
  progress.finish();
  const StageSamples& m = s.steps > 1 ? warm : first;  // step 0 builds the grid and warms the buffers

  const Verification v = verify_candidates(*scene.scene, results, s.seed + 1);
  std::vector<Aabb> frame, moved;
  std::vector<ObjectHandle> objects;
  detail::SceneHooks::last_aabbs(*scene.scene, frame, objects);
  moved = frame;
  for (std::size_t i = 0; i < moved.size(); ++i) {  // the next step's translation (same order as the handles)
    moved[i].min += scene.velocity[objects[i].slot];
    moved[i].max += scene.velocity[objects[i].slot];
  }
  const SapBench sap = time_sap(frame, moved, threads);
  std::vector<peers::BroadphasePeerTiming> peer_timings;
  std::vector<std::string> peer_notes;
  if (s.peers) peer_timings = peers::time_broadphase_peers(frame, moved, frame.size() >= 500000 ? 1 : 3, peer_notes);

  const double n = static_cast<double>(s.objects);
  const double overlaps = 2.0 * static_cast<double>(sap.pairs) / n;
  // Memory kept between frames by the broad phase, per object: the SAP's buffers that scale with the objects plus the
  // float boxes it reads (6 floats per object, the scene's frame buffer); the pair buffers (SAP pair words and radix
  // scratch, the output pairs) are counted per candidate pair.
  const double broadphase_bytes_per_object =
      (static_cast<double>(sap.bytes - sap.pair_bytes) + 6.0 * sizeof(float) * n) / n;
  const double pair_count = static_cast<double>(sap.pairs);
  const double pair_bytes =
      static_cast<double>(sap.pair_bytes) + pair_count * static_cast<double>(sizeof(broadphase::CandidatePair));
  const double pair_bytes_per_pair = sap.pairs == 0 ? 0.0 : pair_bytes / pair_count;
  nlohmann::json j = {
      {"objects", s.objects}, {"steps", s.steps}, {"threads", threads}, {"distribution", s.distribution},
      {"density", s.density}, {"move", s.move}, {"query", s.query}, {"seed", s.seed},
      {"aabb_ms_median", median(m.aabb)}, {"sap_ms_median", median(m.sap)},
      {"sap_bucket_ms_median", median(m.bucket)}, {"sap_sort_sweep_ms_median", median(m.sweep)},
      {"sap_emit_ms_median", median(m.emit)}, {"broadphase_ms_median", median(m.broadphase)},
      {"batch_ms_median", median(m.batch)}, {"narrowphase_ms_median", median(m.narrow)},
      {"total_ms_median", median(m.total)}, {"move_ms_median", median(m.move)},
      {"broadphase_ms_min", minimum(m.broadphase)}, {"sap_ms_min", minimum(m.sap)},
      {"narrowphase_ms_min", minimum(m.narrow)}, {"total_ms_min", minimum(m.total)},
      {"first_step_total_ms", first.total.empty() ? 0.0 : first.total[0]}, {"setup_ms", setup_ms},
      {"candidate_pairs", results.candidate_count()}, {"colliding_pairs", results.colliding_count()},
      {"aabb_overlaps_per_object", overlaps}, {"incremental", results.incremental},
      {"peak_rss_mb", peak_rss_mb()}, {"scene_bytes_per_object", static_cast<double>(scene.scene->memory_bytes()) / n},
      {"sap_rebuild_ms_median", sap.rebuild_ms}, {"sap_update_ms_median", sap.update_ms},
      {"sap_rebuild_ms_median_1thread", sap.rebuild_ms_1thread}, {"sap_update_ms_median_1thread", sap.update_ms_1thread},
      {"sap_rebuild_warm_ms_median", sap.rebuild_warm_ms},
      {"sap_rebuild_warm_ms_median_1thread", sap.rebuild_warm_ms_1thread},
      {"sap_update_incremental", sap.update_incremental}, {"sap_update_rebucketed_fraction", sap.update_rebucketed},
      {"sap_update_overflow_objects", sap.overflow}, {"sap_cell_copies_per_object", sap.copies},
      {"sap_bytes_per_object", static_cast<double>(sap.bytes) / n},
      {"broadphase_bytes_per_object", broadphase_bytes_per_object},
      {"pair_bytes_per_pair", pair_bytes_per_pair},
      {"verified", v.equal}, {"verified_scope", v.scope}, {"verified_objects", v.objects},
      {"verified_pairs", v.pairs}, {"verified_missing", v.missing}, {"verified_extra", v.extra}};
  nlohmann::json pj = nlohmann::json::array();
  for (const auto& p : peer_timings)
    pj.push_back({{"name", p.name}, {"rebuild_ms", p.rebuild_ms}, {"update_ms", p.update_ms},
                  {"rebuild_pairs", p.rebuild_pairs}, {"update_pairs", p.update_pairs},
                  {"rebuild_ratio", sap.rebuild_ms > 0 ? p.rebuild_ms / sap.rebuild_ms : 0.0},
                  {"update_ratio", sap.update_ms > 0 ? p.update_ms / sap.update_ms : 0.0}});
  if (s.peers) j["peers"] = pj, j["peers_missing"] = peer_notes;

  if (s.json) {
    std::cout << j.dump(2) << '\n';
  } else {
    std::printf("scene: %lld objects (%s, density %.3g -> %.3g AABB overlaps/object), %lld steps, move %.3g, "
                "threads %d, query %s\n",
                static_cast<long long>(s.objects), s.distribution.c_str(), s.density, overlaps,
                static_cast<long long>(s.steps), s.move, threads, s.query.c_str());
    std::printf("per step (median of %zu%s): aabb %.3f ms | sap %.3f ms (bucket %.3f, sort+sweep %.3f, emit %.3f) | "
                "batch %.3f ms | narrow %.3f ms | total %.3f ms (broad phase %.3f ms)\n",
                m.total.size(), s.steps > 1 ? " steps after the first" : " step", median(m.aabb), median(m.sap),
                median(m.bucket), median(m.sweep), median(m.emit), median(m.batch), median(m.narrow),
                median(m.total), median(m.broadphase));
    std::printf("pairs: %zu candidates, %zu colliding (last step)\n", results.candidate_count(),
                results.colliding_count());
    std::printf("sweep-and-prune alone on the last frame: rebuild %.3f ms (warm %.3f), update %.3f ms (%d threads); "
                "rebuild %.3f ms (warm %.3f), update %.3f ms (1 thread)\n",
                sap.rebuild_ms, sap.rebuild_warm_ms, sap.update_ms, threads, sap.rebuild_ms_1thread,
                sap.rebuild_warm_ms_1thread, sap.update_ms_1thread);
    std::printf("broad-phase memory: %.1f B/object (SAP buffers + float boxes), %.1f B per candidate pair; "
                "SAP total %.1f B/object\n",
                broadphase_bytes_per_object, pair_bytes_per_pair, static_cast<double>(sap.bytes) / n);
    for (const auto& p : peer_timings)
      std::printf("peer %-26s rebuild %9.3f ms (%.2fx ours)  update %9.3f ms (%.2fx ours)  pairs %zu / %zu\n",
                  p.name.c_str(), p.rebuild_ms, sap.rebuild_ms > 0 ? p.rebuild_ms / sap.rebuild_ms : 0.0,
                  p.update_ms, sap.update_ms > 0 ? p.update_ms / sap.update_ms : 0.0, p.rebuild_pairs,
                  p.update_pairs);
    for (const auto& note : peer_notes) std::printf("note: %s\n", note.c_str());
    std::printf("memory: peak RSS %.1f MB, scene %.1f B/object\n", peak_rss_mb(),
                static_cast<double>(scene.scene->memory_bytes()) / n);
    std::printf("verified: %s (%s, %zu objects, %zu pairs, %zu missing, %zu extra)\n", v.equal ? "yes" : "NO",
                v.scope.c_str(), v.objects, v.pairs, v.missing, v.extra);
  }
  std::cout.flush();
  if (!std::cout) throw InputError("writing to standard output failed");
  return v.equal ? 0 : 1;
}

}  // namespace

Command add_stress_command(CLI::App& parent) {
  auto s = std::make_shared<StressSettings>();
  CLI::App* app = parent.add_subcommand(
      "stress", "Step a large scene of mixed shapes through broad + narrow phase and report per-stage times");
  app->add_option("--objects", s->objects, "Number of objects (>= 1)")->capture_default_str();
  app->add_option("--distribution", s->distribution, "uniform, clustered or layered")->capture_default_str();
  app->add_option("--density", s->density, "Expected AABB overlaps per object (>= 1e-6)")->capture_default_str();
  app->add_option("--steps", s->steps, "Steps (>= 1); the medians skip the first step when there are several")
      ->capture_default_str();
  app->add_option("--move", s->move, "Per step: translation as a fraction of the object size, rotation in radians")
      ->capture_default_str();
  app->add_option("--query", s->query, "boolean or witness")->capture_default_str();
  app->add_option("--threads", s->threads, "Worker threads (0 = all cores)")->capture_default_str();
  app->add_option("--seed", s->seed, "Seed of the scene")->capture_default_str();
  app->add_flag("--json", s->json, "Print one JSON object");
  app->add_flag("--peers", s->peers, "Also time Bullet btDbvtBroadphase, FCL DynamicAABBTree and FCL SaP");
  return {app, [s] { return run_stress(*s); }};
}

}  // namespace batchcol::cli
