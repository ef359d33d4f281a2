#!/usr/bin/env bash
# Geometric multigrid (matrix-free or on level matrices) against the AMG of
# membranes: benchmarks/gmg_floor.cc, run several times one after the
# other, and the medians of its tables.
#
#   benchmarks/gmg_floor.sh [path/to/gmg_floor] [output-dir] [arguments...]
#
# Defaults: build/gmg_floor of this repository (made by
# `cmake --build build --target gmg_floor`), /tmp/membranes-gmg-floor and
# the arguments `s gmg 10` (the Poisson problem on 1024 × 1024 cells with
# the V-cycle; see the head of gmg_floor.cc for the others). RUNS=n in the
# environment sets the number of runs (default 3), PROCESSES=n runs each
# on n MPI processes (default 1). Each run's tables are kept in
# <output-dir>/run<i>.md, the medians in medians.md.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
program=${1:-$root/build/gmg_floor}
out=${2:-/tmp/membranes-gmg-floor}
shift $(($# < 2 ? $# : 2))
arguments=("$@")
if [[ ${#arguments[@]} -eq 0 ]]; then
  arguments=(s gmg 10)
fi
runs=${RUNS:-3}
processes=${PROCESSES:-1}

if [[ ! -x $program ]]; then
  echo "gmg_floor.sh: error: '$program' is not an executable" >&2
  exit 1
fi
mkdir -p "$out"
rm -f "$out"/run*.md

echo "== $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at start"
echo "== gmg_floor ${arguments[*]} on $processes process(es)"
for ((run = 1; run <= runs; ++run)); do
  echo "== run $run"
  if [[ $processes -gt 1 ]]; then
    nice mpiexec -n "$processes" "$program" "${arguments[@]}" |
      tee "$out/run$run.md"
  else
    nice "$program" "${arguments[@]}" | tee "$out/run$run.md"
  fi
done
echo "== load average $(cut -d' ' -f1-3 /proc/loadavg) at end"
echo "== medians of $runs runs"

# The tables of the first run with every number replaced by the median of
# that cell over the runs.
python3 "$root/benchmarks/median_tables.py" "$out"/run*.md | tee "$out/medians.md"
