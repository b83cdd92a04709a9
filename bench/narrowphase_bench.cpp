// Throughput of collide() per shape family, query level, solver and instruction set on seeded random pairs
// (centres 0-0.5 m apart, shapes 2-40 cm: a mix of separated and overlapping pairs). Reports pairs per second;
// instruction sets this CPU lacks are skipped with a message.
#include "support/generators.hpp"

#include <benchmark/benchmark.h>

namespace {

using namespace batchcol;

struct Workload {
  ShapeTable shapes;
  PairBatch batch;
};

Workload make_workload(ShapeType ta, ShapeType tb, std::size_t pairs) {
  testing::Rng rng(42);
  Workload w;
  for (int k = 0; k < 16; ++k) {
    w.shapes.add(testing::random_shape(rng, ta));
    w.shapes.add(testing::random_shape(rng, tb));
  }
  for (std::size_t i = 0; i < pairs; ++i) {
    const Pose pa{testing::random_vector(rng), testing::random_rotation(rng)};
    const Pose pb{pa.translation + testing::random_unit_vector(rng) * testing::uniform(rng, 0, 0.5),
                  testing::random_rotation(rng)};
    w.batch.add(static_cast<std::uint32_t>(2 * (rng() % 16)), pa, static_cast<std::uint32_t>(2 * (rng() % 16) + 1), pb);
  }
  return w;
}

void BM_Collide(benchmark::State& state) {
  const auto ta = static_cast<ShapeType>(state.range(0)), tb = static_cast<ShapeType>(state.range(1));
  const Workload w = make_workload(ta, tb, 20000);
  QueryOptions o;
  o.level = static_cast<QueryLevel>(state.range(2));
  o.solver = static_cast<Solver>(state.range(3));
  o.isa = static_cast<InstructionSet>(state.range(4));
  try {
    resolve_instruction_set(o.isa);
  } catch (const InputError& e) {
    state.SkipWithError(e.what());
    return;
  }
  PairResults r;
  for (auto _ : state) {
    collide(w.shapes, w.batch, o, r);
    benchmark::DoNotOptimize(r.distance.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(w.batch.size()));
  state.SetLabel(std::string(to_string(ta)) + "-" + to_string(tb) + " " + to_string(o.level) + " " + to_string(o.solver) +
                 " " + to_string(o.isa));
}

void families(benchmark::internal::Benchmark* b) {
  const std::vector<std::pair<ShapeType, ShapeType>> fams = {
      {ShapeType::sphere, ShapeType::sphere},      {ShapeType::capsule, ShapeType::capsule},
      {ShapeType::box, ShapeType::box},            {ShapeType::ellipsoid, ShapeType::ellipsoid},
      {ShapeType::cylinder, ShapeType::cylinder},  {ShapeType::convex, ShapeType::convex}};
  for (const auto& [a, c] : fams)
    for (QueryLevel l : {QueryLevel::boolean, QueryLevel::witness})
      for (Solver s : {Solver::gjk, Solver::nesterov})
        for (InstructionSet isa : {InstructionSet::scalar, InstructionSet::avx2, InstructionSet::avx512})
          b->Args({static_cast<int>(a), static_cast<int>(c), static_cast<int>(l), static_cast<int>(s),
                   static_cast<int>(isa)});
}

BENCHMARK(BM_Collide)->Apply(families)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
