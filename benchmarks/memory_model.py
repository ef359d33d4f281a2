#!/usr/bin/env python3
"""The memory of a run against its DoFs and processes, and what fits where::

    memory_model.py [--min-dofs N] [--processes 1,2,8,64,512]
                    [--memory-gib 4,16] LABEL=report.csv [LABEL=report.csv ...]

Made for the runs of ``PROCESSES="1 2 3" benchmarks/mpi_scaling.sh``, which
calls it at their end. The numbers in README.md ("Beyond one machine") come
from::

    PROCESSES="1 2 3" benchmarks/mpi_scaling.sh build/membranes /tmp/mpi-model

(9 cycles, up to 2 101 250 DoFs; with fewer cycles a dominates and b, c
mean little) and, by hand on its output::

    benchmarks/memory_model.py \\
      quadrilateral=/tmp/mpi-model/quadrilateral/np1/report.csv \\
      quadrilateral=/tmp/mpi-model/quadrilateral/np2/report.csv \\
      quadrilateral=/tmp/mpi-model/quadrilateral/np3/report.csv \\
      triangle=/tmp/mpi-model/triangle/np1/report.csv \\
      triangle=/tmp/mpi-model/triangle/np2/report.csv \\
      triangle=/tmp/mpi-model/triangle/np3/report.csv

Every row of a report is one cycle: ``dofs`` N (both membranes),
``processes`` P and ``memory_mb``, the peak resident memory (VmHWM) of each
process from its start to the end of that cycle, in MiB, summed over the
processes. Under global refinement each cycle has four times the DoFs of
the one before, so the peak of the run so far is the peak of the current
cycle. The memory per process m = memory_mb / P is the mean over the
processes (the report has no maximum); for each LABEL (a cell type) the
script fits

    m = a + b N / P + c N

to every cycle with N >= --min-dofs of every run of that label, by least
squares on the relative difference (m_model - m) / m, so that the small
cycles, which fix a, weigh as much as the large ones: a is what a process
holds before the problem (the program, deal.II, Trilinos, MPI), b the bytes
per DoF that are distributed over the processes, c the bytes per DoF that
every process holds whatever P (on triangles, the parallel::shared
mesh and what comes with it; small on the p4est mesh of quadrilaterals).
The runs need at least two process counts to tell b from c.

As a check of c, the growth between the two largest cycles alone, in which
a and every other part that does not grow with N cancel, gives c again
as the slope of P times the growth against P ("c from the last step").

It prints the coefficients, the measured against the model for the
largest cycle of each run (and the largest difference over its cycles),
and the largest N that P processes of M GiB each reach by the model,
N = (M - a) / (b / P + c): with c > 0, never more than (M - a) / c,
however many processes. Entries marked † have more than 2^31 - 1 rows in
one Trilinos matrix of the decoupled method (N/2 rows; the coupled method
has N), which a deal.II built without 64-bit indices (Debian's) cannot
number.
"""
import argparse
import csv
import sys

MIB = 2.0**20
GIB = 2.0**30
INDEX_LIMIT = 2**31 - 1


def read_runs(arguments):
    """{label: [(N, P, bytes per process)]} from LABEL=report.csv."""
    runs = {}
    for argument in arguments:
        label, separator, path = argument.partition("=")
        if not separator or not label or not path:
            sys.exit(f"memory_model.py: '{argument}' is not LABEL=report.csv")
        try:
            with open(path, newline="") as f:
                rows = list(csv.DictReader(f))
        except OSError as error:
            sys.exit(f"memory_model.py: {path}: {error.strerror}")
        if not rows or not {"dofs", "processes", "memory_mb"} <= set(rows[0]):
            sys.exit(f"memory_model.py: {path}: no rows with the columns "
                     "dofs, processes, memory_mb")
        for row in rows:
            processes = int(row["processes"])
            runs.setdefault(label, []).append(
                (int(row["dofs"]), processes,
                 float(row["memory_mb"]) * MIB / processes))
    return runs


def solve(matrix, rhs):
    """Gaussian elimination with partial pivoting, small dense systems."""
    n = len(rhs)
    a = [list(matrix[i]) + [rhs[i]] for i in range(n)]
    for k in range(n):
        pivot = max(range(k, n), key=lambda i: abs(a[i][k]))
        if a[pivot][k] == 0:
            raise ZeroDivisionError("singular")
        a[k], a[pivot] = a[pivot], a[k]
        for i in range(k + 1, n):
            factor = a[i][k] / a[k][k]
            for j in range(k, n + 1):
                a[i][j] -= factor * a[k][j]
    x = [0.0] * n
    for i in reversed(range(n)):
        x[i] = (a[i][n] - sum(a[i][j] * x[j] for j in range(i + 1, n))) \
            / a[i][i]
    return x


def fit(points):
    """(a, b, c) of m = a + b N/P + c N, relative least squares."""
    separable = len({p for _, p, _ in points}) > 1
    columns = [lambda n, p: 1.0, lambda n, p: n / p]
    if separable:
        columns.append(lambda n, p: float(n))
    rows = [[column(n, p) / m for column in columns] for n, p, m in points]
    # The columns scaled to unit norm, for the normal equations.
    scale = [max(sum(r[j]**2 for r in rows)**0.5, 1e-300)
             for j in range(len(columns))]
    rows = [[r[j] / scale[j] for j in range(len(columns))] for r in rows]
    normal = [[sum(r[i] * r[j] for r in rows) for j in range(len(columns))]
              for i in range(len(columns))]
    rhs = [sum(r[i] for r in rows) for i in range(len(columns))]
    x = [xi / s for xi, s in zip(solve(normal, rhs), scale)]
    return (x[0], x[1], x[2] if separable else 0.0), separable


def step_c(points):
    """c from the step between the two largest N that every run reached.

    The growth of a run from N1 to N2 is (b/P + c)(N2 - N1): a, and any
    other part that does not grow with N, cancel. P times it against P is
    a line of slope c (N2 - N1). None with fewer than two process counts.
    """
    counts = sorted({p for _, p, _ in points})
    common = set.intersection(*({n for n, q, _ in points if q == p}
                                for p in counts))
    if len(counts) < 2 or len(common) < 2:
        return None
    n1, n2 = sorted(common)[-2:]
    memory = {(n, p): m for n, p, m in points}
    xs = counts
    ys = [p * (memory[n2, p] - memory[n1, p]) for p in counts]
    mean_x, mean_y = sum(xs) / len(xs), sum(ys) / len(ys)
    slope = (sum((x - mean_x) * (y - mean_y) for x, y in zip(xs, ys)) /
             sum((x - mean_x)**2 for x in xs))
    return slope / (n2 - n1), n1, n2


def model(coefficients, n, p):
    a, b, c = coefficients
    return a + b * n / p + c * n


def largest_n(coefficients, p, memory):
    a, b, c = coefficients
    if memory <= a:
        return 0
    return int((memory - a) / (b / p + max(c, 0.0)))


def human(n):
    """3 significant digits with a power of ten: 1.23e9 as 1.23·10⁹."""
    if n == 0:
        return "0"
    mantissa, exponent = f"{n:.2e}".split("e")
    superscript = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
    return f"{mantissa}·10{str(int(exponent)).translate(superscript)}"


def main():
    parser = argparse.ArgumentParser(
        description="Fit bytes per process = a + b N/P + c N to report.csv "
        "files and print what P processes of M GiB each reach.")
    parser.add_argument("--min-dofs", type=int, default=0,
                        help="fit only cycles with at least this many DoFs")
    parser.add_argument("--processes", default="1,2,8,64,512",
                        help="process counts of the last table")
    parser.add_argument("--memory-gib", default="4,16",
                        help="memory per process of the last table, GiB")
    parser.add_argument("reports", nargs="+", metavar="LABEL=report.csv")
    arguments = parser.parse_args()
    process_counts = [int(p) for p in arguments.processes.split(",")]
    memories = [float(m) for m in arguments.memory_gib.split(",")]

    runs = read_runs(arguments.reports)
    fits = {}
    for label, points in runs.items():
        points = [x for x in points if x[0] >= arguments.min_dofs]
        if len(points) < 3:
            sys.exit(f"memory_model.py: {label}: fewer than 3 cycles with "
                     f"at least {arguments.min_dofs} DoFs")
        fits[label] = (fit(points), points)

    print("Bytes per process = a + b·N/P + c·N (N DoFs of both membranes, "
          "P processes), fitted by least squares on the relative "
          "difference to the cycles below.\n")
    print("| cell type | a: MiB per process | b: bytes per DoF, shared out "
          "| c: bytes per DoF, on every process | c from the last step |")
    print("|---|--:|--:|--:|--:|")
    for label, ((coefficients, separable), points) in fits.items():
        a, b, c = coefficients
        step = step_c(points)
        print(f"| {label} | {a / MIB:.0f} | {b:.0f} | "
              f"{f'{c:.0f}' if separable else '(one P: not fitted)'} | "
              f"{f'{step[0]:.0f} ({step[1]} to {step[2]} DoFs)' if step else '–'}"
              " |")
    print("\n\"c from the last step\": the same c from the growth between "
          "the two largest cycles alone, P·Δm = b·ΔN + c·ΔN·P, in which a "
          "and whatever else does not grow with N cancel; where it differs "
          "from the fitted c, the fit does not resolve c.")

    print("\nMeasured against the model: each run's largest cycle, and the "
          "largest relative difference over all its fitted cycles.\n")
    print("| cell type | P | N | measured: MiB per process "
          "| model: MiB per process | difference | largest over the run |")
    print("|---|--:|--:|--:|--:|--:|--:|")
    for label, ((coefficients, _), points) in fits.items():
        for p in sorted({x[1] for x in points}):
            run = sorted(x for x in points if x[1] == p)
            differences = [model(coefficients, n, p) / m - 1
                           for n, _, m in run]
            n, _, m = run[-1]
            worst = max(differences, key=abs)
            print(f"| {label} | {p} | {n} | {m / MIB:.0f} | "
                  f"{model(coefficients, n, p) / MIB:.0f} | "
                  f"{differences[-1]:+.1%} | {worst:+.1%} |")

    print("\nThe largest N by the model, P processes of M GiB each:\n")
    print("| cell type | M | " +
          " | ".join(f"P = {p}" for p in process_counts) + " |")
    print("|---|--:|" + "--:|" * len(process_counts))
    beyond = False
    for label, ((coefficients, _), _) in fits.items():
        for memory in memories:
            cells = []
            for p in process_counts:
                n = largest_n(coefficients, p, memory * GIB)
                mark = "†" if n // 2 > INDEX_LIMIT else ""
                beyond = beyond or bool(mark)
                cells.append(human(n) + mark)
            print(f"| {label} | {memory:g} GiB | " + " | ".join(cells) + " |")
    for label, ((coefficients, _), _) in fits.items():
        a, _, c = coefficients
        if c > 0:
            print(f"\n{label}: at most {human((max(memories) * GIB - a) / c)} "
                  f"DoFs on any number of processes of "
                  f"{max(memories):g} GiB (the replicated part c·N alone).")
    if beyond:
        print("\n† beyond 2^31 − 1 unknowns in one Trilinos matrix (N/2 in "
              "the decoupled method): needs deal.II with 64-bit indices.")


if __name__ == "__main__":
    main()
