#!/usr/bin/env python3
"""Where CG with AMG overtakes the direct solver, for `Linear solver = auto`.

    benchmarks/solver_crossover.py [path/to/membranes] [output-dir]

Defaults: build/membranes of this repository and
/tmp/membranes-solver-crossover. Runs four scenes with the decoupled method
on one process, once with `Linear solver = direct` (UMFPACK, the direct
solver of one process) and once with `cg-amg`, REPEATS times each (default
3), the two solvers in turn, on meshes up to about 2·10⁴ unknowns, well
past the crossover:

- the default scene (case M on the disk, Q1, adaptive, 11 cycles) and the
  same on triangles (P1, 9 cycles): adaptive meshes with hanging nodes;
- case M on the square, Q1 and P1, uniform refinement, 6 cycles.

For every cycle the table gives the number of unknowns of each scalar
problem (s and w: one per vertex, half the `dofs` of the report), and the
median over the repetitions of the time of the active set method on the
mesh, `time_assembly_s + time_solve_s` (with the direct solver the
assembly phase condenses and the solve phase factorizes the matrix of w at
every active set iteration; with CG the AMG setups are in the solve
phase), for both solvers, and their ratio. The last lines give, per scene,
the fewest unknowns from which CG is faster on every larger cycle.
"""
import csv
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MEMBRANES = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
    ROOT, "build", "membranes")
OUTPUT = (sys.argv[2] if len(sys.argv) > 2
          else "/tmp/membranes-solver-crossover")
REPEATS = int(os.environ.get("REPEATS", "3"))
SCENES = [
    ("disk Q1 adaptive", "default.prm", ["Refinement/Cycles=11"]),
    ("disk P1 adaptive", "default.prm", ["Geometry/Cell type=triangle",
                                         "Refinement/Cycles=9"]),
    ("square Q1 uniform", "case-m-quadrilateral.prm", ["Refinement/Cycles=6"]),
    ("square P1 uniform", "case-m-triangle.prm", ["Refinement/Cycles=6"]),
]
SOLVERS = ["direct", "cg-amg"]


def run(scene, settings, solver, repeat):
    """The report.csv rows of one run."""
    directory = os.path.join(OUTPUT, "%s-%s-%d" % (
        scene.replace(" ", "-"), solver, repeat))
    command = [MEMBRANES, os.path.join(ROOT, "parameters", settings[0])]
    for entry in settings[1] + ["Output/Directory=" + directory,
                                "Output/Write vtu=false",
                                "Solver/Method=decoupled",
                                "Solver/Linear solver=" + solver]:
        command += ["--set", entry]
    print("$ " + " ".join(command), flush=True)
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    with open(os.path.join(directory, "report.csv")) as report:
        return list(csv.DictReader(report))


def main():
    lines = ["| scene | cycle | unknowns | direct s | cg-amg s | cg/direct |",
             "|---|--:|--:|--:|--:|--:|"]
    crossovers = []
    for scene, prm, settings in SCENES:
        times = {solver: [] for solver in SOLVERS}
        for repeat in range(REPEATS):
            for solver in SOLVERS:
                times[solver].append(run(scene, (prm, settings), solver,
                                         repeat))
        reference = times["direct"][0]
        faster_from = None
        for k, row in enumerate(reference):
            unknowns = int(row["dofs"]) // 2
            medians = {}
            for solver in SOLVERS:
                medians[solver] = statistics.median(
                    float(rows[k]["time_assembly_s"]) +
                    float(rows[k]["time_solve_s"])
                    for rows in times[solver])
            ratio = medians["cg-amg"] / medians["direct"]
            if ratio < 1 and faster_from is None:
                faster_from = unknowns
            elif ratio >= 1:
                faster_from = None
            lines.append("| %s | %d | %d | %.3f | %.3f | %.2f |" % (
                scene, k, unknowns, medians["direct"], medians["cg-amg"],
                ratio))
        crossovers.append("%s: CG-AMG faster on every cycle from %s "
                          "unknowns on" % (
                              scene, faster_from if faster_from is not None
                              else "no"))
    table = "\n".join(lines + [""] + crossovers)
    print(table)
    with open(os.path.join(OUTPUT, "table.md"), "w") as out:
        out.write(table + "\n")


if __name__ == "__main__":
    main()
