// Lowercase names of the public enums, used by batch files, the CLI and result output.
#include "batchcol/batch.hpp"
#include "batchcol/io.hpp"
#include "batchcol/shapes.hpp"

#include <string>

namespace batchcol {
namespace {

// Looks `name` up in `names` (indexed by enumerator value); throws InputError listing the valid names.
template <typename Enum, std::size_t N>
Enum parse_enum(const std::string& name, const char* const (&names)[N], const char* what) {
  for (std::size_t i = 0; i < N; ++i) {
    if (name == names[i]) return static_cast<Enum>(i);
  }
  std::string valid;
  for (std::size_t i = 0; i < N; ++i) valid += (i ? ", " : "") + std::string(names[i]);
  throw InputError("unknown " + std::string(what) + " '" + name + "' (valid: " + valid + ")");
}

template <typename Enum, std::size_t N>
const char* name_of(Enum value, const char* const (&names)[N]) {
  const auto i = static_cast<std::size_t>(value);
  return i < N ? names[i] : "unknown";
}

// Same order as the enumerators.
constexpr const char* kShapeTypeNames[] = {"sphere", "capsule", "box",    "cylinder", "cone",
                                           "ellipsoid", "convex", "triangle", "halfspace"};
constexpr const char* kQueryLevelNames[] = {"boolean", "distance", "witness", "penetration"};
constexpr const char* kSolverNames[] = {"gjk", "nesterov", "polyak", "automatic"};
constexpr const char* kPrecisionNames[] = {"double", "float"};
constexpr const char* kStatusNames[] = {"converged", "max_iterations", "degenerate", "invalid_input"};
constexpr const char* kInstructionSetNames[] = {"automatic", "scalar", "avx2", "avx512"};

static_assert(sizeof(kShapeTypeNames) / sizeof(kShapeTypeNames[0]) == kShapeTypeCount);

}  // namespace

const char* to_string(ShapeType type) { return name_of(type, kShapeTypeNames); }
const char* to_string(QueryLevel level) { return name_of(level, kQueryLevelNames); }
const char* to_string(Solver solver) { return name_of(solver, kSolverNames); }
const char* to_string(Precision precision) { return name_of(precision, kPrecisionNames); }
const char* to_string(Status status) { return name_of(status, kStatusNames); }
const char* to_string(InstructionSet isa) { return name_of(isa, kInstructionSetNames); }

QueryLevel parse_query_level(const std::string& name) {
  return parse_enum<QueryLevel>(name, kQueryLevelNames, "query level");
}
Solver parse_solver(const std::string& name) { return parse_enum<Solver>(name, kSolverNames, "solver"); }
Precision parse_precision(const std::string& name) {
  return parse_enum<Precision>(name, kPrecisionNames, "precision");
}
InstructionSet parse_instruction_set(const std::string& name) {
  return parse_enum<InstructionSet>(name, kInstructionSetNames, "instruction set");
}

}  // namespace batchcol
