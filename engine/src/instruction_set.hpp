// The choice of the kernels' instruction set beyond what the CPU offers (kernels/simd/wide_gjk.hpp): the
// environment's cap. Internal: tests check it; resolve_instruction_set() (batchcol/batch.hpp) applies it.
#pragma once

#include "batchcol/types.hpp"

namespace batchcol::detail {

/// The automatic choice lowered by the value of BATCHCOL_ISA (`cap`: null or empty = no cap; a set above `best`
/// leaves `best`); InputError when `cap` names no set. resolve_instruction_set() applies it once per process.
InstructionSet capped_instruction_set(InstructionSet best, const char* cap);

}  // namespace batchcol::detail
