// Peer timings of `batchcol bench`: FCL, Bullet and Coal (when found at configure time) on the same pairs, with
// tbb::parallel_for in a task_arena of the same thread count, timed as batchcol is (bench_timing.hpp).
#pragma once

#include "testkit/bench_pairs.hpp"

#include <batchcol/batch.hpp>

#include <string>
#include <vector>

namespace batchcol::cli {

using testkit::BenchCase;
using testkit::BenchPairs;

struct PeerTiming {
  std::string name;              // "FCL", "Bullet", "Coal collide", "Coal distance", "Coal GJK direct", ...
  std::string query;             // what the peer ran: "collide", "distance" or a description
  double ns_per_pair = 0;        // median per-call time / pairs (bench_timing.hpp)
  int calls_per_run = 1;
  std::size_t handled = 0;       // pairs the peer answered (ok)
  double error_max = 0;          // max |signed distance - reference| over handled pairs (distance queries)
  std::size_t disagreements = 0; // boolean queries: collide != (reference <= 0)
};

struct PeerReport {
  std::vector<PeerTiming> timings;
  std::vector<std::string> notes;  // missing or unsupported peers
};

/// Boolean queries run the peers' collide, every other level their (signed) distance. Geometries are built once
/// before timing (peers::FclShapeCache, peers::BulletShapeCache, peers::CoalShapeCache). Coal runs three ways:
/// coal::collide / coal::distance, and its GJK called directly, plain and Nesterov-accelerated.
PeerReport time_peers(const BenchCase& bench_case, const BenchPairs& pairs, QueryLevel level, int threads,
                      int timed_runs, double min_run_seconds);

}  // namespace batchcol::cli
