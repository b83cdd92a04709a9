// Shared steps of the derivative entry points (derivatives.cpp, derivative_smoothed0.cpp).
#pragma once

#include "batchcol/derivatives.hpp"
#include "derivative_ift.hpp"
#include "derivative_polytope_add.hpp"
#include "derivative_smoothed1.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cstddef>
#include <cstdint>

namespace batchcol::detail {

/// Runs body(begin, end) over [0, n) on `threads` threads (0 = all). Each index is independent, so the result does
/// not depend on the split.
template <class Body> void for_pairs(int threads, std::size_t n, const Body& body) {
  const auto run = [&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256),
                      [&](const tbb::blocked_range<std::size_t>& r) { body(r.begin(), r.end()); });
  };
  if (threads <= 0 || threads == tbb::this_task_arena::max_concurrency()) {
    run();
  } else {
    tbb::task_arena arena(threads);
    arena.execute(run);
  }
}

/// True when pair i has a converged witness query between two shapes with support maps (no halfspace); fills the
/// witness points, normal and signed distance of `g` and the rotations.
bool nominal_geometry(const ShapeTable& shapes, const PairBatch& batch, const PairResults& results, std::size_t i,
                      PairGeometry& g, Eigen::Matrix3d& R_a, Eigen::Matrix3d& R_b);

/// rows[e] = where entry e of pair `first` lives in d's arrays (StoreEntries of them, in the output arrays' order:
/// the two 6-vectors, then 18 per matrix; entry e of an array is its SoA index k of data[k * n + i]). Flushing
/// StoreBlock and smoothed0's FinishLanes write a block of consecutive pairs from rows[e][0 .. count).
void entry_rows(DerivativeResults& d, std::size_t first, double** rows);

/// Collects the derivatives of up to 8 consecutive pairs in a structure-of-arrays buffer (entry e of slot j at
/// buf_[e][j], in the order of the output arrays: distance_gradient_a/b (6 each), then witness_a_wrt_a,
/// witness_a_wrt_b, witness_b_wrt_a, witness_b_wrt_b, normal_wrt_a, normal_wrt_b (18 each, row-major)) and writes
/// them array by array: each of the 120 SoA arrays then gets one whole cache line per flush. Writing pair by pair
/// touched 120 lines per pair, which for a power-of-two batch size (arrays a multiple of 4 KB apart) all fall in
/// one L1 set: 4.5x a witness query in wall time for 1.6x in instructions (4096 ellipsoid pairs, 1 thread). The
/// buffer is filled in place (slot()) rather than through a PairJacobians copy and a member-pointer walk, which
/// cost ~1100 instructions per pair. Flushes when a pair is not the next one, when the block is full (AVX-512: at
/// limit_) and on destruction; one block per task range.
class StoreBlock {
 public:
  static constexpr int kEntries = StoreEntries;
  static constexpr std::size_t kStride = SmoothLanes::kLanes;  // slot entries are kStride doubles apart
  /// Outputs of at least this many bytes (2 MiB: ~2200 pairs) are written with non-temporal stores on AVX-512.
  static constexpr std::size_t kStreamBytes = std::size_t(2) << 20;
  explicit StoreBlock(DerivativeResults& d) : d(d) {}
  StoreBlock(const StoreBlock&) = delete;
  StoreBlock& operator=(const StoreBlock&) = delete;
  ~StoreBlock() {
    flush();
    if (!stream_) return;
    if (stream_rows_.carried) flush_stream_carry(stream_rows_, rows_, last_at_);
    __builtin_ia32_sfence();  // the non-temporal stores are weakly ordered: visible before the task ends
  }
  /// The slot of pair i (entry e at slot[e * kStride]); every entry must be written before the next call.
  double* slot(std::size_t i) {
    // (An empty block flushes as a no-op and then starts at i; limit_ is 0 until the first block.)
    if (count_ == limit_ || i != first_ + count_) start(i);
    return &buf_[0][count_++];
  }
  void add(std::size_t i, const PairJacobians& J);
  /// Queues pair i (smooth_pair(g)) for the block's SIMD solve at the flush.
  void add_smooth(std::size_t i, const PairGeometry& g, const CurvedSide* curved_a = nullptr,
                  const CurvedSide* curved_b = nullptr) {
    slot(i);
    smooth_.add(count_ - 1, g, curved_a, curved_b);
  }
  /// Queues smoothed1 pair i (smooth_pair(g); g's H_a, H_b are not read) for the block's SmoothLanes, its world
  /// curvatures R psd_projection(S) R^T computed at the flush for the block's pairs together (Smoothed1Lanes).
  void add_smoothed1(std::size_t i, const PairGeometry& g, const Eigen::Matrix3d& S_a, const Eigen::Matrix3d& S_b,
                     const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
    slot(i);
    const std::size_t l = smooth_.count;
    smooth_.add_given(count_ - 1, g);
    smoothed1_.set(l, S_a, S_b, R_a, R_b);
  }
  /// Queues pair i (polytope_pair(g)) for the block's PolytopeLanes; returns null, or pair i's slot to be written by
  /// the caller when its flats are dependent (no lane taken). Forced inline, with PolytopeLanes::add()
  /// (derivative_polytope_add.hpp).
  __attribute__((always_inline)) double* add_polytope(std::size_t i, const PairGeometry& g) {
    double* s = slot(i);
    return polytope_.add(count_ - 1, g) ? nullptr : s;
  }
  void flush();

  DerivativeResults& d;
  /// Smooth pairs write normal_wrt_b only (the smoothed0 samples' predictor reads nothing else); the other pairs
  /// still write all their entries.
  bool normal_b_only = false;
  /// The set whose registers solve whole blocks (SmoothLanes / PolytopeLanes::solve()); the same bits on every set.
  InstructionSet isa = InstructionSet::scalar;

 private:
  // Not zeroed (a 7.7 KB fill per task range, 3.75 instructions per pair at 256 pairs a range, callgrind AVX2): every
  // slot handed out has all its entries written before the flush reads them, except the rows normal_b_only skips,
  // which the flush then does not copy (analytic_normal_b()'s caller reads only normal_wrt_b's rows).
  alignas(64) double buf_[kEntries][kStride];
  // entry_rows(d, 0): the output arrays' rows of pair 0, computed in start() (d is sized by then and not
  // resized during the block's life); a block of pairs from first_ is at rows_[e] + first_. With the 120 pointers
  // rebuilt at every flush, flush() was 98.5 instructions per analytic hull pair; now it is inlined in its caller,
  // whose count did not move, and the lanes' `+ first_` costs 15 (callgrind, AVX2).
  double* rows_[kEntries];
  bool have_rows_ = false;
  // AVX-512 (aligned_): blocks end where the next 64-byte line of most output rows starts (phase_: their offset
  // in a line at pair 0, in doubles), so that a whole block stores whole lines of those rows, the others through
  // StreamRows' carry. Large outputs (stream_) are written in whole lines with non-temporal stores (start()).
  bool aligned_ = false, stream_ = false;
  std::size_t phase_ = 0;
  std::size_t limit_ = 0;    // the pairs of the current block (up to kStride)
  std::size_t last_at_ = 0;  // the first pair of the last streamed block (stream_rows_.carried)
  StreamRows stream_rows_;
  /// Flushes, starts a block at pair i (the first call sets rows_, aligned_, phase_ and the stream rows).
  void start(std::size_t i);
  SmoothLanes smooth_{};  // value-initialised: an unused register half is computed (not written) on initialised numbers
  PolytopeLanes polytope_{};
  Smoothed1Lanes smoothed1_{};  // smoothed1: the pending curvatures of smooth_'s lanes
  std::size_t first_ = 0, count_ = 0;
};

/// Stores one pair's Jacobians.
inline void store(StoreBlock& out, std::size_t i, const PairJacobians& J) { out.add(i, J); }

/// Stores NaN everywhere for pair i (the smoothed values too when present) and status no_witness.
void store_nothing(StoreBlock& out, std::size_t i);

/// Sizes `d` for n pairs (the smoothed arrays only when `smoothed`) without filling it: the callers write every
/// entry of every pair (store() or store_nothing()), so a reused result is not written twice.
void size_for(DerivativeResults& d, std::size_t n, bool smoothed);

/// The analytic derivatives as differentiate_results() computes them, for the smoothed0 samples' first-order start:
/// statuses and normal_wrt_b are those bits; the smooth pairs (SmoothLanes) write no other entry, the rest may.
/// `isa` (resolved) is the query's, so that a query pinned to an instruction set runs that set's lanes here too.
void analytic_normal_b(const ShapeTable& shapes, const PairBatch& batch, const PairResults& results,
                       const DerivativeOptions& analytic, int threads, InstructionSet isa,
                       DerivativeResults& derivatives);

/// The 0th-order estimator (derivative_smoothed0.cpp); `results` holds the unperturbed query.
void smoothed0(const ShapeTable& shapes, const PairBatch& batch, const QueryOptions& query,
               const DerivativeOptions& options, const PairResults& results, DerivativeResults& derivatives);

}  // namespace batchcol::detail
