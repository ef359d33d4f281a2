#!/usr/bin/env bash
# Where the time of a whole run goes: the shares of perf's samples by
# library group and by function, on a P1 and a Q1 scene.
#
#   benchmarks/profile.sh [path/to/membranes] [output-dir]
#
# Defaults: build/membranes of this repository and /tmp/membranes-profile.
# Runs two scenes under global refinement, without VTU output, each as one
# whole process under `perf record -F 999` (999 samples per second of CPU
# time of each thread; in the kernel too as root or with
# /proc/sys/kernel/perf_event_paranoid at 1 or less, else the row
# "kernel" stays empty):
#
#   p1  parameters/degenerate-free-boundary.prm as shipped: P1, 7 cycles to
#       526 338 DoFs;
#   q1  parameters/case-m-quadrilateral.prm with Solver/Linear solver =
#       cg-amg and Refinement/Cycles = 9: Q1, 2 101 250 DoFs on the last
#       cycle (about 40 s and 2 GB of memory).
#
# The profile is flat (no -g): the tables count each sample once, in the
# function it was taken in (its self share), for which the sampled
# instruction is enough. Call chains (-g, by frame pointers) leave these
# shares within the spread between runs (a point or two per group on p1),
# but double the data and are cut short in the libraries built without
# frame pointers. CALLGRAPH=1 records them, for a look at the callers with
# perf report; the tables are made the same way.
#
# Before each profiled run, one cycle of the same scene is run unprofiled,
# so that the scene's expressions are compiled (and cached) then: the
# compiler, a child process, is not in the profile.
#
# For each scene <output-dir> keeps <scene>.data (perf's samples),
# <scene>.log (the program's output), <scene>.err (perf's and the
# program's messages), <scene>.report.txt (perf report's text, the input
# of the tables) and <scene>/ (the run's report.csv). The tables of
# benchmarks/profile_table.py, by library group and by function, are
# printed and kept in <output-dir>/table.md.
# Needs perf (apt-get install linux-perf). CYCLES=n in the environment
# shortens the Q1 run (cycle n-1 has 2·(2^(n+1)+1)² DoFs); SCENES=p1 or
# SCENES=q1 runs one scene only (default "p1 q1").
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
membranes=${1:-$root/build/membranes}
out=${2:-/tmp/membranes-profile}
cycles=${CYCLES:-9}
scenes=${SCENES:-p1 q1}

if ! command -v perf > /dev/null; then
  echo "profile.sh: error: perf is missing; install it with 'apt-get install linux-perf'" >&2
  exit 1
fi
if [[ ! -x $membranes ]]; then
  echo "profile.sh: error: '$membranes' is not an executable" >&2
  exit 1
fi
for scene in $scenes; do
  if [[ $scene != p1 && $scene != q1 ]]; then
    echo "profile.sh: error: unknown scene '$scene' in SCENES (p1, q1)" >&2
    exit 1
  fi
done
for file in degenerate-free-boundary.prm case-m-quadrilateral.prm; do
  if [[ ! -f $root/parameters/$file ]]; then
    echo "profile.sh: error: the scene '$root/parameters/$file' is missing" >&2
    exit 1
  fi
done
mkdir -p "$out"

# perf may be installed and still not allowed to sample: try it on `true`.
if ! perf record -q -F 999 -o "$out/probe.data" -- true 2> "$out/probe.err"; then
  echo "profile.sh: error: perf record cannot sample here:" \
    "'$(grep -m1 . "$out/probe.err")'" \
    "(/proc/sys/kernel/perf_event_paranoid is" \
    "$(cat /proc/sys/kernel/perf_event_paranoid 2> /dev/null || echo unreadable);" \
    "2 or less allows user-space sampling)" >&2
  exit 1
fi
rm -f "$out/probe.data" "$out/probe.err"

record=(perf record -q -F 999)
if [[ ${CALLGRAPH:-0} == 1 ]]; then
  record+=(-g)
fi

# profile SCENE: the scene under perf record, then perf report's text and
# the tables under a heading with the last cycle's DoFs and the run time.
profile() {
  local scene=$1 file description
  local -a settings=(--set "Output/Write vtu=false")
  case $scene in
    p1)
      file=$root/parameters/degenerate-free-boundary.prm
      description="P1, as shipped"
      ;;
    q1)
      file=$root/parameters/case-m-quadrilateral.prm
      description="Q1, Solver/Linear solver = cg-amg, Refinement/Cycles = $cycles"
      settings+=(--set "Solver/Linear solver=cg-amg" --set "Refinement/Cycles=$cycles")
      ;;
  esac
  echo "== $scene: compiling the scene's expressions (one cycle, not profiled)" >&2
  if ! "$membranes" "${settings[@]}" --set "Refinement/Cycles=1" \
       --set "Output/Directory=$out/$scene-compile" "$file" \
       > "$out/$scene-compile.log" 2>&1; then
    echo "profile.sh: error: one cycle of scene $scene failed; see" \
      "$out/$scene-compile.log" >&2
    exit 1
  fi
  local command=("$membranes" "${settings[@]}"
                 --set "Output/Directory=$out/$scene" "$file")
  echo "== $scene: ${record[*]} -o $out/$scene.data -- ${command[*]}" >&2
  rm -f "$out/$scene/report.csv"
  local start
  start=$(date +%s.%N)
  if ! "${record[@]}" -o "$out/$scene.data" -- "${command[@]}" \
       > "$out/$scene.log" 2> "$out/$scene.err"; then
    echo "profile.sh: error: the run of scene $scene failed; see $out/$scene.err" \
      "and $out/$scene.log" >&2
    exit 1
  fi
  local seconds
  seconds=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
  perf report -i "$out/$scene.data" --stdio --no-children -g none \
    --sort dso,sym -n --percent-limit 0 \
    > "$out/$scene.report.txt" 2> "$out/$scene.report.err"
  local dofs
  dofs=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "dofs") c = i }
                  END { print $c }' "$out/$scene/report.csv")
  echo "### $scene: ${file#"$root"/}, $description"
  echo
  echo "Whole process $seconds s under perf, last cycle $dofs DoFs."
  python3 "$root/benchmarks/profile_table.py" --program "$(basename "$membranes")" \
    "$out/$scene.report.txt"
  echo
}

echo "== $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at start" >&2
for scene in $scenes; do
  profile "$scene"
done | tee "$out/table.md"
echo "== load average $(cut -d' ' -f1-3 /proc/loadavg) at end" >&2
