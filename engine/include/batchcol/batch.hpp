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
#include "batchcol/types.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace batchcol {

// QueryLevel, Solver (and resolve_solver), Precision, Status, InstructionSet, QueryOptions and kMaxThreads are plain
// types shared with the kernels: batchcol/types.hpp.

BATCHCOL_API const char* to_string(QueryLevel level);
BATCHCOL_API const char* to_string(Solver solver);
BATCHCOL_API const char* to_string(Precision precision);
BATCHCOL_API const char* to_string(Status status);

BATCHCOL_API const char* to_string(InstructionSet isa);
/// What `requested` runs as on this machine (never `automatic`); throws InputError for a set the CPU lacks.
BATCHCOL_API InstructionSet resolve_instruction_set(InstructionSet requested = InstructionSet::automatic);

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
