#!/usr/bin/env python3
"""The same meshes and numbers on one, two and three processes.

    benchmarks/process_count.py [path/to/membranes] [output-dir]

Defaults: build/membranes of this repository and
/tmp/membranes-process-count. Runs the symmetric scenes case M on triangles
(P1, parameters/case-m-triangle.prm) and on quadrilaterals (Q1,
parameters/case-m-quadrilateral.prm), and full contact on the square (Q1,
parameters/full-contact.prm), refined adaptively for 9 cycles by each
estimator (residual, flux) with each marking (bulk, fixed number), on 1,
2 and 3 processes (mpiexec -n N --oversubscribe), with `Solver/Linear
solver = cg-amg` and `Solver/Tolerance = 1e-12`, no field output. (With
`auto`, the one-process runs would solve their first meshes, up to 1000
unknowns, directly and the others by CG: the KKT residual, round-off on
one process, would be the CG residual on more.)

For each run on 2 and 3 processes the table compares, cycle by cycle, with
the run on one process: whether the meshes are the same (the numbers of
cells and DoFs of every cycle, and the energy errors to 1e-9 relative,
which tell two meshes of the same numbers of cells apart: the energy error
does not see the algebraic error of CG at that level), the largest
relative difference of the errors and estimators over the cycles, and
whether every column of the two reports agrees as in the tests
(tests/compare_reports.py --report with rtol 1e-8, its PASS/FAIL lines in
compare-report.txt of the directory of the run on 2 or 3 processes:
"agree", or the columns that do not). The target: the same meshes,
differences below 1e-8 (a difference above it is marked **bold**) and
every column agreeing. The exit status is 1 if a run misses it.

With the default `Solver/Tolerance = 1e-10` the meshes are the same too,
but the L2 errors and the flux estimator differ by up to about 1e-7
relative (its contact part by 1e-4) on the larger cycles: CG stops at
another iterate on another partition, within the algebraic error that the
tolerance allows. `TOLERANCE=1e-10` in the environment shows it.
"""
import csv
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
COMPARE = os.path.join(ROOT, "tests", "compare_reports.py")
MEMBRANES = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
    ROOT, "build", "membranes")
OUTPUT = sys.argv[2] if len(sys.argv) > 2 else "/tmp/membranes-process-count"
TOLERANCE = os.environ.get("TOLERANCE", "1e-12")
SCENES = ["case-m-triangle", "case-m-quadrilateral", "full-contact"]
ESTIMATORS = ["residual", "flux"]
MARKINGS = ["bulk", "fixed number"]
PROCESSES = [1, 2, 3]
CYCLES = 9
COLUMNS = ["err_u1_H1", "err_u2_H1", "err_u1_L2", "err_u2_L2",
           "err_lambda_L2", "err_energy", "estimator", "flux_estimator"]
TARGET = 1e-8
# Relative difference of the energy errors below which two meshes of the
# same numbers of cells are taken to be the same mesh.
SAME_MESH = 1e-9
ENVIRONMENT = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1",
                   OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")


def directory_of(scene, estimator, marking, processes):
    """The output directory of one run."""
    return os.path.join(OUTPUT, "%s-%s-%s-np%d" % (
        scene, estimator, marking.replace(" ", "-"), processes))


def run(scene, estimator, marking, processes):
    """The report.csv rows of one run."""
    directory = directory_of(scene, estimator, marking, processes)
    settings = {"Output/Directory": directory,
                "Output/Write vtu": "false",
                "Refinement/Strategy": "adaptive",
                "Refinement/Cycles": str(CYCLES),
                "Refinement/Estimator": estimator,
                "Refinement/Marking": marking,
                "Solver/Linear solver": "cg-amg",
                "Solver/Tolerance": TOLERANCE}
    if estimator == "flux":
        settings["Output/Flux reconstruction"] = "true"
    command = ["mpiexec", "-n", str(processes), "--oversubscribe",
               MEMBRANES, os.path.join(ROOT, "parameters", scene + ".prm")]
    for entry, value in settings.items():
        command += ["--set", "%s=%s" % (entry, value)]
    print("$ " + " ".join(command), flush=True)
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL,
                   env=ENVIRONMENT)
    with open(os.path.join(directory, "report.csv")) as report:
        return list(csv.DictReader(report))


def largest_difference(a, b):
    """The largest relative difference of COLUMNS over the rows."""
    largest = 0.0
    for row_a, row_b in zip(a, b):
        for column in COLUMNS:
            if row_a.get(column) and row_b.get(column):
                x, y = float(row_a[column]), float(row_b[column])
                if max(abs(x), abs(y)) > 0:
                    largest = max(largest,
                                  abs(x - y) / max(abs(x), abs(y)))
    return largest


def same_meshes(a, b):
    """Whether two runs refined the same cells on every cycle."""
    return len(a) == len(b) and all(
        x["cells"] == y["cells"] and x["dofs"] == y["dofs"] and
        abs(float(x["err_energy"]) - float(y["err_energy"])) <=
        SAME_MESH * float(x["err_energy"])
        for x, y in zip(a, b))


def compare_every_column(one, more):
    """compare_reports.py --report on the reports of the output directories
    one (one process) and more, its lines written to compare-report.txt of
    more; "agree", or the columns that do not."""
    result = subprocess.run(
        [sys.executable, COMPARE, os.path.join(one, "report.csv"),
         os.path.join(more, "report.csv"), "--report", "--rtol",
         "%g" % TARGET], stdout=subprocess.PIPE, universal_newlines=True)
    with open(os.path.join(more, "compare-report.txt"), "w") as out:
        out.write(result.stdout)
    failed = [line.split()[1].rstrip(":")
              for line in result.stdout.splitlines()
              if line.startswith("FAIL")]
    if result.returncode == 0:
        return "agree"
    return "**%s**" % (", ".join(failed) or "error")


def main():
    rows = []
    failed = False
    for scene in SCENES:
        for estimator in ESTIMATORS:
            for marking in MARKINGS:
                reports = {n: run(scene, estimator, marking, n)
                           for n in PROCESSES}
                row = [scene, estimator, marking,
                       reports[1][-1]["dofs"]]
                for n in PROCESSES[1:]:
                    same = same_meshes(reports[1], reports[n])
                    difference = largest_difference(reports[1], reports[n])
                    columns = compare_every_column(
                        *(directory_of(scene, estimator, marking, m)
                          for m in (1, n)))
                    failed = (failed or not same or difference >= TARGET
                              or columns != "agree")
                    row += ["same" if same else "**different**",
                            ("%.1e" if difference < TARGET else "**%.1e**")
                            % difference, columns]
                rows.append(row)
    header = ["scene", "estimator", "marking", "DoFs, cycle %d" % (
        CYCLES - 1)]
    for n in PROCESSES[1:]:
        header += ["meshes, %d processes" % n, "max rel. difference",
                   "every column"]
    lines = ["| " + " | ".join(header) + " |",
             "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    lines.append("")
    lines.append("Solver/Tolerance = %s; target: the same meshes, "
                 "differences below %.0e, every column agreeing: %s." % (
                     TOLERANCE, TARGET, "FAIL" if failed else "met"))
    table = "\n".join(lines)
    print(table)
    with open(os.path.join(OUTPUT, "table.md"), "w") as out:
        out.write(table + "\n")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
