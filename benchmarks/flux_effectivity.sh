#!/usr/bin/env bash
# Effectivity of the flux estimator on every shipped scene, both cell
# types, refined uniformly and adaptively (by the flux estimator), to at
# least 2·10⁴ DoFs.
#
#   benchmarks/flux_effectivity.sh [path/to/membranes] [output-dir]
#
# Defaults: build/membranes of this repository and /tmp/membranes-effectivity.
# Every scene of parameters/ (case M once, cell type set here), with
# Refinement/Estimator = flux, no VTU output, and Max dofs = MAX_DOFS
# (default 70000): a run stops before a mesh with more DoFs, so that its
# last cycle has between MAX_DOFS/4 and MAX_DOFS DoFs on uniform meshes.
# Runs one after the other, then prints (and keeps in
# <output-dir>/table.md) the table of benchmarks/flux_effectivity_table.py:
# per run the last cycle's DoFs, the effectivity of the flux estimator there
# and its range over the cycles, and its parts (flux, oscillation, contact)
# relative to the energy error.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
membranes=${1:-$root/build/membranes}
out=${2:-/tmp/membranes-effectivity}
max_dofs=${MAX_DOFS:-70000}

if [[ ! -x $membranes ]]; then
  echo "flux_effectivity.sh: error: '$membranes' is not an executable" >&2
  exit 1
fi
mkdir -p "$out"

runs=()
for scene in case-m-quadrilateral default degenerate-free-boundary \
  full-contact lshape no-contact disk-contact straight-free-boundary; do
  for cell in q1 p1; do
    type=quadrilateral
    [[ $cell == p1 ]] && type=triangle
    for refinement in uniform adaptive; do
      strategy=global
      [[ $refinement == adaptive ]] && strategy=adaptive
      name=${scene%-quadrilateral}-$cell-$refinement
      rm -f "$out/$name/report.csv"
      start=$SECONDS
      "$membranes" --set "Output/Write vtu=false" \
        --set "Geometry/Cell type=$type" \
        --set "Refinement/Strategy=$strategy" \
        --set "Refinement/Estimator=flux" \
        --set "Refinement/Cycles=40" --set "Refinement/Max dofs=$max_dofs" \
        --set "Output/Directory=$out/$name" "$root/parameters/$scene.prm" \
        > "$out/$name.log" 2>&1
      echo "== $name: $((SECONDS - start)) s"
      runs+=("$out/$name")
    done
  done
done
python3 "$root/benchmarks/flux_effectivity_table.py" "${runs[@]}" \
  | tee "$out/table.md"
