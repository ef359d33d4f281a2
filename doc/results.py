#!/usr/bin/env python3
"""The tables of the documents, made from the program's output, and their
place in the documents. Called by doc/make_results.sh; each subcommand can
also be used on its own.

Usage::

    results.py errors KIND report.csv[=LABEL] ...
    results.py adaptive report.csv
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

The first eleven print Markdown to standard output:

* ``errors``: per run (labelled in the first column if there are several)
  and each of its last three cycles the DoFs and the errors of KIND, each with its rate in h
  (h ~ N^(-1/2), uniform refinement) in brackets: ``case-m`` the energy
  error, the L2 errors of u1 and u2 and the L2(omega) and H^-1(omega)
  errors of the action; ``full-contact`` the energy error, the action error
  on omega and on omega_h, (4 l 13/3)^(1/2), l the side of the grid, the norm
  of lambda on the strip omega minus omega_h to first order (without a
  rate), and the H^-1(omega) error of the action;
* ``adaptive``: every sixth cycle and the last one of an adaptive run with
  an exact solution: DoFs, energy error, estimator, effectivity and the
  action errors in L2(omega) and H^-1(omega);
* ``solver``: per run and cycle the DoFs, active set iterations, active
  vertices, CG iterations and cumulative wall time;
* ``identities``: per run the discrete identities of the last cycle (report
  columns kkt_residual, prop12_defect, complementarity_defect, min_w,
  min_lambda);
* ``flux-identities``: per run and cycle the defects of (4.17), (4.18) and of
  the balance of Lemma 17;
* ``terminal``: the progress lines of one cycle of a run's terminal output,
  up to the cycle's summary line (which holds its run time);
* ``balanced``: exact against balanced stopping, per scene (pairs of runs):
  sums over the cycles and the finest cycle;
* ``summary``: one sentence on a run: its last cycle, the rate of the energy
  error in N and the effectivity range of the estimator;
* ``estimators``: per run its last cycle, DoFs and estimator, and the rate r
  of estimator ~ N^(-r) (least squares over the last half of the cycles),
  for scenes without an exact solution;
* ``adaptivity``: one row per scene and cell type of the output directory of
  benchmarks/adaptivity.sh: the rates of uniform and adaptive refinement
  and the effectivity band (the DoFs at equal error are in the block
  adaptivity of benchmarks/estimators.md);
* ``comparisons``: from the table.md of benchmarks/adaptivity.sh, only the
  comparisons at equal error and the PASS/FAIL lines.

``splice`` replaces, in DOCUMENT, the lines between ``<!-- results: NAME -->``
and ``<!-- end of results: NAME -->`` by the contents of BLOCK-FILE; it stops
with an error (and leaves DOCUMENT as it is) if the markers are missing.

``check`` compares the table of block NAME of DOCUMENT with the table
``errors`` (of the kind whose header the block has) or ``adaptive`` makes
from report.csv:
the same rows and columns, errors equal to 1e-3 relative as printed (four
significant digits, two for the H^-1 error of the action) and rates to
0.011 (two decimals). Without a
block NAME, NAME is BLOCK-LABEL: the rows of the run LABEL (case ignored) in
block BLOCK, e.g. case-m-q1 for the rows Q1 of block case-m. It prints the first difference and exits with status
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



def strip(row):
    """(4 l 13/3)^(1/2), l = 2 / n on the uniform n x n grid of vertices
    with n + 1 = (dofs / 2)^(1/2) (squares, or squares cut into two
    triangles): the norm of lambda = 2 + xy of full contact on the strip
    omega minus omega_h of width l/2 along the boundary of (-1, 1)^2, to
    first order in l (13/3 is the mean of lambda^2 on the boundary)."""
    n = math.sqrt(value(row, "dofs") / 2) - 1
    return math.sqrt(4 * 2 / n * 13 / 3)


def column(name):
    return lambda row: value(row, name)


# The error tables of the tutorial show the last cycles of each run; per
# kind, (header, value of a row, whether a rate follows the value, format).
# err_lambda_Hm1 is 3-6 % low where the action jumps (its Riesz
# representative of degree 2 against one of degree 3, benchmarks/estimators.md,
# "The H^-1 norm of the action"): two significant digits, not four. Its
# rates agree with those of the reference to 0.01 and keep two decimals.
SHOWN_CYCLES = 3
ERROR = ".3e"
HM1 = ".1e"
ERROR_TABLES = {
    "case-m": [
        ("energy error", column("err_energy"), True, ERROR),
        ("$L^2$ error of $u_1$", column("err_u1_L2"), True, ERROR),
        ("$L^2$ error of $u_2$", column("err_u2_L2"), True, ERROR),
        ("action error on $\\omega$", column("err_lambda_L2"), True, ERROR),
        ("action error in $H^{-1}(\\omega)$", column("err_lambda_Hm1"), True,
         HM1)],
    "full-contact": [
        ("energy error", column("err_energy"), True, ERROR),
        ("action error on $\\omega$", column("err_lambda_L2"), True, ERROR),
        ("action error on $\\omega_h$", column("err_lambda_L2_omega_h"), True,
         ERROR),
        ("$(4\\ell\\cdot\\tfrac{13}{3})^{1/2}$", strip, False, ERROR),
        ("action error in $H^{-1}(\\omega)$", column("err_lambda_Hm1"), True,
         HM1)],
}

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


def errors(kind, arguments):
    """The table ``errors`` of the runs @p arguments (report.csv[=LABEL])."""
    runs = list(labelled(arguments))
    header = (["mesh"] if len(runs) > 1 else []) + ["DoFs"] + \
        [title for title, _, _, _ in ERROR_TABLES[kind]]
    table = []
    for path, label in runs:
        rows = read_report(path)
        for index, (before, row) in enumerate(zip([None] + rows, rows)):
            if index < len(rows) - SHOWN_CYCLES:
                continue
            first = index == max(len(rows) - SHOWN_CYCLES, 0)
            line = [label if first else ""] if len(runs) > 1 else []
            line.append(row["dofs"])
            for _, quantity, with_rate, digits in ERROR_TABLES[kind]:
                error = quantity(row)
                if before is None or not with_rate:
                    line.append(f"{error:{digits}}")
                else:
                    h_ratio = math.sqrt(value(row, "dofs") /
                                        value(before, "dofs"))
                    rate = math.log(quantity(before) / error) / \
                        math.log(h_ratio)
                    line.append(f"{error:{digits}} ({rate:.2f})")
            table.append(line)
    return markdown(header, table, "l" * (len(runs) > 1) +
                    "r" * (len(header) - (len(runs) > 1)))


def adaptive(path):
    """Every sixth cycle and the last of an adaptive run."""
    rows = read_report(path)
    shown = [row for index, row in enumerate(rows)
             if index % 6 == 0 or index == len(rows) - 1]
    header = ["cycle", "DoFs", "energy error", "estimator $\\eta$",
              "effectivity $\\eta$ / error", "action error on $\\omega$",
              "action error in $H^{-1}(\\omega)$"]
    table = [[row["cycle"], row["dofs"], f"{value(row, 'err_energy'):.3e}",
              f"{value(row, 'estimator'):.3e}",
              f"{value(row, 'effectivity'):.2f}",
              f"{value(row, 'err_lambda_L2'):.3e}",
              f"{value(row, 'err_lambda_Hm1'):{HM1}}"] for row in shown]
    return markdown(header, table, "rrrrrrr")


def solver(arguments):
    """One row per run: the active set iterations and active vertices of
    each cycle, and the CG iterations of the last one."""
    header = ["run", "DoFs, first to last cycle",
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
    header = ["run", "relative KKT residual",
              "Proposition 12: $\\max_a\\vert\\lambda_{1a}-\\lambda_{2a}\\vert d_a/F_\\infty$",
              "(4.8): $\\max_a\\vert\\lambda_ad_aw_a\\vert/(F_\\infty U_{\\max})$",
              "$\\min_aw_a$", "$\\min_a\\lambda_a$"]
    table = []
    for path, label in labelled(arguments):
        last = read_report(path)[-1]
        table.append([label] + [short(value(last, c)) for c in columns])
    return markdown(header, table, "l" + "r" * len(columns))


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
    """The lines of cycle @p cycle in a run's terminal output up to its
    summary line, in a code block."""
    lines, inside = [], False
    with open(path) as stream:
        for line in stream:
            if line.startswith("Cycle "):
                inside = line.startswith(f"Cycle {cycle}:")
            elif not line.startswith("      "):
                inside = False
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
    header = ["scene", "rate, uniform", "rate, adaptive",
              "effectivity, largest / smallest"]
    table = []
    for scene, name in [("lshape", "L-shape"), ("slit", "slit")]:
        for cells in ["q1", "p1"]:
            prefix = os.path.join(directory, f"{scene}-{cells}-")
            uniform = read_report(prefix + "uniform/report.csv")
            adaptive_rows = read_report(prefix + "adaptive/report.csv")
            table.append([
                f"{name} {cells.upper()}",
                f"{adaptivity_table.rate(uniform)[0]:.3f}",
                f"{adaptivity_table.rate(adaptive_rows)[0]:.3f}",
                f"{adaptivity_table.effectivity_band(adaptive_rows):.2f}"])
    return markdown(header, table, "lrrr")


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


def numbers_of(cell):
    """The numbers of a cell "error" or "error (rate)"."""
    return cell.replace("(", " ").replace(")", " ").split()


def agree(documented, computed):
    if documented == computed:
        return True
    a, b = numbers_of(documented), numbers_of(computed)
    if len(a) != len(b):
        return False
    try:
        a, b = [float(x) for x in a], [float(x) for x in b]
    except ValueError:
        return False
    # The error to 1e-3 relative (as printed: a value of two digits must
    # print the same), the rate (the second number) to 0.011.
    return abs(a[0] - b[0]) <= 1e-3 * max(abs(a[0]), abs(b[0])) and \
        all(abs(x - y) <= 0.011 for x, y in zip(a[1:], b[1:]))


def run_rows(rows, label):
    """The rows of the run @p label of a table whose first column labels
    runs (on their first row only), without that column."""
    kept, current = [], None
    for row in rows:
        current = row[0] or current
        if current.lower() == label.lower():
            kept.append(row[1:])
    return kept


def check(document, name, report):
    label = None
    try:
        text = block_text(document, name)
    except ValueError:
        if "-" not in name:
            raise
        name, label = name.rsplit("-", 1)
        text = block_text(document, name)
    documented = table_cells(text)
    if not documented:
        raise ValueError(f"{document}, {name}: no table")
    header = documented[0][1:] if label else documented[0]
    tables = [errors(kind, [report]) for kind in ERROR_TABLES] + \
        [adaptive(report)]
    kinds = [table for table in tables if table_cells(table)[0] == header]
    if not kinds:
        raise ValueError(f"{document}, {name}: a header that no table of "
                         f"errors or adaptive has: {documented[0]}")
    computed = table_cells(kinds[0])[1:]
    documented = run_rows(documented[1:], label) if label \
        else documented[1:]
    if len(documented) != len(computed):
        raise ValueError(f"{document}, {name}: {len(documented)} rows"
                         f"{' of ' + label if label else ''}, "
                         f"{report}: {len(computed)}")
    for documented_row, computed_row in zip(documented, computed):
        for column, (a, b) in enumerate(zip(documented_row, computed_row)):
            if len(documented_row) != len(computed_row) or not agree(a, b):
                raise ValueError(
                    f"{document}, {name}: DoFs {computed_row[0]}, "
                    f"{header[column]}: {a} in the document, {b} in "
                    f"{report} (doc/make_results.sh makes the tables anew)")
    print(f"{document}, {name}{' ' + label if label else ''}: "
          f"{len(computed)} rows agree with {report}")
    return None


def main(argv):
    commands = {
        "errors": lambda a: errors(a[0], a[1:]),
        "adaptive": lambda a: adaptive(*a),
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
