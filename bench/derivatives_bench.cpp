// Throughput of differentiate() against the plain witness query on the same separated pairs (issue #18's speed
// targets): analytic, and smoothed0 / smoothed1 with M = 4, 16, 64, for ellipsoid pairs and random 24-point hull
// pairs.
// Reports pairs per second of wall time (derivative pairs, not samples; TBB threads work outside the main
// thread, so CPU time would miss them); compare rows of one run, the machine is shared.
#include "derivative_pairs.hpp"
#include "support/derivative_reference.hpp"

#include <benchmark/benchmark.h>
#include <emmintrin.h>

#include <algorithm>
#include <cstdint>

namespace {

using namespace batchcol;

struct Workload {
  ShapeTable shapes;
  PairBatch batch;
};

// Seeded: every row of a family times the same pairs.
Workload workload(ShapeType type) {
  Workload w;
  testing::Rng rng(18);
  w.batch = testing::random_separated_pairs(rng, w.shapes, {type}, 4096);
  return w;
}

// The floor of any derivative pass: only the 120 output doubles per pair, a whole block of 8 consecutive pairs of
// each SoA array in turn (one cache line per array), on the same task ranges and threads as differentiate();
// `streamed`: with non-temporal stores (one write-combined line per row; tried for StoreBlock::flush(), branch
// dhull-nt), else ordinary stores.
void write_outputs_only(DerivativeResults& d, bool streamed) {
  const std::size_t n = d.status.size();
  double* const arrays[8] = {d.distance_gradient_a.data.data(), d.distance_gradient_b.data.data(),
                             d.witness_a_wrt_a.data.data(),     d.witness_a_wrt_b.data.data(),
                             d.witness_b_wrt_a.data.data(),     d.witness_b_wrt_b.data.data(),
                             d.normal_wrt_a.data.data(),        d.normal_wrt_b.data.data()};
  detail::for_pairs(0, n, [&](std::size_t begin, std::size_t end) {
    for (std::size_t first = begin; first < end; first += 8) {
      const std::size_t count = std::min<std::size_t>(8, end - first);
      for (int a = 0; a < 8; ++a)
        for (int k = 0, rows = a < 2 ? 6 : 18; k < rows; ++k) {
          double* row = arrays[a] + k * n + first;
          if (streamed && count == 8 && reinterpret_cast<std::uintptr_t>(row) % 16 == 0) {
            for (std::size_t j = 0; j < 8; j += 2) _mm_stream_pd(row + j, _mm_set_pd(k + j + 1.0, k + j + 0.0));
          } else {
            for (std::size_t j = 0; j < count; ++j) row[j] = static_cast<double>(k + j);
          }
        }
    }
    _mm_sfence();
  });
}

// range(0): 0 ellipsoids, 1 hulls; range(1): -1 witness query only, -2 / -3 the output write only (no query;
// ordinary / streamed stores), else the
// DerivativeMethod; range(2): M.
void BM_Derivatives(benchmark::State& state) {
  const Workload w = workload(state.range(0) == 0 ? ShapeType::ellipsoid : ShapeType::convex);
  QueryOptions q;
  q.level = QueryLevel::witness;
  DerivativeOptions o;
  o.samples = static_cast<int>(state.range(2));
  PairResults r;
  DerivativeResults d;
  std::string label = state.range(0) == 0 ? "ellipsoids " : "hulls ";
  if (state.range(1) <= -2) {
    const bool streamed = state.range(1) == -3;
    label += streamed ? "output write only, streamed" : "output write only";
    d.resize(w.batch.size(), false);
    for (auto _ : state) {
      write_outputs_only(d, streamed);
      benchmark::DoNotOptimize(d.witness_a_wrt_b.data.data());
    }
  } else if (state.range(1) < 0) {
    label += "witness query";
    for (auto _ : state) {
      collide(w.shapes, w.batch, q, r);
      benchmark::DoNotOptimize(r.witness_a.x.data());
    }
  } else {
    o.method = static_cast<DerivativeMethod>(state.range(1));
    label += to_string(o.method);
    if (o.method != DerivativeMethod::analytic) label += " M=" + std::to_string(o.samples);
    for (auto _ : state) {
      differentiate(w.shapes, w.batch, q, o, r, d);
      benchmark::DoNotOptimize(d.witness_a_wrt_b.data.data());
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(w.batch.size()));
  state.SetLabel(label);
}

void rows(benchmark::internal::Benchmark* b) {
  for (int family : {0, 1}) {
    b->Args({family, -1, 1});
    b->Args({family, -2, 1});
    b->Args({family, -3, 1});
    b->Args({family, static_cast<int>(DerivativeMethod::analytic), 1});
    for (int method : {static_cast<int>(DerivativeMethod::smoothed0), static_cast<int>(DerivativeMethod::smoothed1)})
      for (int M : {4, 16, 64}) b->Args({family, method, M});
  }
}

BENCHMARK(BM_Derivatives)->Apply(rows)->Unit(benchmark::kMillisecond)->MinTime(0.2)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
