#!/usr/bin/env bash
# The quadrature error of the error norms: every err_* column of
# report.csv against the same run with the composite reference rule
# (`Exact solution/Reference quadrature`: each sub-triangle of the dual
# mesh cut into 4^N triangles, 4 points on each).
#
#   benchmarks/error_quadrature.sh [path/to/membranes] [output-dir]
#
# Defaults: build/membranes of this repository and
# /tmp/membranes-error-quadrature. Case M on P1 and on Q1 (6 cycles,
# uniform), the full-contact scene, and case M P1 with adaptive refinement
# (10 cycles), each with the program's rule and with the reference N = 4;
# case M P1 and Q1 also with N = 5, to check the reference. Then two
# solutions singular at a vertex, refined adaptively, with N = 4 and 5: the
# L-shape (13 cycles) and the slit (8 cycles, Minimum growth = 2.5).
# REFERENCE in the environment names another program for the reference runs
# (the same discrete solutions; e.g. to measure a program without the
# parameter). Runs one after the other (about 10 minutes on two cores), then
# prints (and keeps in <output-dir>/table.md) the tables of
# benchmarks/error_quadrature_table.py.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
membranes=${1:-$root/build/membranes}
out=${2:-/tmp/membranes-error-quadrature}
reference=${REFERENCE:-$membranes}

for program in "$membranes" "$reference"; do
  if [[ ! -x $program ]]; then
    echo "error_quadrature.sh: error: '$program' is not an executable" >&2
    exit 1
  fi
done
mkdir -p "$out"

# run NAME PROGRAM [--set ...] SCENE: one run into <output-dir>/NAME.
run() {
  local name=$1 program=$2 start=$SECONDS
  shift 2
  rm -f "$out/$name/report.csv"
  "$program" --set "Output/Write vtu=false" --set "Output/Directory=$out/$name" \
    "$@" >"$out/$name.log" 2>&1
  echo "== $name: $((SECONDS - start)) s"
}

runs=()
for scene in case-m-p1 case-m-q1 full-contact case-m-p1-adaptive \
  lshape-adaptive slit-adaptive; do
  case $scene in
  case-m-p1) options=("$root/parameters/case-m-triangle.prm") ;;
  case-m-q1) options=("$root/parameters/case-m-quadrilateral.prm") ;;
  full-contact) options=("$root/parameters/full-contact.prm") ;;
  case-m-p1-adaptive)
    options=(--set Refinement/Strategy=adaptive --set Refinement/Cycles=10
      "$root/parameters/case-m-triangle.prm")
    ;;
  lshape-adaptive)
    options=(--set Refinement/Cycles=13 "$root/parameters/lshape.prm")
    ;;
  slit-adaptive)
    options=(--set Refinement/Cycles=8 --set "Refinement/Minimum growth=2.5"
      "$root/parameters/slit.prm")
    ;;
  esac
  levels=(4 5)
  [[ $scene == full-contact || $scene == case-m-p1-adaptive ]] && levels=(4)
  run "$scene" "$membranes" "${options[@]}"
  for n in "${levels[@]}"; do
    run "$scene-reference-$n" "$reference" \
      --set "Exact solution/Reference quadrature=$n" "${options[@]}"
  done
  runs+=("$out/$scene")
done
python3 "$root/benchmarks/error_quadrature_table.py" "${runs[@]}" |
  tee "$out/table.md"
