// Pair batches (structure of arrays), query options and per-pair results.
//
// Conventions (all results): witness points are in the world frame; the normal is a unit vector pointing from
// shape a to shape b; the signed distance is negative when the shapes overlap (its magnitude is the penetration
// depth, computed only at QueryLevel::penetration). Every pair satisfies witness_b - witness_a = distance * normal.
// Arrays of values a query level does not compute are left empty by collide(): `distance` below
// QueryLevel::distance, `witness_a`, `witness_b` and `normal` below QueryLevel::witness (a boolean query on a million
// pairs writes 30 MB of results, not 110). Inside a computed array, pairs without a value (overlapping pairs'
// distance below penetration, invalid input) hold NaN; the CLI prints NaN and missing arrays as empty fields.
#pragma once

#include "batchcol/export.hpp"

#include "batchcol/errors.hpp"
#include "batchcol/pose.hpp"
#include "batchcol/shapes.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace batchcol {

/// What to compute per pair; each level includes the previous ones and costs more.
enum class QueryLevel : std::uint8_t {
  boolean,      // collide only; stops as soon as a separating plane (or an overlap) is proven
  distance,     // + signed distance for separated pairs; overlapping pairs get it only where it costs no EPA
                //   (closed forms, inflated shapes whose cores are apart), else NaN
  witness,      // + witness points and normal wherever the distance is known
  penetration,  // + EPA depth, normal and witness points for overlapping pairs
};

enum class Solver : std::uint8_t {
  gjk,        // GJK = fully-corrective Frank-Wolfe on the Minkowski difference
  nesterov,   // Nesterov-accelerated GJK (Montaut et al. 2022), falls back to gjk when momentum stalls
  polyak,     // heavy-ball (Polyak) momentum on the support direction, same fallback
  automatic,  // the default: polyak for QueryLevel::boolean, gjk for the other levels (see resolve_solver)
};
/// The solver `requested` runs as at `level` (never `automatic`). Measured on the bench's GJK type pairs (25, 26)
/// (mean iterations, geometric mean over the pairs, relative to nesterov): boolean polyak 0.80 close / 0.98
/// overlap / 0.99 distant (gjk 0.85 / 0.96 / 1.02); distance and witness gjk 0.89 / 0.89 / 0.66 (polyak 0.95 /
/// 0.98 / 0.81), with the same worst-case error. Nesterov stays best on ellipsoid-ellipsoid witness in the close
/// regime (20.7 iterations against gjk's 28.3): ask for it by name there. Penetration was not measured: it takes
/// witness's choice for its GJK part.
inline Solver resolve_solver(Solver requested, QueryLevel level) {
  if (requested != Solver::automatic) return requested;
  return level == QueryLevel::boolean ? Solver::polyak : Solver::gjk;
}

enum class Precision : std::uint8_t { float64, float32 };

enum class Status : std::uint8_t {
  converged,       // the duality gap (or a closed form) certified the result to the tolerance, or to the
                   // arithmetic's limit when that is larger (GJK stalled: see kernels/narrowphase.cpp)
  max_iterations,  // the iteration budget ran out; the result is the last iterate
  degenerate,      // numerical breakdown (e.g. EPA on a flat Minkowski difference); collide is still valid
  invalid_input,   // bad pair (shape index out of range, non-finite or non-unit pose); nothing else computed
};

BATCHCOL_API const char* to_string(QueryLevel level);
BATCHCOL_API const char* to_string(Solver solver);
BATCHCOL_API const char* to_string(Precision precision);
BATCHCOL_API const char* to_string(Status status);

/// Instruction set of the narrow-phase kernels (one pair per SIMD lane). `automatic` = the best this CPU runs,
/// lowered to the environment variable BATCHCOL_ISA (scalar | avx2 | avx512) when that is set. All sets give
/// bitwise the same results (the wide kernels repeat the scalar reference's operations in the same order).
enum class InstructionSet : std::uint8_t { automatic, scalar, avx2, avx512 };
BATCHCOL_API const char* to_string(InstructionSet isa);
/// What `requested` runs as on this machine (never `automatic`); throws InputError for a set the CPU lacks.
BATCHCOL_API InstructionSet resolve_instruction_set(InstructionSet requested = InstructionSet::automatic);

/// Upper bound on QueryOptions::threads (validate() rejects more). Fixed rather than derived from the machine so a
/// setting that validates on one machine validates on every other; 1024 is above the hardware threads of today's
/// largest two-socket servers (oversubscribing beyond them cannot speed anything up), while oneTBB allocates a slot
/// per requested thread at arena creation (~0.6 KB each: 10^6 threads took 619 MB, 10^7 crashed inside TBB).
constexpr int kMaxThreads = 1024;

struct QueryOptions {
  QueryLevel level = QueryLevel::witness;
  Solver solver = Solver::automatic;
  Precision precision = Precision::float64;
  /// Absolute bound on the distance error in metres, certified by the Frank-Wolfe duality gap:
  /// GJK stops when (|x|^2 - <x, s>) / |x| <= max(tolerance, relative_tolerance * |x|). The tolerance is raised
  /// to the precision floor 16 eps (bounding radii + centre distance): ~1e-15 m in double, ~1e-6 m in float for
  /// 0.5 m problems. EPA stops when its depth bounds are within the same tolerance.
  double tolerance = 1e-8;
  double relative_tolerance = 0.0;
  /// Security margin: a pair collides when its distance is <= margin (boolean queries stop once that is decided).
  /// collide is conservative: false only when a separating plane beyond the margin is certified (GJK's lower bound
  /// > margin), while `distance` is GJK's upper estimate. A converged pair may therefore report collide = 1 with a
  /// distance above the margin by at most the effective tolerance max(tolerance, relative_tolerance * distance,
  /// precision floor); collide = 0 always comes with a distance above the margin.
  double margin = 0.0;
  int max_iterations = 128;       // GJK iterations per pair
  int epa_max_iterations = 1000;  // EPA expansions per pair (near-concentric curved pairs need hundreds)
  bool closed_forms = true;       // analytic kernels for sphere/capsule pairs, sphere against cylinder or cone,
                                  // sphere-box, box-box boolean (halfspace pairs always use their closed form:
                                  // they have no support function)
  int threads = 0;                // 0 = all cores, else 1..kMaxThreads
  InstructionSet isa = InstructionSet::automatic;
};
/// Which kernel answers pairs of these two shapes under `options`: "closed form" (analytic: in SIMD lanes straight
/// from the batch arrays for sphere/capsule pairs, sphere-cylinder, sphere-cone and box-box boolean, per pair
/// otherwise) or "gjk" (the SIMD GJK,
/// one pair per lane; EPA runs scalar on the overlapping pairs that asked for depth).
BATCHCOL_API const char* kernel_for(const Shape& a, const Shape& b, const QueryOptions& options);

/// A batch of pairs in structure-of-arrays layout. `warm_start`, when not empty, holds one support direction per
/// pair (world frame, e.g. the `direction` output of the previous frame) used to start GJK.
struct BATCHCOL_API PairBatch {
  std::vector<std::uint32_t> shape_a, shape_b;
  Vec3Array translation_a, translation_b;
  QuatArray rotation_a, rotation_b;
  Vec3Array warm_start;

  std::size_t size() const { return shape_a.size(); }
  void reserve(std::size_t n);
  /// Appends a pair and returns its index.
  std::size_t add(std::uint32_t a, const Pose& pose_a, std::uint32_t b, const Pose& pose_b);
  Pose pose_a(std::size_t i) const { return {translation_a[i], rotation_a[i]}; }
  Pose pose_b(std::size_t i) const { return {translation_b[i], rotation_b[i]}; }
};

/// A pair batch whose arrays are owned by the caller (NumPy arrays, memory-mapped files): the same layout as
/// PairBatch, viewed instead of copied. Each component array must hold size() entries (warm_start may be empty) and
/// stay unchanged until collide() returns.
struct BATCHCOL_API PairBatchView {
  ConstSpan<std::uint32_t> shape_a, shape_b;
  Vec3View translation_a, translation_b;
  QuatView rotation_a, rotation_b;
  Vec3View warm_start;

  std::size_t size() const { return shape_a.size(); }
  static PairBatchView of(const PairBatch& batch);
};

/// Per-pair results in input order (structure of arrays).
struct BATCHCOL_API PairResults {
  std::vector<Status> status;
  std::vector<std::uint8_t> collide;
  std::vector<double> distance;           // empty below QueryLevel::distance
  Vec3Array witness_a, witness_b, normal;  // empty below QueryLevel::witness
  Vec3Array direction;  // final support direction (world frame); feed it back as PairBatch::warm_start
  std::vector<std::int32_t> iterations;  // GJK iterations plus EPA expansions

  std::size_t size() const { return status.size(); }
  /// n pairs of defaults (invalid_input, NaN), with the arrays `level` computes (collide() sizes them so itself).
  void resize(std::size_t n, QueryLevel level = QueryLevel::penetration);
};

/// Runs every pair of `batch` against `shapes`. Per-pair problems become Status::invalid_input; the function
/// throws InputError only for problems with the call itself (mismatched array sizes, invalid options).
/// Results are bitwise identical for any thread count.
BATCHCOL_API void collide(const ShapeTable& shapes, const PairBatch& batch, const QueryOptions& options, PairResults& results);
/// The same on caller-owned arrays (bitwise the same results as on a PairBatch holding the same values). Throws
/// InputError when the view's arrays have different lengths or a non-empty one has no data pointer.
BATCHCOL_API void collide(const ShapeTable& shapes, const PairBatchView& batch, const QueryOptions& options, PairResults& results);

/// Throws InputError naming the option when `options` is invalid (non-finite or negative tolerance, ...).
BATCHCOL_API void validate(const QueryOptions& options);

}  // namespace batchcol
