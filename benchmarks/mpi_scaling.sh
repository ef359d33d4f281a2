#!/usr/bin/env bash
# Strong scaling of the quadrilateral path from one to two MPI processes.
#
#   benchmarks/mpi_scaling.sh [path/to/membranes] [output-dir]
#
# Defaults: build/membranes of this repository and
# /tmp/membranes-mpi-scaling. Runs case M (parameters/case-m-quadrilateral.prm,
# Q1, p4est mesh) under global refinement with nested iteration, 10 cycles:
# 2·(2^(k+2)+1)² DoFs on cycle k, 8 396 802 on the last, first on one
# process, then on two (mpiexec -n 2), CG-AMG, no field output. The same
# binary and the same scene, one after the other in one run of this script.
# Neither run is bound to cores (--bind-to none): by default Open MPI binds
# a process to one core when it starts one or two, and membranes then takes
# one thread; unbound, the single process uses every core with its threads,
# the two processes one each.
#
# The table of benchmarks/mpi_scaling_table.py is printed at the end and kept
# in <output-dir>/table.md: per phase of the last cycle the wall time on one
# and two processes, the speed-up and the parallel efficiency, the peak
# memory per DoF (report.csv's memory_mb, summed over the processes), and
# the check that both runs computed the same thing (DoFs, active vertices,
# energy error). The exit status is that script's.
# CYCLES=n in the environment shortens the run for a quick try.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
membranes=${1:-$root/build/membranes}
out=${2:-/tmp/membranes-mpi-scaling}
cycles=${CYCLES:-10}
scene=$root/parameters/case-m-quadrilateral.prm

if [[ ! -x $membranes ]]; then
  echo "mpi_scaling.sh: error: '$membranes' is not an executable" >&2
  exit 1
fi
mkdir -p "$out"
# Open MPI refuses to run as root without these.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

for processes in 1 2; do
  command=(mpiexec -n "$processes" --bind-to none "$membranes"
           --set "Refinement/Cycles=$cycles"
           --set "Solver/Linear solver=cg-amg"
           --set "Output/Write vtu=false"
           --set "Output/Directory=$out/np$processes"
           "$scene")
  rm -f "$out/np$processes/report.csv"
  echo "== $processes process(es): ${command[*]}"
  "${command[@]}" 2>&1 | tee "$out/np$processes.log"
done

/usr/bin/env python3 "$root/benchmarks/mpi_scaling_table.py" \
  "$out/np1/report.csv" "$out/np2/report.csv" | tee "$out/table.md"
