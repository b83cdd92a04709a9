// Large analytic outputs: StoreBlock writes them on AVX-512 in whole 64-byte lines with non-temporal stores, the
// rows whose lines do not start with a lane block through a carry of the previous block's entries (StreamRows,
// derivative_ift.hpp), and the first and last blocks of a task range with masked stores. Every entry must still
// get the scalar set's bits, for any thread count (task ranges split the lines between threads) and for batch sizes
// whose rows are not a whole number of lines apart.
#include "batchcol/batchcol.hpp"
#include "support/derivative_reference.hpp"
#include "support/same_results.hpp"

#include <gtest/gtest.h>

#include <string>

namespace batchcol::testing {
namespace {

// `count` pairs cycling through `base`'s (random hulls are slow to build; the stores only need the count).
PairBatch repeated(const PairBatch& base, std::size_t count) {
  PairBatch out;
  out.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t k = i % base.size();
    out.add(base.shape_a[k], base.pose_a(k), base.shape_b[k], base.pose_b(k));
  }
  return out;
}

TEST(DerivativesStream, LargeOutputsGiveTheScalarBitsOnEverySetAndThreadCount) {
  if (vector_isas_here().empty()) GTEST_SKIP() << "no AVX2 or AVX-512 on this CPU: nothing to compare with scalar";
  Rng rng(29);
  ShapeTable shapes;
  const PairBatch hulls = random_separated_pairs(rng, shapes, {ShapeType::convex}, 300);
  const PairBatch ellipsoids = random_separated_pairs(rng, shapes, {ShapeType::ellipsoid}, 300);
  const PairBatch mixed = random_separated_pairs(rng, shapes, bounded_shape_types(), 300);
  // 2304 pairs write 2.2 MB (streamed: StoreBlock::kStreamBytes is 2 MiB); 2301 pairs put consecutive rows of an
  // array at different offsets in a line; the mixed batch interleaves lane blocks with per-pair ones.
  const PairBatch batches[] = {repeated(hulls, 2304), repeated(hulls, 2301), repeated(ellipsoids, 2301),
                               repeated(mixed, 2304)};
  int compared = 0;
  for (const PairBatch& batch : batches) {
    PairResults r;
    QueryOptions q;
    q.isa = InstructionSet::scalar;
    q.threads = 1;
    DerivativeResults reference;
    differentiate(shapes, batch, q, DerivativeOptions{}, r, reference);
    int solved = 0;
    for (const DerivativeStatus s : reference.status)
      solved += s == DerivativeStatus::smooth || s == DerivativeStatus::zero_curvature;
    EXPECT_GE(solved, int(batch.size() * 9 / 10));
    for (InstructionSet isa : vector_isas_here())
      for (int threads : {1, 2, 3}) {
        q.isa = isa;
        q.threads = threads;
        DerivativeResults d;
        differentiate(shapes, batch, q, DerivativeOptions{}, r, d);
        expect_same_derivatives(reference, d, std::string(to_string(isa)) + ", " + std::to_string(batch.size()) +
                                                  " pairs, threads " + std::to_string(threads));
        ++compared;
      }
  }
  EXPECT_GE(compared, 12);
}

}  // namespace
}  // namespace batchcol::testing
