#!/usr/bin/env bash
# What the error columns cost: the last cycle of case M with no error
# column, the default columns of `Exact solution/Norms`, and all eight.
#
#   benchmarks/error_columns.sh [path/to/membranes] [output-dir]
#
# Defaults: build/membranes of this repository and
# /tmp/membranes-error-columns. Case M under global refinement, CG-AMG, no
# VTU output, on Q1 (parameters/case-m-quadrilateral.prm) with each choice
# of columns and on P1 (parameters/case-m-triangle.prm) with all eight;
# the variants run in turn, ROUNDS times (default 3), and the table gives
# the medians of the last cycle's wall_time_s (the method), time_errors_s
# and memory_mb (peak resident memory of the run), and memory_mb per DoF.
# CYCLES=n (default 8: 526 338 DoFs; 9: 2 101 250) and ROUNDS=n in the
# environment choose the size and the number of runs.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
membranes=${1:-$root/build/membranes}
out=${2:-/tmp/membranes-error-columns}
cycles=${CYCLES:-8}
rounds=${ROUNDS:-3}

if [[ ! -x $membranes ]]; then
  echo "error_columns.sh: error: '$membranes' is not an executable" >&2
  exit 1
fi
mkdir -p "$out"

default_norms="err_u1_H1, err_u2_H1, err_u1_L2, err_u2_L2, err_energy, err_lambda_L2, err_lambda_L2_omega_h"
# name | scene | arguments
variants=(
  "q1-none|case-m-quadrilateral|--set|Exact solution/Known=false"
  "q1-default|case-m-quadrilateral|--set|Exact solution/Norms=$default_norms"
  "q1-all|case-m-quadrilateral"
  "p1-all|case-m-triangle"
)

for round in $(seq 1 "$rounds"); do
  for variant in "${variants[@]}"; do
    IFS='|' read -r -a fields <<<"$variant"
    name=${fields[0]}
    scene=$root/parameters/${fields[1]}.prm
    directory=$out/$name-$round
    echo "== round $round of $rounds: $name"
    "$membranes" --set "Refinement/Cycles=$cycles" \
      --set "Solver/Linear solver=cg-amg" --set "Output/Write vtu=false" \
      --set "Output/Directory=$directory" "${fields[@]:2}" "$scene" \
      >"$directory.log" 2>&1
  done
done

python3 - "$out" "$rounds" <<'EOF'
import csv
import statistics
import sys

out, rounds = sys.argv[1], int(sys.argv[2])
labels = {"q1-none": ("case M, Q1", "none"),
          "q1-default": ("", "the default"),
          "q1-all": ("", "all eight"),
          "p1-all": ("case M, P1", "all eight")}
print("| scene | columns | DoFs | `wall_time_s` | `time_errors_s` | `memory_mb` | bytes per DoF |")
print("|---|---|--:|--:|--:|--:|--:|")
for name, (scene, columns) in labels.items():
    rows = [list(csv.DictReader(open(f"{out}/{name}-{r}/report.csv")))[-1]
            for r in range(1, rounds + 1)]
    median = lambda key: statistics.median(float(row[key]) for row in rows)
    dofs = int(rows[0]["dofs"])
    errors = f"{median('time_errors_s'):.2f}" if "time_errors_s" in rows[0] \
        and rows[0]["time_errors_s"] else "–"
    memory = median("memory_mb")
    grouped = lambda value: f"{value:,.0f}".replace(",", " ")
    print(f"| {scene} | {columns} | {grouped(dofs)} | "
          f"{median('wall_time_s'):.2f} | {errors} | {grouped(memory)} | "
          f"{memory * 2**20 / dofs:.0f} |")
EOF
