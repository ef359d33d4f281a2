#!/usr/bin/env bash
# Strong scaling from one to two MPI processes, Q1 beside P1 (and, with
# PROCESSES="1 2 3", memory on three and the memory model).
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
# vertices, energy error). The exit status is 1 if that script (or
# memory_model.py, below) fails or finds the runs in disagreement, else 0.
# CYCLES=n in the environment shortens the run for a quick try.
#
# PROCESSES="1 2 3" in the environment runs each scene on these process
# counts instead of "1 2" (the table above needs 1 and 2 among them). A count
# above the cores of the machine is started with --oversubscribe: on two
# cores, three processes share them, which makes them slow but leaves
# their memory as it is. With any count other than 1 and 2, the memory
# model of benchmarks/memory_model.py (bytes per process = a + b N/P + c N,
# fitted to every cycle of every run, and the largest N that P processes of
# M bytes each reach) follows the table and is kept in
# <output-dir>/memory-model.md. CELL_TYPES=quadrilateral (or triangle) runs
# one cell type alone, e.g. one cycle more (CYCLES=10, 8 396 802 DoFs) for
# Q1, whose three processes hold about 8 GB together where P1's would need
# twice that.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
membranes=${1:-$root/build/membranes}
out=${2:-/tmp/membranes-mpi-scaling}
cycles=${CYCLES:-9}
read -r -a process_counts <<< "${PROCESSES:-1 2}"
read -r -a cell_types <<< "${CELL_TYPES:-quadrilateral triangle}"
cores=$(nproc)

if [[ ! -x $membranes ]]; then
  echo "mpi_scaling.sh: error: '$membranes' is not an executable" >&2
  exit 1
fi
# Open MPI refuses to run as root without these.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

reports=()
model=()
for cell_type in "${cell_types[@]}"; do
  scene=$root/parameters/case-m-$cell_type.prm
  for processes in "${process_counts[@]}"; do
    dir=$out/$cell_type/np$processes
    oversubscribe=()
    if (( processes > cores )); then
      oversubscribe=(--oversubscribe)
    fi
    command=(mpiexec -n "$processes" "${oversubscribe[@]}" --bind-to none
             "$membranes"
             --set "Refinement/Cycles=$cycles"
             --set "Solver/Linear solver=cg-amg"
             --set "Output/Write vtu=false"
             --set "Output/Directory=$dir"
             "$scene")
    mkdir -p "$dir"
    rm -f "$dir/report.csv"
    echo "== $cell_type, $processes process(es): ${command[*]}"
    "${command[@]}" 2>&1 | tee "$out/$cell_type-np$processes.log"
    model+=("$cell_type=$dir/report.csv")
  done
  reports+=("$cell_type" "$out/$cell_type/np1/report.csv"
            "$out/$cell_type/np2/report.csv")
done

status=0
if [[ " ${process_counts[*]} " == *" 1 "* &&
      " ${process_counts[*]} " == *" 2 "* ]]; then
  if ! /usr/bin/env python3 "$root/benchmarks/mpi_scaling_table.py" \
         "${reports[@]}" | tee "$out/table.md"; then
    status=1
  fi
else
  echo "mpi_scaling.sh: no table (it compares 1 and 2 processes)"
fi
if [[ " ${process_counts[*]} " != " 1 2 " ]]; then
  echo
  if ! /usr/bin/env python3 "$root/benchmarks/memory_model.py" \
         "${model[@]}" | tee "$out/memory-model.md"; then
    status=1
  fi
fi
exit "$status"
