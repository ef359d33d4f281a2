#!/usr/bin/env python3
"""The tables of the documents, made from the program's output, and their
place in the documents. Called by doc/make_results.sh; each subcommand can
also be used on its own.

Usage::

    results.py errors report.csv
    results.py solver report.csv=LABEL ...
    results.py identities report.csv=LABEL ...
    results.py flux-identities report.csv=LABEL ...
    results.py terminal run.log CYCLE
    results.py balanced LABEL exact/report.csv balanced/report.csv [...]
    results.py summary report.csv
    results.py estimators report.csv=LABEL ...
    results.py adaptivity OUTPUT-DIR
    results.py comparisons table.md
    results.py splice DOCUMENT NAME BLOCK-FILE
    results.py check DOCUMENT NAME report.csv

The first ten print Markdown to standard output:

* ``errors``: per cycle the cells, DoFs and the error columns with their
  rates in h (h ~ N^(-1/2), uniform refinement), as the program's terminal
  table;
* ``solver``: per run and cycle the DoFs, active set iterations, active
  vertices, CG iterations and cumulative wall time;
* ``identities``: per run the discrete identities of the last cycle;
* ``flux-identities``: per run and cycle the defects of (4.17), (4.18) and of
  the balance of Lemma 17;
* ``terminal``: the progress lines of one cycle of a run's terminal output;
* ``balanced``: exact against balanced stopping, per scene (pairs of runs):
  sums over the cycles and the finest cycle;
* ``summary``: one sentence on a run: its last cycle, the rate of the energy
  error in N and the effectivity range of the estimator;
* ``estimators``: per run its last cycle, DoFs and estimator, and the rate r
  of estimator ~ N^(-r) (least squares over the last half of the cycles),
  for scenes without an exact solution;
* ``adaptivity``: one row per scene and cell type of the output directory of
  benchmarks/adaptivity.sh: rates, N/N_u and T/T_u at equal error, the
  effectivity band and the most active set iterations after the first cycle;
* ``comparisons``: from the table.md of benchmarks/adaptivity.sh, only the
  comparisons at equal error and the PASS/FAIL lines.

``splice`` replaces, in DOCUMENT, the lines between ``<!-- results: NAME -->``
and ``<!-- end of results: NAME -->`` by the contents of BLOCK-FILE; it stops
with an error (and leaves DOCUMENT as it is) if the markers are missing.

``check`` compares the error table of block NAME of DOCUMENT with the table
``errors`` makes from report.csv: the same rows and columns, errors equal to
1e-3 relative (both are printed with four significant digits) and rates to
0.011 (two decimals). It prints the first difference and exits with status
1 if they differ: a test of the suite runs it, so that a change of the
program's results cannot leave the tables of the documents behind.
"""

import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))), "benchmarks"))
import adaptivity_table  # noqa: E402
from solver_cost_table import number as value, read_report  # noqa: E402

ERROR_COLUMNS = ["err_u1_H1", "err_u2_H1", "err_u1_L2", "err_u2_L2",
                 "err_lambda_L2", "err_lambda_L2_omega_h"]


def labelled(arguments):
    """(path, label) of arguments report.csv=LABEL."""
    for argument in arguments:
        path, _, label = argument.partition("=")
        yield path, label or path


def markdown(header, rows, align):
    """A Markdown table; align holds 'l' or 'r' per column."""
    lines = ["| " + " | ".join(header) + " |",
             "|" + "|".join("---" if a == "l" else "--:" for a in align) + "|"]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def short(x):
    """Three significant digits between 1e-3 and 1e3, two in exponent
    notation outside, 0 as 0."""
    return "0" if x == 0 else f"{x:.3g}" if abs(x) >= 1e-3 and abs(x) < 1e3 \
        else f"{x:.1e}"


def errors(path):
    rows = read_report(path)
    header = ["cycle", "cells", "dofs"]
    for column in ERROR_COLUMNS:
        header += [column, "rate"]
    table = []
    for before, row in zip([None] + rows, rows):
        line = [row["cycle"], row["cells"], row["dofs"]]
        for column in ERROR_COLUMNS:
            error = value(row, column)
            line.append(f"{error:.3e}")
            if before is None:
                line.append("-")
            else:
                h_ratio = math.sqrt(value(row, "dofs") / value(before, "dofs"))
                line.append(f"{math.log(value(before, column) / error) / math.log(h_ratio):.2f}")
        table.append(line)
    return markdown(header, table, "r" * len(header))


def solver(arguments):
    """One row per run: the active set iterations and active vertices of
    each cycle, and the CG iterations of the last one."""
    header = ["run", "dofs, first to last cycle",
              "active set iterations per cycle", "active vertices, last cycle",
              "CG iterations, last cycle"]
    table = []
    for path, label in labelled(arguments):
        rows = read_report(path)
        table.append([label, f"{rows[0]['dofs']} to {rows[-1]['dofs']}",
                      ", ".join(row["active_set_iterations"] for row in rows),
                      rows[-1]["active_vertices"],
                      rows[-1]["linear_iterations"]])
    return markdown(header, table, "lrrrr")


def identities(arguments):
    columns = ["kkt_residual", "prop12_defect", "complementarity_defect",
               "min_w", "min_lambda"]
    table = []
    for path, label in labelled(arguments):
        last = read_report(path)[-1]
        table.append([label] + [short(value(last, c)) for c in columns])
    return markdown(["run"] + columns, table, "l" + "r" * len(columns))


def flux_identities(arguments):
    columns = ["measure_defect", "conservation_defect", "balance_defect"]
    table = []
    for path, label in labelled(arguments):
        for index, row in enumerate(read_report(path)):
            table.append([label if index == 0 else "", row["cycle"],
                          row["dofs"]] +
                         [f"{value(row, c):.1e}" for c in columns])
    return markdown(["run", "cycle", "dofs"] + columns, table, "lrrrrr")


def terminal(path, cycle):
    """The lines of cycle @p cycle in a run's terminal output, in a code
    block."""
    lines, inside = [], False
    with open(path) as stream:
        for line in stream:
            if line.startswith("Cycle "):
                inside = line.startswith(f"Cycle {cycle}:")
            if inside and line.strip():
                lines.append(line.rstrip())
    if not lines:
        raise ValueError(f"{path} has no cycle {cycle}")
    return "```text\n" + "\n".join(lines) + "\n```"


def balanced(arguments):
    if len(arguments) % 3:
        raise ValueError("balanced needs LABEL exact.csv balanced.csv triples")
    header = ["scene", "stopping", "AS its", "CG its", "solve s",
              "AS / CG its, finest", "solve s, finest", "err_energy, finest",
              "max ratio of err_energy"]
    table = []
    for label, *paths in zip(*[iter(arguments)] * 3):
        runs = [read_report(p) for p in paths]
        exact = {r["dofs"]: value(r, "err_energy") for r in runs[0]}
        for stopping, rows in zip(["exact", "balanced"], runs):
            last = rows[-1]
            ratios = [value(r, "err_energy") / exact[r["dofs"]]
                      for r in rows if r["dofs"] in exact]
            table.append([
                label if stopping == "exact" else "", stopping,
                sum(int(r["active_set_iterations"]) for r in rows),
                sum(int(r["linear_iterations"]) for r in rows),
                f"{sum(value(r, 'time_solve_s') for r in rows):.2f}",
                f"{last['active_set_iterations']} / {last['linear_iterations']}",
                f"{value(last, 'time_solve_s'):.2f}",
                f"{value(last, 'err_energy'):.6e} ({last['dofs']} DoFs)",
                "" if stopping == "exact" else f"{max(ratios):.7f}"])
    return markdown(header, table, "llrrrrrrr")


def summary(path):
    rows = read_report(path)
    last = rows[-1]
    rate, _, _ = adaptivity_table.rate(rows)
    effectivities = [value(r, "effectivity") for r in rows]
    dofs = f"{int(last['dofs']):,}".replace(",", " ")
    return (f"Last cycle {last['cycle']}: {dofs} DoFs, energy "
            f"error {value(last, 'err_energy'):.3e}, estimator "
            f"{value(last, 'estimator'):.3e}; the energy error falls like "
            f"N^-{rate:.2f} over the last half of the cycles; effectivity "
            f"index {min(effectivities):.2f} to {max(effectivities):.2f} over "
            f"all cycles.")


def estimators(arguments):
    table = []
    for path, label in labelled(arguments):
        rows = read_report(path)
        rate, _, _ = adaptivity_table.rate(rows, "estimator")
        table.append([label, rows[-1]["cycle"], rows[-1]["dofs"],
                      f"{value(rows[-1], 'estimator'):.3f}", f"{rate:.2f}"])
    return markdown(["run", "last cycle", "dofs", "estimator", "rate in N"],
                    table, "lrrrr")


def adaptivity(directory):
    header = ["scene", "uniform rate", "adaptive rate", "$N/N_u$",
              "effectivity band (adaptive)",
              "active set its after the first"]
    table = []
    for scene, name in [("lshape", "L-shape"), ("slit", "slit")]:
        for cells in ["q1", "p1"]:
            prefix = os.path.join(directory, f"{scene}-{cells}-")
            uniform = read_report(prefix + "uniform/report.csv")
            adaptive = read_report(prefix + "adaptive/report.csv")
            target = value(uniform[-1], "err_energy")
            n, _, _ = adaptivity_table.at_error(adaptive, target)
            iterations = max(adaptivity_table.max_active_set_iterations(r)
                             for r in (uniform, adaptive))
            table.append([
                f"{name} {cells.upper()}",
                f"{adaptivity_table.rate(uniform)[0]:.3f}",
                f"{adaptivity_table.rate(adaptive)[0]:.3f}",
                f"{n / value(uniform[-1], 'dofs'):.3f}",
                f"{adaptivity_table.effectivity_band(adaptive):.2f}",
                f"≤ {iterations}"])
    return markdown(header, table, "lrrrrr")


def comparisons(path):
    """The comparison sections and PASS/FAIL lines of adaptivity's table.md."""
    kept, verdicts, inside = [], [], False
    with open(path) as stream:
        for line in stream:
            line = line.rstrip()
            if line.startswith("#"):
                inside = ": at the energy error" in line
                if inside:
                    line = line.lstrip("# ") + ":"
            if line.startswith(("PASS", "FAIL")):
                verdicts.append(line)
            elif inside:
                kept.append(line)
    return ("\n".join(kept).strip() + "\n\n```text\n" + "\n".join(verdicts)
            + "\n```")


def markers(name):
    return f"<!-- results: {name} -->", f"<!-- end of results: {name} -->"


def read_document(document, name):
    """The text of @p document, which must hold the markers of @p name once."""
    with open(document) as stream:
        text = stream.read()
    if any(text.count(marker) != 1 for marker in markers(name)):
        raise ValueError(f"{document} needs the markers "
                         f"'{markers(name)[0]}' and '{markers(name)[1]}' once")
    return text


def splice(document, name, block_file):
    text = read_document(document, name)
    begin, end = markers(name)
    with open(block_file) as stream:
        block = stream.read().strip("\n")
    text = (text[:text.index(begin)] + f"{begin}\n{block}\n{end}" +
            text[text.index(end) + len(end):])
    with open(document + ".new", "w") as stream:
        stream.write(text)
    os.replace(document + ".new", document)
    return None


def block_text(document, name):
    text = read_document(document, name)
    begin, end = markers(name)
    return text[text.index(begin):text.index(end)]


def table_cells(text):
    """The cells of the rows of the first Markdown table in @p text."""
    rows = [line.strip().strip("|").split("|") for line in text.splitlines()
            if line.startswith("|") and not line.startswith("|-")]
    return [[cell.strip() for cell in row] for row in rows]


def agree(documented, computed, header):
    if documented == computed:
        return True
    try:
        a, b = float(documented), float(computed)
    except ValueError:
        return False
    if header == "rate":
        return abs(a - b) <= 0.011
    return abs(a - b) <= 1e-3 * max(abs(a), abs(b))


def check(document, name, report):
    documented = table_cells(block_text(document, name))
    computed = table_cells(errors(report))
    if len(documented) != len(computed):
        raise ValueError(f"{document}, {name}: {len(documented) - 1} rows, "
                         f"{report}: {len(computed) - 1}")
    header = computed[0]
    for documented_row, computed_row in zip(documented, computed):
        for column, (a, b) in enumerate(zip(documented_row, computed_row)):
            if len(documented_row) != len(computed_row) or \
                    not agree(a, b, header[column]):
                raise ValueError(
                    f"{document}, {name}: cycle {computed_row[0]}, "
                    f"{header[column]}: {a} in the document, {b} in {report}"
                    " (doc/make_results.sh makes the tables anew)")
    print(f"{document}, {name}: {len(computed) - 1} rows agree with {report}")
    return None


def main(argv):
    commands = {
        "errors": lambda a: errors(*a),
        "solver": solver,
        "identities": identities,
        "flux-identities": flux_identities,
        "terminal": lambda a: terminal(a[0], int(a[1])),
        "balanced": balanced,
        "summary": lambda a: summary(*a),
        "estimators": estimators,
        "adaptivity": lambda a: adaptivity(*a),
        "comparisons": lambda a: comparisons(*a),
        "splice": lambda a: splice(*a),
        "check": lambda a: check(*a),
    }
    if len(argv) < 3 or argv[1] not in commands:
        print(__doc__, file=sys.stderr)
        return 2
    try:
        output = commands[argv[1]](argv[2:])
    except (OSError, ValueError, KeyError, TypeError) as error:
        print(f"results.py {argv[1]}: error: {error}", file=sys.stderr)
        return 1
    if output is not None:
        print(output)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
