#!/usr/bin/env bash
# Adaptive against uniform refinement at equal energy error, on the L-shape
# (parameters/lshape.prm, r^(2/3) corner singularity) and the slit
# (parameters/slit.prm, r^(1/2) crack tip), Q1 and P1.
#
#   benchmarks/adaptivity.sh [path/to/membranes] [output-dir]
#
# Defaults: build/membranes of this repository and /tmp/membranes-adaptivity.
# Per scene and cell type, three runs one after the other, all with no VTU
# output:
#
#   <scene>-<q1|p1>-uniform/   Refinement/Strategy = global, up to the finest
#                              mesh that fits: L-shape 1 576 962 DoFs (Q1 8
#                              cycles, P1 7), slit 526 850 DoFs (Q1 7, P1 6);
#   <scene>-<q1|p1>-adaptive/  the scene's adaptive refinement (bulk marking,
#                              theta = 0.5), up to Max dofs (L-shape 4·10⁵,
#                              slit 2·10⁵), beyond the uniform error;
#   <scene>-<q1|p1>-growth/    the same with Refinement/Minimum growth = 2:
#                              larger steps, fewer cycles, to show what they
#                              do to the error per DoF and the cost per DoF.
#
# The progress output of each run is kept in <output-dir>/NAME.log. The tables
# of benchmarks/adaptivity_table.py are printed at the end and kept in
# <output-dir>/table.md; the exit status is that script's (1 if a target is
# missed). The figures of README.md (doc/images/lshape-convergence.png,
# doc/images/slit-convergence.png) are drawn from the Q1 and P1 uniform and
# adaptive runs into <output-dir>/<scene>-convergence.png. QUICK=1 in the
# environment runs small meshes only, to try the script (the comparison
# then means little).
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
membranes=${1:-$root/build/membranes}
out=${2:-/tmp/membranes-adaptivity}

if [[ ${QUICK:-0} == 1 ]]; then
  lshape_q1=4 lshape_p1=3 lshape_max=20000 slit_q1=4 slit_p1=3 slit_max=20000
else
  lshape_q1=8 lshape_p1=7 lshape_max=400000
  slit_q1=7 slit_p1=6 slit_max=200000
fi

if [[ ! -x $membranes ]]; then
  echo "adaptivity.sh: error: '$membranes' is not an executable" >&2
  exit 1
fi
mkdir -p "$out"

# run NAME SCENE ARGS...: run membranes on SCENE with ARGS, output directory
# $out/NAME, progress on the terminal and in $out/NAME.log.
run() {
  local name=$1 scene=$2
  shift 2
  local command=("$membranes" --set "Output/Write vtu=false" "$@"
                 --set "Output/Directory=$out/$name" "$root/parameters/$scene")
  rm -f "$out/$name/report.csv"
  echo "== $name: ${command[*]}"
  local start=$SECONDS
  "${command[@]}" 2>&1 | tee "$out/$name.log"
  echo "== $name: $((SECONDS - start)) s"
}

echo "== $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at start"
table_arguments=()
for scene in lshape slit; do
  for cell in q1 p1; do
    type=$([[ $cell == q1 ]] && echo quadrilateral || echo triangle)
    cycles_variable=${scene}_${cell} max_variable=${scene}_max
    run "$scene-$cell-uniform" "$scene.prm" \
        --set "Geometry/Cell type=$type" --set "Refinement/Strategy=global" \
        --set "Refinement/Cycles=${!cycles_variable}"
    run "$scene-$cell-adaptive" "$scene.prm" \
        --set "Geometry/Cell type=$type" --set "Refinement/Cycles=100" \
        --set "Refinement/Max dofs=${!max_variable}"
    run "$scene-$cell-growth" "$scene.prm" \
        --set "Geometry/Cell type=$type" --set "Refinement/Cycles=100" \
        --set "Refinement/Max dofs=${!max_variable}" \
        --set "Refinement/Minimum growth=2"
    # The targets: L-shape DoF ratio 0.15, time ratio 0.2; slit 1/20, 1/10.
    if [[ $scene == lshape ]]; then ratios=(0.15 0.2); else ratios=(0.05 0.1); fi
    label="$scene ${cell^^}"
    table_arguments+=("$label" "${ratios[@]}"
                      "$out/$scene-$cell-uniform/report.csv"
                      "$out/$scene-$cell-adaptive/report.csv"
                      "$out/$scene-$cell-growth/report.csv" --)
  done
  /usr/bin/python3 "$root/source/plot_report.py" \
    --columns err_energy,estimator --output "$out/$scene-convergence" \
    --title "$scene.prm: energy error and residual estimator" \
    "$out/$scene-q1-uniform/report.csv=Q1 uniform" \
    "$out/$scene-q1-adaptive/report.csv=Q1 adaptive" \
    "$out/$scene-p1-uniform/report.csv=P1 uniform" \
    "$out/$scene-p1-adaptive/report.csv=P1 adaptive"
done
echo "== load average $(cut -d' ' -f1-3 /proc/loadavg) at end"
echo

unset 'table_arguments[${#table_arguments[@]}-1]'
python3 "$root/benchmarks/adaptivity_table.py" "${table_arguments[@]}" |
  tee "$out/table.md"
