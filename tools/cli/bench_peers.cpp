#include "cli/bench_peers.hpp"
#include "cli/bench_timing.hpp"

#include <peers/peer_answer.hpp>  // PeerAnswer, also when no peer library was found

#ifdef BATCHCOL_HAVE_FCL
#include <peers/fcl_adapter.hpp>
#endif
#ifdef BATCHCOL_HAVE_BULLET
#include <peers/bullet_adapter.hpp>
#endif
#ifdef BATCHCOL_HAVE_COAL
#include <peers/coal_adapter.hpp>
#endif

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <functional>

namespace batchcol::cli {
namespace {

#if defined(BATCHCOL_HAVE_FCL) || defined(BATCHCOL_HAVE_BULLET) || defined(BATCHCOL_HAVE_COAL)
using PeerQuery = std::function<peers::PeerAnswer(std::size_t pair)>;

PeerTiming time_peer(const std::string& name, bool boolean, const BenchPairs& p, int threads, int timed_runs,
                     double min_run_seconds, const PeerQuery& query) {
  const std::size_t n = p.pairs.size();
  std::vector<peers::PeerAnswer> answers(n);
  tbb::task_arena arena(threads);
  const auto run = [&] {
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) answers[i] = query(i);
      });
    });
  };
  const CallTiming timing = time_calls(run, timed_runs, min_run_seconds);

  PeerTiming t;
  t.name = name;
  t.query = boolean ? "collide" : "distance";
  t.ns_per_pair = timing.seconds_per_call * 1e9 / double(n);
  t.calls_per_run = timing.calls_per_run;
  for (std::size_t i = 0; i < n; ++i) {
    const peers::PeerAnswer& a = answers[i];
    if (!a.ok) continue;
    ++t.handled;
    if (boolean) {
      t.disagreements += a.collide != (p.reference[i] <= 0.0) ? 1 : 0;
    } else if (std::isfinite(a.distance)) {
      t.error_max = std::max(t.error_max, std::abs(a.distance - p.reference[i]));
    }
  }
  return t;
}
#endif

}  // namespace

PeerReport time_peers(const BenchCase& bench_case, const BenchPairs& p, QueryLevel level, int threads,
                      int timed_runs, double min_run_seconds) {
  PeerReport report;
#if defined(BATCHCOL_HAVE_FCL) || defined(BATCHCOL_HAVE_BULLET) || defined(BATCHCOL_HAVE_COAL)
  const bool boolean = level == QueryLevel::boolean;
  const PairBatch& b = p.pairs;
#else
  (void)p, (void)level, (void)threads, (void)timed_runs, (void)min_run_seconds;
#endif
#ifdef BATCHCOL_HAVE_FCL
  {
    const peers::FclShapeCache fcl(p.shapes);
    constexpr double kFclTolerance = 1e-8;  // batchcol's default tolerance (QueryOptions::tolerance)
    report.timings.push_back(time_peer("FCL", boolean, p, threads, timed_runs, min_run_seconds, [&](std::size_t i) {
      return boolean ? fcl.collide(b.shape_a[i], b.pose_a(i), b.shape_b[i], b.pose_b(i), peers::FclSolver::libccd)
                     : fcl.distance(b.shape_a[i], b.pose_a(i), b.shape_b[i], b.pose_b(i), peers::FclSolver::libccd,
                                    kFclTolerance);
    }));
  }
#else
  report.notes.push_back("FCL not installed (apt-get install libfcl-dev)");
#endif
#ifdef BATCHCOL_HAVE_BULLET
  if (!peers::bullet_supports(bench_case.a.type) || !peers::bullet_supports(bench_case.b.type)) {
    report.notes.push_back("Bullet: no " + bench_case.name() + " pair (Bullet has no ellipsoid shape)");
  } else {
    const peers::BulletShapeCache bullet(p.shapes);
    report.timings.push_back(time_peer("Bullet", boolean, p, threads, timed_runs, min_run_seconds, [&](std::size_t i) {
      return bullet.signed_distance(b.shape_a[i], b.pose_a(i), b.shape_b[i], b.pose_b(i));
    }));
    if (boolean) report.timings.back().query = "signed distance (no boolean GJK in btGjkEpaSolver2)";
  }
#else
  (void)bench_case;
  report.notes.push_back("Bullet not installed (apt-get install libbullet-dev)");
#endif
#ifdef BATCHCOL_HAVE_COAL
  {
    const peers::CoalShapeCache coal(p.shapes);
    constexpr double kCoalTolerance = 1e-8;  // batchcol's default tolerance (QueryOptions::tolerance), as for FCL
    const bool want_depth = level == QueryLevel::penetration;
    report.timings.push_back(time_peer(boolean ? "Coal collide" : "Coal distance", boolean, p, threads, timed_runs,
                                       min_run_seconds, [&](std::size_t i) {
      return boolean ? coal.collide(b.shape_a[i], b.pose_a(i), b.shape_b[i], b.pose_b(i))
                     : coal.distance(b.shape_a[i], b.pose_a(i), b.shape_b[i], b.pose_b(i), kCoalTolerance);
    }));
    // GJK called directly (peers/coal_adapter.hpp): Coal's speed without its request/solver/dispatch overhead.
    for (const peers::CoalGjkVariant variant : {peers::CoalGjkVariant::plain, peers::CoalGjkVariant::nesterov}) {
      const char* name = variant == peers::CoalGjkVariant::plain ? "Coal GJK direct" : "Coal Nesterov direct";
      report.timings.push_back(time_peer(name, boolean, p, threads, timed_runs, min_run_seconds, [&](std::size_t i) {
        return boolean ? coal.gjk_collide(b.shape_a[i], b.pose_a(i), b.shape_b[i], b.pose_b(i), variant)
                       : coal.gjk_distance(b.shape_a[i], b.pose_a(i), b.shape_b[i], b.pose_b(i), variant,
                                           kCoalTolerance, want_depth);
      }));
      report.timings.back().query = boolean      ? "GJK::evaluate, early break at 0"
                                    : want_depth ? "GJK::evaluate without early break, EPA for overlapping pairs"
                                                 : "GJK::evaluate without early break (no depth for overlapping pairs)";
    }
  }
#else
  report.notes.push_back("Coal not found (build it with ../shared/peers/build-coal.sh, configure with "
                         "-DCMAKE_PREFIX_PATH=/opt/coal)");
#endif
  return report;
}

}  // namespace batchcol::cli
