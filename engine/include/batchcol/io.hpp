// Batch files (JSON), mesh files and result output. Every function here validates its input completely before
// returning and throws InputError with a message naming the file, the field (JSON pointer such as
// /pairs/3/pose_a/quaternion) and, for parse errors, the line.
#pragma once

#include "batchcol/export.hpp"

#include "batchcol/batch.hpp"
#include "batchcol/rays.hpp"
#include "batchcol/shapes.hpp"

#include <iosfwd>
#include <optional>
#include <string>

namespace batchcol {

/// Everything a batch file holds. The optional top-level settings are applied by apply_to(); command-line flags
/// override them.
struct BatchFile {
  ShapeTable shapes;
  PairBatch pairs;
  /// "rays": [{"shape": i, "pose": {...}, "origin": [x, y, z], "direction": [x, y, z], "t_max": t}] (pose optional:
  /// identity; t_max optional: +inf; a zero direction or negative t_max is an InputError naming the ray). With
  /// "rays", "pairs" may be left out. `batchcol rays --batch FILE` casts them (cast_rays()).
  ShapeRayBatch rays;
  /// A ray scene: "objects": [{"shape": i, "pose": {...}}] (pose optional: identity) are placed in a Scene in this
  /// order (object k gets slot k), and the file's "rays" are then scene rays, cast against all objects:
  /// [{"origin": [x, y, z], "direction": [x, y, z], "t_max": t}] without "shape" or "pose" (they go to scene_rays,
  /// and `rays` stays empty). `batchcol rays --scene FILE` casts them (RaySceneIndex). A file without "objects"
  /// whose rays lack "shape", or one with "objects" whose rays have it, is an InputError naming the first such ray.
  struct Object {
    std::uint32_t shape = 0;
    Pose pose;
  };
  std::vector<Object> objects;
  bool has_objects = false;  // the file has an "objects" key (which may be an empty array)
  RayBatch scene_rays;
  std::optional<QueryLevel> query;
  std::optional<Solver> solver;
  std::optional<double> tolerance;
  std::optional<Precision> precision;
  std::optional<double> margin;

  void apply_to(QueryOptions& options) const;
};

/// Reads a batch file; mesh paths inside it are relative to the file's folder.
BATCHCOL_API BatchFile load_batch_file(const std::string& path);
/// Parses batch-file text; `source` names it in messages and `base_dir` resolves mesh paths.
BATCHCOL_API BatchFile parse_batch_json(const std::string& text, const std::string& source, const std::string& base_dir);

/// Loads a mesh file (OBJ, STL, PLY, COLLADA, ... through assimp) and returns its vertices.
BATCHCOL_API std::vector<Eigen::Vector3d> load_mesh_points(const std::string& path);

BATCHCOL_API QueryLevel parse_query_level(const std::string& name);  // throws InputError on an unknown name
BATCHCOL_API Solver parse_solver(const std::string& name);
BATCHCOL_API Precision parse_precision(const std::string& name);
BATCHCOL_API InstructionSet parse_instruction_set(const std::string& name);

/// Result rows: pair,status,collide,distance,pa_x,pa_y,pa_z,pb_x,pb_y,pb_z,n_x,n_y,n_z,iterations.
/// Values the query level did not compute are empty (CSV) or null (JSON). Numbers use 17 significant digits.
/// With `derivatives` (same size), the derivative columns follow (d_status, g_a0.., dpa_da_00.., see
/// results_output.cpp).
struct DerivativeResults;
BATCHCOL_API void write_results_csv(const PairResults& results, std::ostream& out, const DerivativeResults* derivatives = nullptr);
BATCHCOL_API void write_results_json(const PairResults& results, std::ostream& out, const DerivativeResults* derivatives = nullptr);

}  // namespace batchcol
