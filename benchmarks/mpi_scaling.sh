#!/usr/bin/env bash
# Strong scaling from one to two MPI processes, Q1 beside P1.
#
#   benchmarks/mpi_scaling.sh [path/to/membranes] [output-dir]
#
# Defaults: build/membranes of this repository and
# /tmp/membranes-mpi-scaling. Runs case M under global refinement with
# nested iteration, 9 cycles, on quadrilaterals
# (parameters/case-m-quadrilateral.prm, Q1, the p4est mesh) and on
# triangles (parameters/case-m-triangle.prm, P1, the mesh on every process
# in a parallel::shared::Triangulation): both have 526 338 DoFs on the
# next-to-last cycle and 2 101 250 on the last. Each scene first on one
# process, then on two (mpiexec -n 2), CG-AMG, no field output; the same
# binary, one run after the other.
# Neither run is bound to cores (--bind-to none): by default Open MPI binds
# a process to one core when it starts one or two, and membranes then takes
# one thread; unbound, the single process uses every core with its threads,
# the two processes one each.
#
# The table of benchmarks/mpi_scaling_table.py is printed at the end and kept
# in <output-dir>/table.md: for the last two cycles of each cell type, the
# wall time per phase on one and two processes and the speed-up, the peak
# memory per process, the memory that the second process adds per cell,
# and the check that both runs computed the same thing (DoFs, active
# vertices, energy error). The exit status is that script's.
# CYCLES=n in the environment shortens the run for a quick try.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
membranes=${1:-$root/build/membranes}
out=${2:-/tmp/membranes-mpi-scaling}
cycles=${CYCLES:-9}

if [[ ! -x $membranes ]]; then
  echo "mpi_scaling.sh: error: '$membranes' is not an executable" >&2
  exit 1
fi
# Open MPI refuses to run as root without these.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

reports=()
for cell_type in quadrilateral triangle; do
  scene=$root/parameters/case-m-$cell_type.prm
  for processes in 1 2; do
    dir=$out/$cell_type/np$processes
    command=(mpiexec -n "$processes" --bind-to none "$membranes"
             --set "Refinement/Cycles=$cycles"
             --set "Solver/Linear solver=cg-amg"
             --set "Output/Write vtu=false"
             --set "Output/Directory=$dir"
             "$scene")
    mkdir -p "$dir"
    rm -f "$dir/report.csv"
    echo "== $cell_type, $processes process(es): ${command[*]}"
    "${command[@]}" 2>&1 | tee "$out/$cell_type-np$processes.log"
  done
  reports+=("$cell_type" "$out/$cell_type/np1/report.csv"
            "$out/$cell_type/np2/report.csv")
done

/usr/bin/env python3 "$root/benchmarks/mpi_scaling_table.py" "${reports[@]}" |
  tee "$out/table.md"
exit "${PIPESTATUS[0]}"
