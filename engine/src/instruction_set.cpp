// Run-time choice of the instruction set: the CPU's best (kernels::simd::detected_instruction_set), lowered by the
// environment variable BATCHCOL_ISA, or an explicit request checked against the CPU.
#include "instruction_set.hpp"

#include "batchcol/batch.hpp"
#include "kernels/simd/wide_gjk.hpp"

#include <cstdlib>
#include <string>

namespace batchcol {
namespace detail {

InstructionSet capped_instruction_set(InstructionSet best, const char* cap) {
  if (cap == nullptr || *cap == '\0') return best;
  for (const InstructionSet isa : {InstructionSet::scalar, InstructionSet::avx2, InstructionSet::avx512})
    if (std::string(cap) == to_string(isa)) return static_cast<int>(isa) < static_cast<int>(best) ? isa : best;
  throw InputError("environment variable BATCHCOL_ISA='" + std::string(cap) +
                   "' names no instruction set (valid: scalar, avx2, avx512)");
}

}  // namespace detail

InstructionSet resolve_instruction_set(InstructionSet requested) {
  using kernels::simd::cpu_has;
  // The CPU and the environment are read once per process (the first call), not on every collide().
  static const InstructionSet detected = kernels::simd::detected_instruction_set();
  if (requested == InstructionSet::automatic) {
    static const InstructionSet chosen = detail::capped_instruction_set(detected, std::getenv("BATCHCOL_ISA"));
    return chosen;
  }
  if (static_cast<int>(requested) > static_cast<int>(detected))
    throw InputError(std::string("instruction set ") + to_string(requested) + " is not supported by this CPU (best: " +
                     to_string(detected) + ")");
  return requested;
}

}  // namespace batchcol
