#!/usr/bin/env bash
# Cost of the active set method against one linear solve.
#
#   benchmarks/solver_cost.sh [path/to/membranes] [output-dir]
#
# Defaults: build/membranes of this repository and /tmp/membranes-benchmark.
# Runs case M (parameters/case-m-quadrilateral.prm) on Q1 under global
# refinement up to more than 2·10⁶ DoFs, twice, with CG-AMG and no VTU output:
#
#   contact/    the scene as it is (Solver/Method = auto, the default):
#               active set method, errors computed;
#   nocontact/  the same meshes and the coupled (u1, u2) system
#               (Solver/Method = coupled) with membrane 2 clamped one unit
#               lower (Problem/g2 = -1), so that u1 - u2 >= 0.68 everywhere,
#               the active set stays empty and each cycle is one linear
#               solve of the unconstrained system: the yardstick.
#
# Peak memory (maximum resident set size) of each run is taken from
# /usr/bin/time -v, or, where that program is missing, from
# getrusage(RUSAGE_CHILDREN) in Python. Both read the kernel's accounting of
# the finished process, so no sampling is involved.
#
# The table of benchmarks/solver_cost_table.py is printed at the end and kept
# in <output-dir>/table.md; the exit status is that script's (1 if a target is
# missed or the no-contact run is not one linear solve per cycle).
# CYCLES=n in the environment shortens the run for a quick try;
# STOPPING=balanced runs the contact scene with Solver/Stopping = balanced
# (the yardstick stays one exact linear solve).
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
membranes=${1:-$root/build/membranes}
out=${2:-/tmp/membranes-benchmark}
# Initial refinement 2: 50 DoFs on cycle 0, 2·(2^(k+2)+1)² on cycle k, so
# cycle 8, the last of 9, has 2 101 250 DoFs.
cycles=${CYCLES:-9}
scene=$root/parameters/case-m-quadrilateral.prm

if [[ ! -x $membranes ]]; then
  echo "solver_cost.sh: error: '$membranes' is not an executable" >&2
  exit 1
fi
mkdir -p "$out"

common=(--set "Output/Write vtu=false"
        --set "Solver/Linear solver=cg-amg"
        --set "Refinement/Cycles=$cycles")

# run_measured NAME ARGS...: run membranes with ARGS, output directory
# $out/NAME, progress on the terminal and in $out/NAME.log, peak resident
# set size in KiB in $out/NAME.peak_rss_kib.
run_measured() {
  local name=$1
  shift
  local command=("$membranes" "${common[@]}" "$@"
                 --set "Output/Directory=$out/$name" "$scene")
  rm -f "$out/$name/report.csv"
  echo "== $name: ${command[*]}"
  if [[ -x /usr/bin/time ]]; then
    /usr/bin/time -v -o "$out/$name.time" "${command[@]}" 2>&1 |
      tee "$out/$name.log"
    awk -F': ' '/Maximum resident set size/ {print $2}' "$out/$name.time" \
      >"$out/$name.peak_rss_kib"
  else
    python3 -c '
import resource, subprocess, sys
status = subprocess.call(sys.argv[2:])
with open(sys.argv[1], "w") as f:
    print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, file=f)
sys.exit(status)' "$out/$name.peak_rss_kib" "${command[@]}" 2>&1 |
      tee "$out/$name.log"
  fi
}

echo "== $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at start"
run_measured contact --set "Solver/Stopping=${STOPPING:-exact}"
run_measured nocontact --set "Problem/g2=-1" --set "Exact solution/Known=false" \
  --set "Solver/Method=coupled"
echo "== load average $(cut -d' ' -f1-3 /proc/loadavg) at end"
echo "== peak memory without contact: $(($(cat "$out/nocontact.peak_rss_kib") / 1024)) MiB"
echo

python3 "$root/benchmarks/solver_cost_table.py" \
  "$out/contact/report.csv" "$out/nocontact/report.csv" \
  "$(cat "$out/contact.peak_rss_kib")" | tee "$out/table.md"
