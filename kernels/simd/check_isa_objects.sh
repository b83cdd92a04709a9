#!/bin/bash
# Guards the one-binary-runs-everywhere rule: in the AVX2 / AVX-512 objects, every function the linker could share
# with other objects (weak symbols outside the ISA's own namespace: inline code of the standard library, Eigen or
# the scalar kernels) must contain no AVX instruction; otherwise the linker may pick that copy for baseline code
# and crash a CPU without AVX. Usage: check_isa_objects.sh OBJECT... (arguments may be ;-separated CMake lists)
status=0
objects=()
for arg in "$@"; do IFS=';' read -ra parts <<< "$arg"; objects+=("${parts[@]}"); done
[ ${#objects[@]} -gt 0 ] || { echo "error: no object files given"; exit 1; }
for obj in "${objects[@]}"; do
  ns=$(basename "$obj" | sed -E 's/^isa_([a-z0-9]+)\.cpp\.o$/\1/')
  while read -r sym; do
    if objdump -d --no-show-raw-insn --disassemble="$sym" "$obj" | grep -qE '%[yz]mm|vfmadd|%k[0-7]'; then
      echo "error: $obj: shared symbol $(echo "$sym" | c++filt) contains AVX instructions"
      status=1
    fi
  done < <(nm "$obj" | awk '$2 == "W" || $2 == "V" {print $3}' | grep -v "simd${#ns}${ns}")
  echo "checked $obj ($ns)"
done
exit $status
