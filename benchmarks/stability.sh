#!/usr/bin/env bash
# The stability suite: stiff and extreme cases, one table.
#
#   benchmarks/stability.sh [path/to/membranes] [output-dir]
#
# Defaults: build/membranes of this repository and /tmp/membranes-stability.
# Runs each case below (Output/Write vtu = false, Solver/Tolerance = 1e-10,
# the scene's default), one after the other, into <output-dir>/NAME with
# its progress output in <output-dir>/NAME.log, then prints the table of
# benchmarks/stability_table.py (kept in <output-dir>/table.md). A run that
# stops with an error is a row with the program's message. The exit status
# is that script's: 1 if a case did not converge to a relative KKT residual
# <= 1e-10, or if a scaled case made other decisions than its unscaled one.
# QUICK=1 in the environment runs fewer cycles.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
membranes=${1:-$root/build/membranes}
out=${2:-/tmp/membranes-stability}
stability=$root/parameters/stability
quick=${QUICK:-0}

if [[ ! -x $membranes ]]; then
  echo "stability.sh: error: '$membranes' is not an executable" >&2
  exit 1
fi
mkdir -p "$out"

# cycles N M: N cycles, or M with QUICK=1.
cycles() { if [[ $quick == 1 ]]; then echo "$2"; else echo "$1"; fi; }

# run NAME SCENE [--set ...]...: one case; the list of cases in run order
# goes to $out/cases.
: >"$out/cases"
run() {
  local name=$1 scene=$2
  shift 2
  rm -rf "${out:?}/$name"
  echo "== $name"
  "$membranes" --set "Output/Write vtu=false" \
    --set "Output/Directory=$out/$name" "$@" "$scene" >"$out/$name.log" 2>&1 ||
    true
  tail -n 1 "$out/$name.log"
  echo "$name" >>"$out/cases"
}

m=$(cycles 7 4)
for ratio in 1e-8 1e-4 1 1e4 1e8; do
  run "mu1:mu2=$ratio" "$stability/case-m.prm" --set "Problem/mu1=$ratio" \
    --set "Problem/mu2=1" --set "Refinement/Cycles=$m"
done
# At the sizes of refinement studies, with CG-AMG from the first cycle:
# case M on Q1 to 2.1 million DoFs.
for ratio in 1e-8 1e8; do
  run "mu1:mu2=$ratio,cg-amg" "$stability/case-m.prm" \
    --set "Problem/mu1=$ratio" --set "Problem/mu2=1" \
    --set "Refinement/Cycles=$(cycles 9 5)" --set "Solver/Linear solver=cg-amg"
done
run "unscaled" "$stability/case-m.prm" --set "Refinement/Cycles=$m"
for scale in 1e-8 1e8; do
  run "loads,g*$scale" "$stability/case-m.prm" \
    --set "Problem/Function constants=R=0.5, S=$scale" \
    --set "Refinement/Cycles=$m"
  # (mu1, mu2) = (1, 2) times the scale.
  run "mu1,mu2*$scale" "$stability/case-m.prm" \
    --set "Problem/mu1=$scale" --set "Problem/mu2=2${scale#1}" \
    --set "Refinement/Cycles=$m"
done
run "g=0" "$stability/g-zero.prm" --set "Refinement/Cycles=$m"
run "contact everywhere" "$root/parameters/full-contact.prm" \
  --set "Refinement/Cycles=$m"
run "no contact" "$root/parameters/no-contact.prm" \
  --set "Refinement/Cycles=$m"
run "islands" "$stability/islands.prm" --set "Refinement/Cycles=$(cycles 8 5)"
run "graded" "$stability/graded.prm" --set "Refinement/Cycles=$(cycles 24 12)"
run "degenerate" "$stability/degenerate.prm" --set "Refinement/Cycles=$m"
run "degenerate*1e8" "$stability/degenerate.prm" \
  --set "Problem/Function constants=S=1e8" --set "Refinement/Cycles=$m"
# The degenerate straight free boundary (no strict complementarity), the
# hard class for the active set method, with CG-AMG from the first cycle:
# P1 to 526 338 DoFs at every tension ratio and data scale, Q1 to 2.1
# million DoFs, and the coupled method at the extreme ratios.
straight=$stability/degenerate-straight.prm
amg=(--set "Solver/Linear solver=cg-amg")
p1=(--set "Geometry/Cell type=triangle" --set "Refinement/Cycles=$(cycles 7 5)")
q1=(--set "Geometry/Cell type=quadrilateral" --set "Refinement/Cycles=$(cycles 9 6)")
for ratio in 1e-8 1e-4 1 1e4 1e8; do
  run "straight P1 mu1:mu2=$ratio" "$straight" "${amg[@]}" "${p1[@]}" \
    --set "Problem/mu1=$ratio"
done
for scale in 1e-8 1e8; do
  run "straight P1 data*$scale" "$straight" "${amg[@]}" "${p1[@]}" \
    --set "Problem/Function constants=x0=0.333333333333333333, L=8, S=$scale"
done
for ratio in 1e-8 1 1e8; do
  run "straight Q1 mu1:mu2=$ratio" "$straight" "${amg[@]}" "${q1[@]}" \
    --set "Problem/mu1=$ratio"
done
for ratio in 1e-8 1e8; do
  run "straight P1 coupled mu1:mu2=$ratio" "$straight" "${amg[@]}" "${p1[@]}" \
    --set "Problem/mu1=$ratio" --set "Solver/Method=coupled"
done
echo

python3 "$root/benchmarks/stability_table.py" "$out" | tee "$out/table.md"
