#!/usr/bin/env bash
# The floor of the setup of one case-M cycle: benchmarks/setup_floor.cc,
# run several times one after the other, and the medians of its tables.
#
#   benchmarks/setup_floor.sh [path/to/setup_floor] [output-dir]
#
# Defaults: build/setup_floor of this repository (made by
# `cmake --build build --target setup_floor`) and /tmp/membranes-setup-floor.
# RUNS=n in the environment sets the number of runs (default 3),
# CELL=triangle the mesh of triangles of membranes' `Cell type = triangle`
# instead of quadrilaterals (CELL=quadrilateral, the default),
# REFINEMENTS=k the refinements of the previous mesh (default 9 on
# quadrilaterals: the measured cycle goes from 512 × 512 to 1024 × 1024
# cells; 7 on triangles: from 131 072 to 524 288 triangles), COUPLING=full
# the sparsity pattern of the coupled system instead of the mesh's
# operator (COUPLING=components, the default), TRIM=1 the memory freed in
# each step given back to the system before the resident set is read (the
# current resident set is then what the process holds; the times are
# longer). Each run's
# tables are kept in <output-dir>/run<i>.md, the medians in medians.md.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
program=${1:-$root/build/setup_floor}
out=${2:-/tmp/membranes-setup-floor}
runs=${RUNS:-3}
cell=${CELL:-quadrilateral}
if [[ $cell == triangle ]]; then
  refinements=${REFINEMENTS:-7}
else
  refinements=${REFINEMENTS:-9}
fi

if [[ ! -x $program ]]; then
  echo "setup_floor.sh: error: '$program' is not an executable" >&2
  exit 1
fi
mkdir -p "$out"
rm -f "$out"/run*.md

echo "== $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at start"
for ((run = 1; run <= runs; ++run)); do
  echo "== run $run"
  nice "$program" "$cell" "$refinements" "${COUPLING:-components}" \
    ${TRIM:+trim} | tee "$out/run$run.md"
done
echo "== load average $(cut -d' ' -f1-3 /proc/loadavg) at end"
echo "== medians of $runs runs"

# The tables of the first run with every number replaced by the median of
# that cell over the runs.
python3 "$root/benchmarks/median_tables.py" "$out"/run*.md | tee "$out/medians.md"
