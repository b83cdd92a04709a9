// Plain types shared by every layer, in the spirit of Box2D's id.h: enums, limits, option structs and raw views,
// no Eigen, no shape model, no containers, so that the low layers (broadphase/, kernels/) can include this header
// and nothing else of the public API. Their CMake targets see only this file, errors.hpp and export.hpp of
// batchcol/ (broadphase/CMakeLists.txt, kernels/CMakeLists.txt): including anything else from engine/include or
// engine/src fails to compile there. The public headers (shapes.hpp, pose.hpp, batch.hpp) include this one, so a
// user sees every name below where it always was.
#pragma once

#include <cstdint>

namespace batchcol {

// ---- limits (README "Input limits") ----

/// Input limits, chosen so that no product of four lengths, the highest power the kernels form (|x|^2 of a cross
/// product, squared norms of products), overflows or underflows: in double every shape length (radius, half length,
/// half extent, convex or triangle coordinate, inflation, halfspace offset) is at most kMaxLength and every size at
/// least kMinLength, and pose translations are at most kMaxLength per component (beyond it a pair is
/// Status::invalid_input). Measured: uniformly scaled problems are answered right from 1e-70 to 1e70 in double and
/// fail from 1e+-80; the limits keep 20 orders of magnitude of room for mixed scales.
constexpr double kMaxLength = 1e50;
constexpr double kMinLength = 1e-50;
/// Precision::float32 computes in float: sizes and bounding radii of every shape of the table within
/// [kMinLengthFloat, kMaxLengthFloat] (else collide() throws InputError), and the translation between the two
/// shapes of a pair at most kMaxLengthFloat per component (else the pair is Status::invalid_input). Measured:
/// right from 1e-9 to 1e9, wrong from 1e+-10 (float overflows at 3.4e38 = (4.3e9)^4); 3 orders of room.
constexpr double kMaxLengthFloat = 1e6;
constexpr double kMinLengthFloat = 1e-6;
/// Quaternions and rotation matrices within this of unit norm / orthonormality are normalised; beyond it they are
/// rejected as input errors (a typo, not rounding).
constexpr double kUnitTolerance = 1e-6;
/// Upper bound on QueryOptions::threads (validate() rejects more). Fixed rather than derived from the machine so a
/// setting that validates on one machine validates on every other; 1024 is above the hardware threads of today's
/// largest two-socket servers (oversubscribing beyond them cannot speed anything up), while oneTBB allocates a slot
/// per requested thread at arena creation (~0.6 KB each: 10^6 threads took 619 MB, 10^7 crashed inside TBB).
constexpr int kMaxThreads = 1024;

// ---- shapes ----

enum class ShapeType : std::uint8_t { sphere, capsule, box, cylinder, cone, ellipsoid, convex, triangle, halfspace };
constexpr int kShapeTypeCount = 9;

/// Cells per cube-face side of ConvexHull::start_vertices (kernels/hull_support.inl, start_cell).
constexpr std::uint32_t kHullStartGrid = 32;
constexpr std::uint32_t kHullStartCells = 6 * kHullStartGrid * kHullStartGrid;
constexpr std::uint32_t kNoHullVertex = 0xffffffffu;
/// Flag of a ConvexHull::start_vertices entry: the cell is inside the vertex's normal cone (every direction of the
/// cell, widened by a rounding margin, has that vertex as its only maximiser), so a support in a direction of the
/// cell is the vertex itself, without a climb. The vertex index is the entry without the flag.
constexpr std::uint32_t kHullPureCell = 0x80000000u;
/// Most candidates a cell of ConvexHull::cell_candidates lists (more: the cell has no list, its supports climb).
/// 15 is what the entry's 4-bit count holds; see build_cell_candidates() for the numbers behind the choice.
constexpr std::uint32_t kHullCellCandidatesMax = 15;
/// Neighbours per block of ConvexHull::neighbor_block_xyz (ConvexHull::kNeighborBlock).
constexpr std::uint32_t kHullNeighborBlock = 4;

/// A ConvexHull's arrays as raw pointers and counts: what the kernels read of a hull (support, rays). It owns
/// nothing: the engine builds it from a ConvexHull (engine/src/shape_views.hpp), whose arrays must outlive it.
/// Vectors are 3 consecutive doubles (x, y, z), faces 3 consecutive vertex indices; the fields mean what the
/// ConvexHull fields of the same names mean (batchcol/shapes.hpp). Optional arrays are null when the hull has none.
struct HullView {
  const double* vertices = nullptr;  // 3 vertex_count
  std::uint32_t vertex_count = 0;
  std::uint32_t face_count = 0;
  const std::uint32_t* faces = nullptr;     // 3 face_count, counter-clockwise seen from outside
  const double* face_normals = nullptr;     // 3 face_count, unit, outward
  const std::uint32_t* start_vertices = nullptr;  // kHullStartCells entries, or null
  const std::uint32_t* cell_candidates = nullptr;  // ConvexHull::cell_candidates, or null
  const float* vertex_floats = nullptr;            // ConvexHull::vertex_floats (3 vertex_count), or null
  /// Adjacency in blocks of kHullNeighborBlock (null when the hull has none): vertex_count + 1 offsets, then the
  /// blocks' vertex indices and their coordinates (x of the block's vertices, then y, then z).
  const std::uint32_t* neighbor_block_offsets = nullptr;
  const std::uint32_t* neighbor_block_index = nullptr;
  const double* neighbor_block_xyz = nullptr;
  double centroid[3] = {0, 0, 0};
  double radius = 0.0;
};

/// One shape as plain values: what the kernels' one-pair paths read (the batch kernels read the ShapeTable's
/// per-shape arrays instead). The fields mean what Shape's do; `hull` points to the hull's view (convex only), which
/// must outlive every kernel structure built from this record.
struct ShapeView {
  ShapeType type = ShapeType::sphere;
  double size[3] = {0, 0, 0};
  double offset = 0.0;
  double inflation = 0.0;
  double bounding_radius = 0.0;  // Shape::bounding_radius()
  double triangle[3][3] = {};
  const HullView* hull = nullptr;
};

/// An axis-aligned box as six plain doubles: what the broad phase stores and checks. The public batchcol::Aabb
/// (shapes.hpp, Eigen vectors) has the same min[k] / max[k] access, so code written against either compiles for
/// both (broadphase::AabbSoa::set is a template over the box type for that reason).
struct PlainAabb {
  double min[3] = {0, 0, 0};
  double max[3] = {0, 0, 0};
};

// ---- queries ----

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
  automatic,  // the default: polyak for QueryLevel::boolean except plain_boolean_pays()'s pair types (gjk), gjk for
              // the other levels except momentum_pays()'s pair types (polyak); see resolve_solver
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
/// Distance / witness pair types where `automatic` runs polyak instead of gjk: an ellipsoid against an ellipsoid,
/// a cylinder, a cone or a convex hull. These pairs take Newton directions near the optimum
/// (kernels/gjk.hpp's newton_pair_type()); the heavy ball's first steps bring them into Newton's region sooner,
/// and Newton's first step ends the momentum. Measured (bench, close regime, 4000 pairs, double, gjk -> polyak):
/// witness mean iterations ellipsoid-ellipsoid 8.61 -> 6.58, cylinder-ellipsoid 15.41 -> 13.93, cone-ellipsoid
/// 15.59 -> 15.01, ellipsoid-convex8 13.54 -> 12.69; callgrind (AVX2) instructions per pair 5111 -> 3905,
/// 8140 -> 7305, 8367 -> 7837, 8731 -> 8367, with err_max below the 1e-8 tolerance (both solvers certify it by the
/// same duality gap along x) and not above gjk's on the bench's 20000 close pairs. Not capsule-ellipsoid (4064 ->
/// 3873 instructions, but err_max 9.84e-9 -> 9.92e-9 on those pairs), not sphere-ellipsoid (5.24 -> 5.10
/// iterations but 2421 -> 2455 instructions), not box-ellipsoid (8191 -> 8357), and not the pairs without an
/// ellipsoid, where polyak took more
/// iterations (box-cylinder 13.46 -> 14.62, cone-cone 15.51 -> 16.26, box-cone 11.45 -> 12.32) or as many
/// (cylinder-cylinder 17.25 -> 17.01 iterations, 7884 -> 7917 instructions). Hull-hull pairs gain too (convex940
/// 9483 -> 8652 instructions) but end on a rounded weight where gjk ends exactly (bench err_max 0 -> ~5e-18):
/// left on gjk.
constexpr bool momentum_pays(ShapeType a, ShapeType b) {
  const auto partner = [](ShapeType t) {
    return t == ShapeType::ellipsoid || t == ShapeType::cylinder || t == ShapeType::cone || t == ShapeType::convex;
  };
  return (a == ShapeType::ellipsoid && partner(b)) || (b == ShapeType::ellipsoid && partner(a));
}
/// Boolean pair types where `automatic` runs gjk instead of polyak: a capsule against a box, a cylinder or a cone,
/// a box against a cylinder or a cone, a cone against a cone (either order). On these the heavy ball's steps cost
/// iterations before the first certificate, and plain steps skip its per-iteration arithmetic. Measured (bench,
/// close regime, 20000 pairs, float, mean iterations polyak -> gjk): capsule-box 3.20 -> 2.76, capsule-cylinder
/// 2.91 -> 2.72, capsule-cone 3.03 -> 2.66, box-cylinder 5.41 -> 5.08, box-cone 5.34 -> 4.94, cone-cone 5.03 ->
/// 4.70 (collide_disagreements 0); see the commit for instructions per pair. Not the ellipsoid pairs,
/// cylinder-cylinder or cylinder-cone, where gjk took more (cylinder-cylinder 4.59 -> 5.18, box-ellipsoid 5.04 ->
/// 5.15, cylinder-cone 4.93 -> 5.01).
constexpr bool plain_boolean_pays(ShapeType a, ShapeType b) {
  const auto one_of = [&](ShapeType x, ShapeType y) { return (a == x && b == y) || (a == y && b == x); };
  return one_of(ShapeType::capsule, ShapeType::box) || one_of(ShapeType::capsule, ShapeType::cylinder) ||
         one_of(ShapeType::capsule, ShapeType::cone) || one_of(ShapeType::box, ShapeType::cylinder) ||
         one_of(ShapeType::box, ShapeType::cone) || one_of(ShapeType::cone, ShapeType::cone);
}
/// The solver `requested` runs as at `level` on a pair of types `a`, `b` (never `automatic`): resolve_solver()
/// with polyak for the distance / witness / penetration levels of momentum_pays()'s pair types, and gjk for the
/// boolean level of plain_boolean_pays()'s. Every path that
/// runs a pair as a query (the batch-array GJK, the per-pair path, the scalar solve) resolves with the pair's
/// types, so a pair's result does not depend on the path. (smoothed0's perturbed samples are not queries: they run
/// the level's solver, resolve_solver(requested, level), documented in the README's solver convention.)
inline Solver resolve_solver(Solver requested, QueryLevel level, ShapeType a, ShapeType b) {
  if (requested == Solver::automatic && level != QueryLevel::boolean && momentum_pays(a, b)) return Solver::polyak;
  if (requested == Solver::automatic && level == QueryLevel::boolean && plain_boolean_pays(a, b)) return Solver::gjk;
  return resolve_solver(requested, level);
}

enum class Precision : std::uint8_t { float64, float32 };

enum class Status : std::uint8_t {
  converged,       // the duality gap (or a closed form) certified the result to the tolerance, or to the
                   // arithmetic's limit when that is larger (GJK stalled: see kernels/narrowphase.cpp)
  max_iterations,  // the iteration budget ran out; the result is the last iterate
  degenerate,      // numerical breakdown (e.g. EPA on a flat Minkowski difference); collide is still valid
  invalid_input,   // bad pair (shape index out of range, non-finite or non-unit pose); nothing else computed
};

/// Instruction set of the narrow-phase kernels (one pair per SIMD lane). `automatic` = the best this CPU runs,
/// lowered to the environment variable BATCHCOL_ISA (scalar | avx2 | avx512) when that is set. All sets give
/// bitwise the same results (the wide kernels repeat the scalar reference's operations in the same order).
enum class InstructionSet : std::uint8_t { automatic, scalar, avx2, avx512 };

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

}  // namespace batchcol
