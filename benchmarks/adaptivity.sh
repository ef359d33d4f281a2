#!/usr/bin/env bash
# Adaptive against uniform refinement on the L-shape (parameters/lshape.prm).
#
#   benchmarks/adaptivity.sh [path/to/membranes] [output-dir]
#
# Defaults: build/membranes of this repository and /tmp/membranes-adaptivity.
# Four runs of the scene, one after the other, all with no VTU output:
#
#   q1-adaptive/  quadrilaterals, the scene as it is (bulk marking), 18 cycles:
#                 about 3·10⁵ DoFs on the last;
#   q1-uniform/   quadrilaterals, Refinement/Strategy = global, 8 cycles:
#                 130, 450, 1666, 6402, 25090, 99330, 395266, 1576962 DoFs;
#   p1-adaptive/  triangles, the scene's adaptive refinement, 15 cycles:
#                 about 3·10⁵ DoFs on the last;
#   p1-uniform/   triangles, global refinement, 7 cycles: 450, 1666, 6402,
#                 25090, 99330, 395266, 1576962 DoFs (the initial triangle
#                 mesh has the vertices of the quadrilateral mesh one level
#                 finer).
#
# The progress output of each run is kept in <output-dir>/NAME.log. The tables
# of benchmarks/adaptivity_table.py are printed at the end and kept in
# <output-dir>/table.md; the exit status is that script's (1 if a target is
# missed). QUICK=1 in the environment runs fewer cycles, to try the script
# (the uniform runs then stop far below 10⁵ DoFs and the comparison means
# little).
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
membranes=${1:-$root/build/membranes}
out=${2:-/tmp/membranes-adaptivity}
scene=$root/parameters/lshape.prm

if [[ ${QUICK:-0} == 1 ]]; then
  q1_adaptive=10 q1_uniform=4 p1_adaptive=8 p1_uniform=3
else
  q1_adaptive=18 q1_uniform=8 p1_adaptive=15 p1_uniform=7
fi

if [[ ! -x $membranes ]]; then
  echo "adaptivity.sh: error: '$membranes' is not an executable" >&2
  exit 1
fi
mkdir -p "$out"

# run NAME ARGS...: run membranes on the scene with ARGS, output directory
# $out/NAME, progress on the terminal and in $out/NAME.log.
run() {
  local name=$1
  shift
  local command=("$membranes" --set "Output/Write vtu=false" "$@"
                 --set "Output/Directory=$out/$name" "$scene")
  rm -f "$out/$name/report.csv"
  echo "== $name: ${command[*]}"
  local start=$SECONDS
  "${command[@]}" 2>&1 | tee "$out/$name.log"
  echo "== $name: $((SECONDS - start)) s"
}

echo "== $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at start"
run q1-adaptive --set "Geometry/Cell type=quadrilateral" \
                --set "Refinement/Cycles=$q1_adaptive"
run q1-uniform  --set "Geometry/Cell type=quadrilateral" \
                --set "Refinement/Strategy=global" \
                --set "Refinement/Cycles=$q1_uniform"
run p1-adaptive --set "Geometry/Cell type=triangle" \
                --set "Refinement/Cycles=$p1_adaptive"
run p1-uniform  --set "Geometry/Cell type=triangle" \
                --set "Refinement/Strategy=global" \
                --set "Refinement/Cycles=$p1_uniform"
echo "== load average $(cut -d' ' -f1-3 /proc/loadavg) at end"
echo "== figure: /usr/bin/python3 $root/source/plot_report.py" \
     "--columns err_energy,estimator --output $out/convergence" \
     "'$out/q1-uniform/report.csv=Q1 uniform'" \
     "'$out/q1-adaptive/report.csv=Q1 adaptive'" \
     "'$out/p1-uniform/report.csv=P1 uniform'" \
     "'$out/p1-adaptive/report.csv=P1 adaptive'"
echo

python3 "$root/benchmarks/adaptivity_table.py" \
  Q1 "$out/q1-uniform/report.csv" "$out/q1-adaptive/report.csv" \
  P1 "$out/p1-uniform/report.csv" "$out/p1-adaptive/report.csv" |
  tee "$out/table.md"
