#!/usr/bin/env python3
"""The table of the stability suite, from the runs of stability.sh.

Usage::

    stability_table.py OUTPUT-DIR

OUTPUT-DIR holds ``cases`` (the case names, one per line, in run order) and,
for each case NAME, ``NAME/report.csv`` and ``NAME.log``. One row per case,
over all its cycles: the DoFs and mesh levels of the last cycle, the active
set iterations of every cycle, the largest relative KKT residual, the
smallest u1h - u2h and lambda_a at a vertex, the largest complementarity
defect max |lambda_a d_a (u1h - u2h)(a)| / (F max|u_h|) of (4.8), and the
cumulative wall time. A case whose run stopped with an error shows the
program's message instead.

Then one PASS/FAIL line per target:

* every case converges to a relative KKT residual <= 1e-10 on every cycle;
* every scaled case (a name with ``*``: data or tensions multiplied by a
  factor) has the same DoFs, active set iterations and active vertices on
  every cycle as its unscaled case (``unscaled`` for case M, the tension
  ratio 1 case for ``... data*F``, the part of the name before ``*``
  otherwise);
* every case needs at most 4 active set iterations on each cycle after the
  first;
* every case with a tension ratio (``mu1:mu2=R`` in the name) needs at most
  one active set iteration more than the case of ratio 1 of the same scene
  and cell type on each cycle they share.

Exit status 1 if a line says FAIL.
"""

import csv
import os
import sys

TOLERANCE = 1e-10
MAX_ITERATIONS_AFTER_FIRST = 4


def read_report(path):
    """The rows of a report.csv as dicts, [] if it is missing."""
    if not os.path.isfile(path):
        return []
    with open(path, newline="") as stream:
        return list(csv.DictReader(stream))


def error_line(log):
    """The program's error message in a log, or None."""
    if not os.path.isfile(log):
        return "no log"
    with open(log) as stream:
        for line in stream:
            if line.startswith("membranes: error: "):
                return line[len("membranes: error: "):].strip()
    return None


def column(rows, name):
    return [float(row[name]) for row in rows if row[name] != ""]


def unscaled_case(name):
    """The case a scaled case is compared with."""
    base = name.split("*")[0]
    if base in ("loads,g", "mu1,mu2"):
        return "unscaled"
    if base.endswith(" data"):
        return base[:-len(" data")] + " mu1:mu2=1"
    return base


def ratio_one_case(name):
    """The tension ratio 1 case of a case with a tension ratio, or None."""
    if "mu1:mu2=" not in name:
        return None
    head, tail = name.split("mu1:mu2=", 1)
    return head.replace(" coupled", "") + "mu1:mu2=1"


def main(argv):
    if len(argv) != 2:
        sys.exit(__doc__)
    out = argv[1]
    with open(os.path.join(out, "cases")) as stream:
        cases = [line.strip() for line in stream if line.strip()]

    header = ["case", "DoFs", "levels", "AS its per cycle", "KKT max",
              "min(u1h-u2h)", "min lambda_a", "(4.8) defect", "time s"]
    rows, reports, problems = [], {}, []
    for case in cases:
        report = read_report(os.path.join(out, case, "report.csv"))
        reports[case] = report
        error = error_line(os.path.join(out, case + ".log"))
        if not report:
            rows.append([case] + ["-"] * (len(header) - 1))
        else:
            last = report[-1]
            kkt = max(column(report, "kkt_residual"))
            rows.append([
                case, last["dofs"], last["levels"],
                " ".join(row["active_set_iterations"] for row in report),
                f"{kkt:.1e}", f"{min(column(report, 'min_w')):.1e}",
                f"{min(column(report, 'min_lambda')):.1e}",
                f"{max(column(report, 'complementarity_defect')):.1e}",
                f"{float(last['cumulative_wall_time_s']):.2f}"])
            if kkt > TOLERANCE:
                problems.append(f"{case}: KKT residual {kkt:.2e}")
        if error:
            rows[-1][-1] += " (stopped)"
            problems.append(f"{case}: {error}")

    widths = [max(len(str(row[i])) for row in [header] + rows)
              for i in range(len(header))]
    print("| " + " | ".join(h.ljust(w) for h, w in zip(header, widths)) + " |")
    print("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    for row in rows:
        print("| " + " | ".join(str(c).ljust(w) if i == 0 else str(c).rjust(w)
                                for i, (c, w) in enumerate(zip(row, widths)))
              + " |")
    print()

    ok = not problems
    print(f"{'PASS' if ok else 'FAIL'} every case converges to a relative "
          f"KKT residual <= {TOLERANCE:g} on every cycle")
    for problem in problems:
        print("  " + problem)

    for case in cases:
        if "*" not in case:
            continue
        base = unscaled_case(case)
        keys = ("dofs", "active_set_iterations", "active_vertices")
        same = (reports.get(base) and reports[case] and
                [[r[k] for k in keys] for r in reports[case]] ==
                [[r[k] for k in keys] for r in reports[base]])
        print(f"{'PASS' if same else 'FAIL'} {case}: the same DoFs, active "
              f"set iterations and active vertices on every cycle as {base}")
        ok &= bool(same)

    iterations = {case: [int(row["active_set_iterations"])
                         for row in report]
                  for case, report in reports.items()}
    worst = [(case, max(its[1:])) for case, its in iterations.items()
             if len(its) > 1 and max(its[1:]) > MAX_ITERATIONS_AFTER_FIRST]
    print(f"{'PASS' if not worst else 'FAIL'} at most "
          f"{MAX_ITERATIONS_AFTER_FIRST} active set iterations on every "
          f"cycle after the first")
    for case, count in worst:
        print(f"  {case}: {count}")
    ok &= not worst

    for case in cases:
        reference = ratio_one_case(case)
        if reference is None or reference == case:
            continue
        its, ref = iterations.get(case, []), iterations.get(reference, [])
        n = min(len(its), len(ref))
        within = bool(ref) and len(its) >= n > 0 and all(
            its[i] <= ref[i] + 1 for i in range(n))
        print(f"{'PASS' if within else 'FAIL'} {case}: at most one active "
              f"set iteration more than {reference} on each of its "
              f"{n} cycles")
        ok &= within
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
