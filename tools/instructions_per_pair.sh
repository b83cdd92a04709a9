#!/bin/bash
# Instructions per pair of the timed collide() calls, per function, from callgrind: `batchcol bench` is run with
# --runs RUNS and --runs 5 on one thread (one call per run: --min-run-ms 0) and the difference is divided by
# (RUNS - 5) x PAIRS (pair generation, the reference and the warm-up cancel out). Wall time on a shared 2-core VM is
# too noisy to compare kernels; this is not.
# usage: [PAIRS=20000] [RUNS=45] [REGIME=close] tools/instructions_per_pair.sh BATCHCOL_BINARY CASE [QUERY=boolean] [PRECISION=double]
#        [ISA=auto]      (PAIRS=4000 RUNS=15: ~10x faster, box-cylinder boolean double 2208 vs 2222 with the defaults)
set -euo pipefail
bin=$1; case_name=$2; query=${3:-boolean}; precision=${4:-double}; isa=${5:-auto}; pairs=${PAIRS:-20000}; high=${RUNS:-45}
command -v valgrind >/dev/null || { echo "needs valgrind (apt-get install valgrind)" >&2; exit 2; }
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
(( high > 5 )) || { echo "RUNS must be > 5" >&2; exit 2; }
for runs in 5 $high; do
  valgrind --tool=callgrind --callgrind-out-file="$work/cg$runs" "$bin" bench --case "$case_name" --regime "${REGIME:-close}" \
    --query "$query" --precision "$precision" --pairs $pairs --threads 1 --no-peers --isa "$isa" --runs $runs --min-run-ms 0 \
    >/dev/null 2>&1
  callgrind_annotate --inclusive=no --auto=no "$work/cg$runs" 2>/dev/null | grep -E "^ *[0-9,]+ \(" |
    sed -E 's/,//g; s/^ *([0-9]+) +\( *[0-9.]+%\) +/\1\t/' > "$work/f$runs"
done
python3 - "$work/f5" "$work/f$high" $(((high - 5) * pairs)) <<'PY'
import sys
def read(path):
    out = {}
    for line in open(path):
        count, name = line.rstrip('\n').split('\t', 1)
        out[name.strip()] = int(count)
    return out
low, high, pairs = read(sys.argv[1]), read(sys.argv[2]), int(sys.argv[3])
rows = sorted(((v - low.get(k, 0)) / pairs, k) for k, v in high.items() if not k.startswith('PROGRAM'))[::-1]
print("total %.0f instructions per pair" % sum(r for r, _ in rows))
for per_pair, name in rows[:15]:
    if per_pair >= 0.5: print("%8.1f  %s" % (per_pair, name[:140]))
PY
