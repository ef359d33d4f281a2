#!/usr/bin/env bash
# Every table and figure of README.md, doc/tutorial.md, doc/advanced.md and
# benchmarks/*.md, made anew from the built program.
#
#   doc/make_results.sh [path/to/membranes] [work-dir]
#
# Defaults: build/membranes of this repository and /tmp/membranes-results.
# Runs from the top of the source tree. It prints each command it runs
# (lines starting with "+"), keeps every run's output under <work-dir>, and
# writes each table, with the commands that made it, between the markers
#
#   <!-- results: NAME -->  ...  <!-- end of results: NAME -->
#
# of the documents (doc/results.py splice), and the figures to doc/images/.
# SECTIONS in the environment chooses what to make (default: all of
# "benchmarks readme tutorial"); "benchmarks" runs every script of
# benchmarks/ (about an hour on two cores, up to 9 GB of memory for
# mpi_scaling.sh); the section tutorial summarizes some of their runs and
# the run of the default scene of section readme (whose figure it shows
# too), so it comes last. The section tutorial writes doc/tutorial.md,
# doc/advanced.md (the identities of the flux reconstruction) and the
# comparison of exact and balanced stopping in benchmarks/solvers.md. BLOCKS
# in the environment limits the section benchmarks to the blocks of
# benchmarks/*.md it names (e.g. BLOCKS="solver-cost flux-estimator");
# the others are left as they are. The peer benchmark needs python3-dolfinx; without it its table is
# left as it is and the script says so. The figures need python3-matplotlib.
#
# A benchmark that misses one of its targets exits with status 1; its table
# (with the FAIL line) is written all the same. The script stops at the first
# run that fails in any other way, leaving the documents as they were for
# the tables not yet made.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
membranes=${1:-build/membranes}
work=${2:-/tmp/membranes-results}
sections=${SECTIONS:-benchmarks readme tutorial}
python=/usr/bin/python3

if [[ ! -x $membranes ]]; then
  echo "make_results.sh: error: no program at '$membranes' (build it first)" >&2
  exit 1
fi
mkdir -p "$work/blocks"

# The command line as one would type it: arguments with spaces in quotes.
quoted() {
  local argument text=""
  for argument in "$@"; do
    [[ $argument == *" "* ]] && argument="\"$argument\""
    text+="${text:+ }$argument"
  done
  printf '%s' "$text"
}

# run COMMAND...: print it (on the script's standard error, also where the
# command's output goes to a file), run it, and remember it for the next
# block.
exec 3>&2
commands=()
run() {
  local line
  line=$(quoted "$@")
  echo "+ $line" >&3
  commands+=("$line")
  "$@"
}

# benchmark BLOCK DIR SCRIPT [ENV=VALUE...]: one script of benchmarks/ into
# <work-dir>/DIR, whose missed targets (exit status 1) do not stop this
# script, and its table.md (of adaptivity.sh only the comparisons at equal
# error) under the machine's state as block BLOCK of its document
# (benchmark_document).
benchmark() {
  local block=$1 out=$work/$2 script=$3 status=0 conditions
  shift 3
  chosen "$block" || return 0
  local command=("benchmarks/$script" "$membranes" "$out")
  (($# == 0)) || command=(env "$@" "${command[@]}")
  commands=()
  conditions=$(machine)
  run "${command[@]}" >"$out.log" 2>&1 || status=$?
  if ((status > 1)) || [[ ! -s $out/table.md ]]; then
    echo "make_results.sh: error: $script failed (status $status), see $out.log" >&2
    exit 1
  fi
  {
    echo "$conditions"
    echo
    if [[ $script == adaptivity.sh ]]; then
      $python doc/results.py comparisons "$out/table.md"
    else
      cat "$out/table.md"
    fi
  } | block "$(benchmark_document "$block")" "$block"
}

# benchmark_document BLOCK: the file of benchmarks/ that holds the entry of
# the benchmark whose table is block BLOCK.
benchmark_document() {
  case $1 in
  solver-cost | solver-cost-balanced | balanced | stability) echo benchmarks/solvers.md ;;
  adaptivity | flux-estimator | flux-effectivity | error-quadrature | error-columns)
    echo benchmarks/estimators.md ;;
  mpi-scaling) echo benchmarks/parallel.md ;;
  peer-snesvi) echo benchmarks/costs.md ;;
  *) echo benchmarks/README.md ;;
  esac
}

# chosen BLOCK: whether BLOCKS (all blocks if unset) names BLOCK.
chosen() {
  [[ -z ${BLOCKS:-} || " $BLOCKS " == *" $1 "* ]]
}

# membranes_run NAME SCENE [--set ...]: the program on a scene, without field
# output, into <work-dir>/NAME (progress in <work-dir>/NAME.log).
membranes_run() {
  local name=$1 scene=$2
  shift 2
  run "$membranes" --set "Output/Directory=$work/$name" \
    --set "Output/Write vtu=false" "$@" "$scene" >"$work/$name.log"
}

# block DOCUMENT NAME < TABLE: the table between the markers NAME of
# DOCUMENT. In the documents of benchmarks/ below the list of commands run since the
# last block ("Made by"); README.md and the documents of doc/ teach and hold
# the table alone, their commands are collected in readme_commands and
# doc_commands for the blocks readme-runs and tutorial-runs of
# benchmarks/README.md.
doc_commands=()
readme_commands=()
block() {
  local document=$1 name=$2 file="$work/blocks/$2.md" line
  {
    if [[ $document == doc/* ]]; then
      doc_commands+=("${commands[@]}")
    elif [[ $document == README.md ]]; then
      readme_commands+=("${commands[@]}")
    else
      echo "Made by"
      echo
      echo '```sh'
      for line in "${commands[@]}"; do echo "$line"; done
      echo '```'
      echo
    fi
    cat
  } >"$file"
  $python doc/results.py splice "$document" "$name" "$file"
  echo "  -> $document: $name"
}

# command_block NAME COMMAND...: the commands as a shell block between the
# markers NAME of benchmarks/README.md.
command_block() {
  local name=$1 line
  shift
  {
    echo '```sh'
    for line in "$@"; do echo "$line"; done
    echo '```'
  } >"$work/blocks/$name.md"
  $python doc/results.py splice benchmarks/README.md "$name" \
    "$work/blocks/$name.md"
  echo "  -> benchmarks/README.md: $name"
}

# figure SOURCE IMAGE: copy a figure into doc/images/.
figure() {
  cp "$1" "doc/images/$2"
  echo "  -> doc/images/$2"
}

# The machine's state, and the last commit that changed the program (later
# commits that change only documents do not count).
machine() {
  echo "On $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at the start, program built from commit $(git log -1 --format=%h -- source include CMakeLists.txt)."
}

for section in $sections; do
  case $section in
  benchmarks)
    benchmark solver-cost solver-cost solver_cost.sh
    benchmark solver-cost-balanced solver-cost-balanced solver_cost.sh \
      STOPPING=balanced
    benchmark adaptivity adaptivity adaptivity.sh
    if chosen adaptivity; then
      figure "$work/adaptivity/lshape-convergence.png" lshape-convergence.png
      figure "$work/adaptivity/slit-convergence.png" slit-convergence.png
    fi
    for script in flux_estimator flux_effectivity stability mpi_scaling \
      error_quadrature; do
      benchmark "${script//_/-}" "$script" "$script.sh"
    done
    # error_columns.sh prints its table (after its progress lines) instead
    # of writing table.md: the default size, then 2 101 250 DoFs once.
    if chosen error-columns; then
      commands=()
      conditions=$(machine)
      run benchmarks/error_columns.sh "$membranes" "$work/error_columns" \
        >"$work/error_columns.log" 2>&1
      run env CYCLES=9 ROUNDS=1 benchmarks/error_columns.sh "$membranes" \
        "$work/error_columns-9" >"$work/error_columns-9.log" 2>&1
      {
        echo "$conditions"
        echo
        grep '^|' "$work/error_columns.log"
        echo
        grep '^|' "$work/error_columns-9.log"
      } | block "$(benchmark_document error-columns)" error-columns
    fi
    if chosen peer-snesvi; then
      if $python -c "import dolfinx" 2>/dev/null; then
        benchmark peer-snesvi peer_snesvi peer_snesvi.sh
      else
        echo "make_results.sh: python3-dolfinx is missing: the table of peer_snesvi.sh is left as it is" >&2
      fi
    fi
    ;;

  readme)
    commands=()
    run "$membranes" --set "Output/Directory=$work/default" \
      parameters/default.prm >"$work/default.log"
    run $python source/plot_report.py "$work/default/report.csv" \
      --output "$work/default/convergence"
    figure "$work/default/convergence.png" default-convergence.png
    $python doc/results.py summary "$work/default/report.csv" \
      >"$work/blocks/default.table"
    block README.md default <"$work/blocks/default.table"
    # The progress output of the cycle that the tutorial follows.
    $python doc/results.py terminal "$work/default.log" 8 |
      block doc/tutorial.md terminal

    commands=()
    run "$membranes" --set "Output/Directory=$work/own-scene" \
      --set "Output/Write vtu=false" parameters/own-scene.prm \
      >"$work/own-scene.log"
    run "$membranes" --set Refinement/Strategy=global \
      --set Refinement/Cycles=5 --set "Output/Directory=$work/own-scene-uniform" \
      --set "Output/Write vtu=false" parameters/own-scene.prm \
      >"$work/own-scene-uniform.log"
    run $python doc/results.py estimators \
      "$work/own-scene/report.csv=adaptive" \
      "$work/own-scene-uniform/report.csv=uniform" >"$work/blocks/own-scene.table"
    block README.md own-scene <"$work/blocks/own-scene.table"
    # What made them, in benchmarks/README.md.
    command_block readme-runs "${readme_commands[@]}"
    ;;

  tutorial)
    commands=()
    membranes_run case-m-q1 parameters/case-m-quadrilateral.prm
    membranes_run case-m-p1 parameters/case-m-triangle.prm
    membranes_run full-contact parameters/full-contact.prm
    membranes_run full-contact-p1 parameters/full-contact.prm \
      --set "Geometry/Cell type=triangle"
    run $python doc/results.py errors case-m "$work/case-m-q1/report.csv=Q1" \
      "$work/case-m-p1/report.csv=P1" >"$work/blocks/case-m.table"
    run $python doc/results.py errors full-contact \
      "$work/full-contact/report.csv=Q1" \
      "$work/full-contact-p1/report.csv=P1" >"$work/blocks/full-contact.table"
    block doc/tutorial.md case-m <"$work/blocks/case-m.table"
    commands=()
    block doc/tutorial.md full-contact <"$work/blocks/full-contact.table"

    commands=()
    run $python source/plot_report.py --output "$work/case-m-convergence" \
      --title "Case M" "$work/case-m-q1/report.csv=Q1" \
      "$work/case-m-p1/report.csv=P1"
    figure "$work/case-m-convergence.png" case-m-convergence.png
    doc_commands+=("${commands[@]}")

    reports=("$work/case-m-q1/report.csv=case M, Q1"
      "$work/case-m-p1/report.csv=case M, P1"
      "$work/full-contact/report.csv=full contact")
    commands=()
    run $python doc/results.py solver "${reports[@]}" >"$work/blocks/solver.table"
    block doc/tutorial.md solver <"$work/blocks/solver.table"
    commands=()
    run $python doc/results.py identities "${reports[@]}" \
      >"$work/blocks/identities.table"
    block doc/tutorial.md identities <"$work/blocks/identities.table"

    # Exact against balanced stopping on three scenes.
    commands=()
    arguments=()
    for scene in "degenerate parameters/degenerate-free-boundary.prm" \
      "case-m parameters/case-m-quadrilateral.prm --set Refinement/Cycles=8" \
      "lshape parameters/lshape.prm"; do
      read -r name file settings <<<"$scene"
      for stopping in exact balanced; do
        # shellcheck disable=SC2086
        membranes_run "$name-$stopping" "$file" \
          --set "Solver/Stopping=$stopping" $settings
      done
      arguments+=("$name" "$work/$name-exact/report.csv"
        "$work/$name-balanced/report.csv")
    done
    run $python doc/results.py balanced "${arguments[@]}" \
      >"$work/blocks/balanced.table"
    { machine; echo; cat "$work/blocks/balanced.table"; } |
      block "$(benchmark_document balanced)" balanced

    # From the runs of the benchmarks (section benchmarks).
    commands=()
    run $python doc/results.py flux-identities \
      "$work/flux_estimator/case-m-q1/report.csv=case M, Q1" \
      "$work/flux_estimator/case-m-p1/report.csv=case M, P1" \
      >"$work/blocks/flux-identities.table"
    block doc/advanced.md flux-identities <"$work/blocks/flux-identities.table"
    commands=("benchmarks/adaptivity.sh $membranes $work/adaptivity")
    run $python doc/results.py adaptivity "$work/adaptivity" \
      >"$work/blocks/adaptivity.table"
    block doc/tutorial.md adaptivity <"$work/blocks/adaptivity.table"

    # From the run of the default scene and its figure (section readme).
    commands=("$(quoted "$membranes" --set "Output/Directory=$work/default" \
      parameters/default.prm)"
      "$python source/plot_report.py $work/default/report.csv --output $work/default/convergence")
    run $python doc/results.py adaptive "$work/default/report.csv" \
      >"$work/blocks/default-run.table"
    block doc/tutorial.md default-run <"$work/blocks/default-run.table"

    commands=()
    run $python doc/make_figures.py "$membranes" "$work/figures" \
      >"$work/figures.log"
    mapfile -t drawn < <(sed -n 's/^\$ //p' "$work/figures.log")
    doc_commands+=("${commands[@]}" "${drawn[@]}")
    for image in membranes dual-mesh case-m-fields slit-adaptive-mesh \
      active-set-iterations; do
      figure "$work/figures/$image.png" "$image.png"
    done

    # What made the tables and figures of doc/, in benchmarks/README.md.
    command_block tutorial-runs "${doc_commands[@]}"
    ;;

  *)
    echo "make_results.sh: error: unknown section '$section' in SECTIONS (allowed: benchmarks readme tutorial)" >&2
    exit 1
    ;;
  esac
done
echo "make_results.sh: done; the documents and doc/images/ now hold the results of this run"
