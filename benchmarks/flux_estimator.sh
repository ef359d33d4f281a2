#!/usr/bin/env bash
# The flux reconstruction and the flux estimator against the residual one.
#
#   benchmarks/flux_estimator.sh [path/to/membranes] [output-dir]
#
# Defaults: build/membranes of this repository and /tmp/membranes-flux.
# Runs, one after the other, all with Output/Flux reconstruction = true and
# no VTU output:
#
#   case-m-q1, case-m-p1      case M on the square, uniform, 6 cycles;
#   lshape-q1, lshape-p1      the L-shape, uniform, 6 and 5 cycles;
#   lshape-q1-adaptive-flux,  the L-shape refined by the flux estimator,
#   lshape-p1-adaptive-flux   16 and 13 cycles.
#
# and prints (and keeps in <output-dir>/table.md) the table of
# benchmarks/flux_estimator_table.py: effectivity of both estimators, the
# defects of the identities, and the share of the flux reconstruction and
# flux estimator in the wall time of a cycle. Exit status 1 if a target is
# missed.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
membranes=${1:-$root/build/membranes}
out=${2:-/tmp/membranes-flux}

if [[ ! -x $membranes ]]; then
  echo "flux_estimator.sh: error: '$membranes' is not an executable" >&2
  exit 1
fi
mkdir -p "$out"

# run NAME SCENE ARGS...: run membranes on SCENE with ARGS into $out/NAME.
run() {
  local name=$1 scene=$2
  shift 2
  rm -f "$out/$name/report.csv"
  echo "== $name"
  local start=$SECONDS
  "$membranes" --set "Output/Write vtu=false" \
    --set "Output/Flux reconstruction=true" "$@" \
    --set "Output/Directory=$out/$name" "$root/parameters/$scene" \
    > "$out/$name.log" 2>&1
  echo "== $name: $((SECONDS - start)) s"
}

echo "== $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at start"
run case-m-q1 case-m-quadrilateral.prm --set "Refinement/Cycles=6"
run case-m-p1 case-m-triangle.prm --set "Refinement/Cycles=6"
for cell in q1 p1; do
  type=quadrilateral cycles=6 adaptive_cycles=16
  if [[ $cell == p1 ]]; then
    type=triangle cycles=5 adaptive_cycles=13
  fi
  run lshape-$cell lshape.prm --set "Geometry/Cell type=$type" \
    --set "Refinement/Strategy=global" --set "Refinement/Cycles=$cycles"
  run lshape-$cell-adaptive-flux lshape.prm \
    --set "Geometry/Cell type=$type" --set "Refinement/Estimator=flux" \
    --set "Refinement/Cycles=$adaptive_cycles"
done
echo "== load average $(cut -d' ' -f1-3 /proc/loadavg) at end"
echo

names=(case-m-q1 case-m-p1 lshape-q1 lshape-p1 lshape-q1-adaptive-flux
       lshape-p1-adaptive-flux)
python3 "$root/benchmarks/flux_estimator_table.py" \
  "${names[@]/#/$out/}" | tee "$out/table.md"
