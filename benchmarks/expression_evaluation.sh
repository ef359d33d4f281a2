#!/usr/bin/env bash
# The share of a run's CPU time spent evaluating the scene's expressions,
# with the parser and compiled (Problem/Expression evaluation).
#
#   benchmarks/expression_evaluation.sh [path/to/membranes] [output-dir]
#
# Defaults: build/membranes of this repository and
# /tmp/membranes-expressions. Runs three scenes on P1 under global
# refinement, without VTU output, each with the parser and compiled, under
# `perf record` (flat profile, 999 samples per second):
#
#   degenerate  parameters/degenerate-free-boundary.prm, 7 cycles to
#               526 338 DoFs; with the parser
#               tests/scenes/degenerate-free-boundary-loads.prm (its loads
#               written out by hand), compiled the scene as it is (loads
#               derived, Laplacians by dual numbers);
#   case-m      parameters/case-m-triangle.prm, 7 cycles to 526 338 DoFs;
#   long        tests/scenes/shifted-circle-loads.prm, 7 cycles: long
#               expressions (powers, conditionals, cos), no gradient
#               entries (the parser differentiates u1, u2 by central
#               differences, compiled by dual numbers).
#
# The share of expression evaluation is that of the samples whose function
# is muparser's (libmuparser), deal.II's muparser callbacks, the compiled
# expressions (expressions-*.so), ProblemData's evaluation (Expression,
# its thread-local parsers, the lists of loads and of the exact solution
# with their checks), or libm and its vector forms libmvec (sin, cos,
# exp, pow: the program calls them from nowhere else in the hot loops). Also printed: the whole-process
# wall time, and the time of the first run of the compiled scene against a
# second one (compiling against the cache) with an empty cache directory.
# Needs perf (apt-get install linux-perf). CYCLES=n shortens the runs.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
membranes=${1:-$root/build/membranes}
out=${2:-/tmp/membranes-expressions}
cycles=${CYCLES:-7}

if ! command -v perf > /dev/null; then
  echo "expression_evaluation.sh: error: perf is missing; install it with 'apt-get install linux-perf'" >&2
  exit 1
fi
if [[ ! -x $membranes ]]; then
  echo "expression_evaluation.sh: error: '$membranes' is not an executable" >&2
  exit 1
fi
mkdir -p "$out"
export MEMBRANES_CACHE_DIR=$out/cache
rm -rf "$MEMBRANES_CACHE_DIR"

# share NAME: the percentage of expression evaluation in $out/NAME.data.
share() {
  perf report -i "$out/$1.data" --no-children --sort dso,symbol --stdio \
    2> /dev/null |
    awk '/^ +[0-9.]+%/ {
           p = $1; sub("%", "", p);
           if ($0 ~ /libmuparser|expressions-[0-9a-f]+\.so|libm\.so|libmvec\.so|ProblemData<2>::|ExpressionEntry<2>|ThreadParsers|FunctionParser::mu_/)
             s += p
         }
         END { printf "%.1f", s }'
}

# run NAME EVALUATION SCENE [ARGS...]: one run under perf.
run() {
  local name=$1 evaluation=$2 scene=$3
  shift 3
  echo "== $name ($evaluation)" >&2
  /usr/bin/time -f "%e" -o "$out/$name-$evaluation.time" \
    nice perf record -q -F 999 -o "$out/$name-$evaluation.data" -- \
    "$membranes" --set "Problem/Expression evaluation=$evaluation" \
    --set "Refinement/Cycles=$cycles" --set "Output/Write vtu=false" \
    --set "Output/Directory=$out/$name-$evaluation" "$@" "$scene" \
    > "$out/$name-$evaluation.log"
}

# Compiling once, then from the cache (the long scene, not yet compiled).
for attempt in first second; do
  /usr/bin/time -f "%e" -o "$out/compile-$attempt.time" \
    "$membranes" --set Refinement/Cycles=1 --set "Output/Write vtu=false" \
    --set "Output/Directory=$out/compile-$attempt" \
    "$root/tests/scenes/shifted-circle-loads.prm" > /dev/null
done

run degenerate parser "$root/tests/scenes/degenerate-free-boundary-loads.prm"
run degenerate compiled "$root/parameters/degenerate-free-boundary.prm"
run case-m parser "$root/parameters/case-m-triangle.prm"
run case-m compiled "$root/parameters/case-m-triangle.prm"
run long parser "$root/tests/scenes/shifted-circle-loads.prm"
run long compiled "$root/tests/scenes/shifted-circle-loads.prm"

{
  echo "| scene | evaluation | expression evaluation [% of CPU samples] | whole process [s] |"
  echo "|---|---|--:|--:|"
  for name in degenerate case-m long; do
    for evaluation in parser compiled; do
      echo "| $name | $evaluation | $(share "$name-$evaluation") | $(cat "$out/$name-$evaluation.time") |"
    done
  done
  echo
  echo "One cycle of the long scene with an empty cache: $(cat "$out/compile-first.time") s;" \
       "again, from the cache: $(cat "$out/compile-second.time") s."
} | tee "$out/table.md"
