// Sweep-and-prune on uniform boxes in a unit cube, sized for about 0.4 other boxes overlapping each box (pairs
// ~= 0.2 n): full rebuild and incremental update (every box moved by up to 5% of its size, alternating between two
// frames; the update keeps the grid), 10k / 100k / 1M objects, 2 threads. Main-thread CPU time is the more stable
// figure on a shared machine.
// Counters: pairs found, overlaps per box (2 pairs / n), bytes per object held by the SAP, cell copies per object;
// incremental_fraction = share of updates that kept the grid.
#include "batchcol/shapes.hpp"
#include "broadphase/sweep_and_prune.hpp"
#include "testkit/portable_random.hpp"

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cmath>
#include <utility>

namespace {

using namespace batchcol;
using namespace batchcol::broadphase;

constexpr int kThreads = 2;

struct Frames {
  AabbSoa a, b;
};

Frames make_frames(std::size_t n) {
  batchcol::testkit::PortableRandom rng(42);
  // One draw per statement: the evaluation order of constructor arguments is unspecified.
  const auto unit3 = [&rng](double shift) {
    const double x = rng.uniform() - shift;
    const double y = rng.uniform() - shift;
    const double z = rng.uniform() - shift;
    return Eigen::Vector3d(x, y, z);
  };
  // Equal boxes of half size h in a unit cube overlap with probability (4h)^3 (ignoring the faces).
  const double h = 0.25 * std::cbrt(0.4 / static_cast<double>(n - 1));
  std::vector<Aabb> a(n), b(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d c = unit3(0.0);
    const Eigen::Vector3d d = unit3(0.5);
    a[i] = {c - Eigen::Vector3d::Constant(h), c + Eigen::Vector3d::Constant(h)};
    const Eigen::Vector3d m = c + 0.1 * h * d;
    b[i] = {m - Eigen::Vector3d::Constant(h), m + Eigen::Vector3d::Constant(h)};
  }
  Frames f;
  f.a.assign(a);
  f.b.assign(b);
  return f;
}

void report(benchmark::State& state, const SweepAndPrune& sap, std::size_t n) {
  state.counters["pairs"] = static_cast<double>(sap.stats().pairs);
  state.counters["overlaps_per_box"] = 2.0 * static_cast<double>(sap.stats().pairs) / static_cast<double>(n);
  state.counters["bytes_per_object"] = static_cast<double>(sap.memory_bytes()) / static_cast<double>(n);
  // Honest per-object memory: the SAP's buffers that scale with the objects plus the 24-byte float boxes it reads.
  state.counters["broadphase_bytes_per_object"] =
      static_cast<double>(sap.memory_bytes() - sap.pair_buffer_bytes()) / static_cast<double>(n) + 24.0;
  state.counters["overflow_objects"] = static_cast<double>(sap.stats().overflow);
  state.counters["copies_per_object"] = static_cast<double>(sap.stats().entries) / static_cast<double>(n);
  // Stage split of the last call (wall clock): grid + bucketing, per-cell sort + sweep, pair merge.
  state.counters["bucket_ms"] = sap.stats().bucket_ms;
  state.counters["sweep_ms"] = sap.stats().sweep_ms;
  state.counters["emit_ms"] = sap.stats().emit_ms;
}

void BM_SapRebuild(benchmark::State& state) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, kThreads);
  const auto n = static_cast<std::size_t>(state.range(0));
  const Frames f = make_frames(n);
  SweepAndPrune sap;
  std::vector<CandidatePair> pairs;
  for (auto _ : state) {
    sap.rebuild(f.a, {}, pairs);
    benchmark::DoNotOptimize(pairs.data());
  }
  report(state, sap, n);
}

// Rebuild into a fresh structure every time: allocation and first touch of the buffers included.
void BM_SapRebuildCold(benchmark::State& state) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, kThreads);
  const auto n = static_cast<std::size_t>(state.range(0));
  const Frames f = make_frames(n);
  std::vector<CandidatePair> pairs;
  SweepAndPrune last;
  for (auto _ : state) {
    SweepAndPrune sap;
    sap.rebuild(f.a, {}, pairs);
    benchmark::DoNotOptimize(pairs.data());
    state.PauseTiming();
    last = std::move(sap);  // freed outside the timing
    state.ResumeTiming();
  }
  report(state, last, n);
}

void BM_SapIncremental(benchmark::State& state) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, kThreads);
  const auto n = static_cast<std::size_t>(state.range(0));
  const Frames f = make_frames(n);
  SweepAndPrune sap;
  std::vector<CandidatePair> pairs;
  sap.rebuild(f.a, {}, pairs);
  bool odd = false;
  std::size_t incremental = 0, calls = 0;
  for (auto _ : state) {
    odd = !odd;
    sap.update(odd ? f.b : f.a, {}, pairs);
    benchmark::DoNotOptimize(pairs.data());
    incremental += sap.stats().incremental, ++calls;
  }
  report(state, sap, n);
  state.counters["incremental_fraction"] = static_cast<double>(incremental) / static_cast<double>(calls);
}

BENCHMARK(BM_SapRebuild)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SapRebuildCold)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SapIncremental)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
BENCHMARK_MAIN();
