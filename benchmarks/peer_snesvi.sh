#!/usr/bin/env bash
# membranes against a peer: FEniCSx with PETSc's SNES VI solver.
#
#   benchmarks/peer_snesvi.sh [path/to/membranes] [output-dir]
#
# Defaults: build/membranes of this repository and /tmp/membranes-peer.
# Solves parameters/degenerate-free-boundary.prm, or another scene (SCENE,
# below), (P1, global refinement, 7 cycles from 162 to 526 338 DoFs) twice,
# one run after the other:
#
#   peer       benchmarks/peer_snesvi.py: FEniCSx 0.5 (python3-dolfinx),
#              the same vertex grids and DoF counts, SNES vinewtonrsls with
#              a MUMPS LU per Newton step, nested iteration;
#   membranes  the scene as it is (primal-dual active set method, nested
#              iteration), without VTU output.
#
# Before the measured peer run, one untimed run on the first level fills the
# FFCx cache with the compiled forms, so the measurement holds no form
# compilation (a user pays it once).
#
# Each run is made under /usr/bin/time for its whole-process wall time, CPU
# time and peak resident set size; the progress output is kept in
# <output-dir>/peer.log and membranes.log. The table of
# `peer_snesvi.py --table` (per level: DoFs, iterations, wall time of the
# level, H1 and L2 errors of both solvers; then the whole-process times and
# their ratio) is printed at the end and kept in <output-dir>/table.md; the
# exit status is 1 if the two runs do not have the same DoFs on every level.
# LEVELS=n in the environment shortens both runs to n levels.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
membranes=${1:-$root/build/membranes}
out=${2:-/tmp/membranes-peer}
levels=${LEVELS:-7}
peer=$root/benchmarks/peer_snesvi.py
# The interpreter of Debian's python3-dolfinx.
python=/usr/bin/python3
# SCENE=degenerate (default), shifted-circle or ellipse; EVALUATION=auto
# (default), compiled or parser: membranes' Problem/Expression evaluation.
# With the parser, the degenerate scene is tests/scenes/degenerate-free-
# boundary-loads.prm (its data written out). The shifted circle is always
# tests/scenes/shifted-circle-loads.prm (long expressions as written by hand,
# mu1 = 1, mu2 = 2). The ellipse is tests/scenes/ellipse-contact.prm: contact
# inside an ellipse off the centre, u2 = sin(pi x) sin(pi y), a cubic gap
# and an action vanishing quadratically at the free boundary (data written
# out, mu1 = mu2 = 1).
peer_scene=${SCENE:-degenerate}
evaluation=${EVALUATION:-auto}
case $peer_scene in
  degenerate)
    scene=$root/parameters/degenerate-free-boundary.prm
    [[ $evaluation == parser ]] &&
      scene=$root/tests/scenes/degenerate-free-boundary-loads.prm
    tensions=(--mu1 1 --mu2 1) ;;
  shifted-circle)
    scene=$root/tests/scenes/shifted-circle-loads.prm
    tensions=(--mu1 1 --mu2 2) ;;
  ellipse)
    scene=$root/tests/scenes/ellipse-contact.prm
    tensions=(--mu1 1 --mu2 1) ;;
  *)
    echo "peer_snesvi.sh: error: SCENE=$peer_scene is not degenerate, shifted-circle or ellipse" >&2
    exit 1 ;;
esac

if ! $python -c 'import dolfinx' 2>/dev/null; then
  echo "peer_snesvi.sh: error: $python cannot import dolfinx; install it with 'apt-get install python3-dolfinx'" >&2
  exit 1
fi
if [[ ! -x $membranes ]]; then
  echo "peer_snesvi.sh: error: '$membranes' is not an executable" >&2
  exit 1
fi
if [[ ! -x /usr/bin/time ]]; then
  echo "peer_snesvi.sh: error: /usr/bin/time is missing; install it with 'apt-get install time'" >&2
  exit 1
fi
mkdir -p "$out"

# run_timed NAME COMMAND...: run COMMAND, progress on the terminal and in
# $out/NAME.log, "wall_s user_s sys_s max_rss_kib" in $out/NAME.time.
run_timed() {
  local name=$1
  shift
  echo "== $name: $*"
  /usr/bin/time -f "%e %U %S %M" -o "$out/$name.time" "$@" 2>&1 |
    tee "$out/$name.log"
}

echo "== $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at start"
echo "== filling the FFCx cache (untimed)"
$python "$peer" --scene "$peer_scene" "${tensions[@]}" --levels 1 \
  --output "$out/cache.csv" >"$out/cache.log" 2>&1
rm -f "$out/peer.csv" "$out/membranes/report.csv"
run_timed peer $python "$peer" --scene "$peer_scene" "${tensions[@]}" \
  --levels "$levels" --output "$out/peer.csv"
run_timed membranes "$membranes" --set "Output/Write vtu=false" \
  --set "Problem/Expression evaluation=$evaluation" \
  --set "Output/Directory=$out/membranes" \
  --set "Refinement/Cycles=$levels" "$scene"
echo "== load average $(cut -d' ' -f1-3 /proc/loadavg) at end"
echo

$python "$peer" --table "$out/peer.csv" "$out/membranes/report.csv" \
  "$out/peer.time" "$out/membranes.time" | tee "$out/table.md"
