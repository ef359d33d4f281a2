#!/usr/bin/env python3
"""Adaptive against uniform refinement at equal error (see adaptivity.sh).

Usage::

    adaptivity_table.py LABEL DOFS_RATIO TIME_RATIO uniform/report.csv
                        adaptive/report.csv [more/report.csv ...] [-- ...]

One group per scene and cell type, groups separated by ``--``, e.g.
``'slit Q1' 0.05 0.1 q1-uniform/report.csv q1-adaptive/report.csv
q1-growth/report.csv``. The first adaptive run is the one the targets apply
to; further ones (the same scene with other marking settings) are compared
in the same way, for their error per DoF and cost per DoF, without targets.

For each group it prints one table per run and then the comparison at
equal error. The energy error e_u of the finest uniform cycle is located
between two adaptive cycles (the first with err_energy <= e_u and the one
before), and their DoFs N and cumulative wall times T are interpolated
log-log in the error: log N = log N_0 + (log N_1 - log N_0) (log e_u - log
e_0) / (log e_1 - log e_0), likewise T. The ratios N/N_u and T/T_u are those
of an adaptive run that stops exactly at the uniform error. Also printed,
for each run:

* the least-squares rate r in err_energy ~ N^(-r) over the last half of its
  cycles, and the constant err_energy sqrt(N) of its last cycle (the error
  per DoF: N^(-1/2) is the best rate of P1/Q1 in two dimensions);
* the cost per DoF: cumulative wall time / DoFs of its last cycle; for an
  adaptive run also as a ratio to that of the uniform cycle of the closest
  size (in log N);
* the effectivity band (max / min of estimator / err_energy), the most
  active-set iterations on a cycle after the first, and the largest share
  of the estimator in the wall time of a cycle (cycles of at least 0.05 s;
  shorter ones are timer noise).

One PASS/FAIL line per target, on the first adaptive run of each group:

* DoF ratio <= DOFS_RATIO and time ratio <= TIME_RATIO at equal error;
* adaptive rate >= 0.45 in N;
* cost per final DoF <= 1.3 times that of the uniform run of similar size;
* at most 4 active-set iterations on every cycle after the first (both
  runs); the estimator <= 15 % of the wall time of a cycle (both runs);
* effectivity band max/min <= 1.6 (both runs).

Exit status 1 if a target is missed or a report lacks a column it needs.
"""

import csv
import math
import os
import sys

from solver_cost_table import fmt, number, print_table

MIN_ADAPTIVE_RATE = 0.45
MAX_COST_RATIO = 1.3
MAX_ACTIVE_SET_ITERATIONS = 4
MAX_ESTIMATOR_SHARE = 0.15
MIN_TIMED_CYCLE_S = 0.05
MAX_EFFECTIVITY_BAND = 1.6

NEEDED = ("cycle", "dofs", "active_set_iterations", "wall_time_s",
          "cumulative_wall_time_s", "err_energy", "estimator", "effectivity",
          "time_estimate_s")


class ReportError(Exception):
    """An input problem worth a one-line message."""


def read_report(path):
    """The rows of a report.csv as dicts keyed by column name."""
    try:
        with open(path, newline="") as f:
            reader = csv.DictReader(f)
            rows = list(reader)
            header = reader.fieldnames or []
    except OSError as error:
        raise ReportError(f"cannot read {path}: {error.strerror}") from error
    missing = [c for c in NEEDED if c not in header]
    if missing:
        raise ReportError(f"{path}: no column {', '.join(missing)}")
    if not rows:
        raise ReportError(f"{path}: no rows")
    return rows


def estimator_share(row):
    """time_estimate_s / wall_time_s of a cycle, None if not available."""
    estimate, wall = number(row, "time_estimate_s"), number(row, "wall_time_s")
    return estimate / wall if estimate is not None and wall else None


def run_table(name, rows):
    print(f"### {name}")
    print()
    header = ["cycle", "dofs", "err_energy", "err sqrt(N)", "effectivity",
              "AS its", "wall s", "estimate share", "cumulative s",
              "cumulative us/DoF"]
    body = []
    for r in rows:
        share = estimator_share(r)
        dofs, error = number(r, "dofs"), number(r, "err_energy")
        cumulative = number(r, "cumulative_wall_time_s")
        body.append([r["cycle"], r["dofs"], fmt(error, ".4e"),
                     fmt(error * math.sqrt(dofs), ".2f"),
                     fmt(number(r, "effectivity"), ".3f"),
                     r["active_set_iterations"],
                     fmt(number(r, "wall_time_s"), ".3f"),
                     "-" if share is None else f"{100 * share:.1f} %",
                     fmt(cumulative, ".3f"),
                     fmt(1e6 * cumulative / dofs, ".1f")])
    print_table(header, body)
    print()


def rate(rows, column="err_energy"):
    """(r, first cycle, last cycle): least-squares fit of
    log column = c - r log N over the last half of the cycles."""
    points = [(math.log(number(r, "dofs")), math.log(number(r, column)),
               r["cycle"])
              for r in rows[len(rows) // 2:]
              if (number(r, column) or 0) > 0]
    if len(points) < 2:
        return None, None, None
    n = len(points)
    mx = sum(p[0] for p in points) / n
    my = sum(p[1] for p in points) / n
    sxx = sum((p[0] - mx) ** 2 for p in points)
    if sxx == 0:
        return None, None, None
    slope = sum((p[0] - mx) * (p[1] - my) for p in points) / sxx
    return -slope, points[0][2], points[-1][2]


def at_error(rows, target):
    """(N, T, cycle) of the run interpolated log-log to err_energy = target
    between the first cycle at or below it and the one before; None if no
    cycle reaches it."""
    for before, row in zip([None] + rows, rows):
        error = number(row, "err_energy")
        if error is None or error > target:
            continue
        n, t = number(row, "dofs"), number(row, "cumulative_wall_time_s")
        if before is None or error == target:
            return n, t, row["cycle"]
        e0 = number(before, "err_energy")
        s = math.log(target / e0) / math.log(error / e0)
        n0 = number(before, "dofs")
        t0 = number(before, "cumulative_wall_time_s")
        return (n0 * (n / n0) ** s, t0 * (t / t0) ** s,
                f"{before['cycle']}..{row['cycle']}")
    return None


def cost_per_dof(row):
    return number(row, "cumulative_wall_time_s") / number(row, "dofs")


def closest(rows, dofs):
    """The row of @p rows whose DoFs are closest to @p dofs in log scale."""
    return min(rows, key=lambda r: abs(math.log(number(r, "dofs") / dofs)))


def effectivity_band(rows):
    values = [v for v in (number(r, "effectivity") for r in rows) if v and v > 0]
    return max(values) / min(values) if values else None


def max_active_set_iterations(rows):
    later = [int(r["active_set_iterations"]) for r in rows[1:]]
    return max(later) if later else None


def max_estimator_share(rows):
    shares = [estimator_share(r) for r in rows
              if (number(r, "wall_time_s") or 0) >= MIN_TIMED_CYCLE_S
              and estimator_share(r) is not None]
    return max(shares) if shares else None


def ratio(value):
    """A ratio, also as 1/x when below one."""
    if value is None:
        return "-"
    return f"{value:.3f}" + (f" = 1/{1 / value:.1f}" if 0 < value < 1 else "")


def verdict(passed):
    return "PASS" if passed else "FAIL"


def compare(label, dofs_ratio, time_ratio, uniform_path, adaptive_paths):
    """Print the tables, the comparison and the PASS/FAIL lines; True if all
    pass."""
    uniform = read_report(uniform_path)
    runs = [(path, read_report(path)) for path in adaptive_paths]
    print(f"## {label}")
    print()
    run_table(f"{label} uniform ({uniform_path})", uniform)
    for path, rows in runs:
        run_table(f"{label} adaptive ({path})", rows)

    finest = uniform[-1]
    target = number(finest, "err_energy")
    n_u, t_u = number(finest, "dofs"), number(finest, "cumulative_wall_time_s")
    print(f"### {label}: at the energy error {target:.4e} of the finest "
          f"uniform cycle ({int(n_u)} DoFs, {t_u:.2f} s cumulative)")
    print()
    header = ["run", "cycles", "N at e_u", "N/N_u", "T at e_u s", "T/T_u",
              "rate in N", "last err sqrt(N)", "us/DoF", "us/DoF / uniform",
              "effectivity band", "max AS its", "max estimate share"]
    body, measured = [], []
    named = [(os.path.basename(os.path.dirname(os.path.abspath(path))), rows)
             for path, rows in runs]
    for name, rows in [("uniform", uniform)] + named:
        reached = at_error(rows, target) if name != "uniform" else None
        r, _, _ = rate(rows)
        last = rows[-1]
        cost_ratio = (cost_per_dof(last) /
                      cost_per_dof(closest(uniform, number(last, "dofs")))
                      if name != "uniform" else None)
        share = max_estimator_share(rows)
        values = {
            "n_ratio": reached[0] / n_u if reached else None,
            "t_ratio": reached[1] / t_u if reached else None,
            "rate": r, "cost_ratio": cost_ratio,
            "band": effectivity_band(rows),
            "iterations": max_active_set_iterations(rows), "share": share}
        measured.append(values)
        body.append([name, reached[2] if reached else "-",
                     fmt(reached[0], ".0f") if reached else "-",
                     ratio(values["n_ratio"]),
                     fmt(reached[1], ".2f") if reached else "-",
                     ratio(values["t_ratio"]), fmt(r, ".3f"),
                     fmt(number(last, "err_energy") *
                         math.sqrt(number(last, "dofs")), ".2f"),
                     fmt(1e6 * cost_per_dof(last), ".1f"),
                     fmt(cost_ratio, ".2f"), fmt(values["band"], ".3f"),
                     fmt(values["iterations"], "d"),
                     "-" if share is None else f"{100 * share:.1f} %"])
    print_table(header, body)
    print()

    def at_most(value, bound):
        return value is not None and value <= bound

    uniform_values, adaptive_values = measured[0], measured[1]
    checks = [
        (at_most(adaptive_values["n_ratio"], dofs_ratio),
         f"DoF ratio at equal error <= {dofs_ratio:g}: "
         f"{ratio(adaptive_values['n_ratio'])}"),
        (at_most(adaptive_values["t_ratio"], time_ratio),
         f"cumulative time ratio at equal error <= {time_ratio:g}: "
         f"{ratio(adaptive_values['t_ratio'])}"),
        ((adaptive_values["rate"] or 0) >= MIN_ADAPTIVE_RATE,
         f"adaptive rate in N >= {MIN_ADAPTIVE_RATE}: "
         f"{fmt(adaptive_values['rate'], '.3f')}"),
        (at_most(adaptive_values["cost_ratio"], MAX_COST_RATIO),
         f"adaptive cost per final DoF <= {MAX_COST_RATIO} x uniform: "
         f"{fmt(adaptive_values['cost_ratio'], '.2f')}")]
    for name, values in (("uniform", uniform_values),
                         ("adaptive", adaptive_values)):
        share = values["share"]
        checks += [
            (at_most(values["iterations"], MAX_ACTIVE_SET_ITERATIONS),
             f"{name}: active-set iterations after the first cycle <= "
             f"{MAX_ACTIVE_SET_ITERATIONS}: {fmt(values['iterations'], 'd')}"),
            (at_most(share, MAX_ESTIMATOR_SHARE),
             f"{name}: estimator <= {100 * MAX_ESTIMATOR_SHARE:g} % of a "
             f"cycle: " + ("-" if share is None else f"{100 * share:.1f} %")),
            (at_most(values["band"], MAX_EFFECTIVITY_BAND),
             f"{name}: effectivity band max/min <= {MAX_EFFECTIVITY_BAND}: "
             f"{fmt(values['band'], '.3f')}")]
    for passed, text in checks:
        print(f"{verdict(passed)} {label}: {text}")
    print()
    return all(passed for passed, _ in checks)


def groups(arguments):
    """Split the arguments at '--' into groups of at least five."""
    group = []
    for argument in arguments + ["--"]:
        if argument != "--":
            group.append(argument)
            continue
        if len(group) < 5:
            raise ValueError("each group needs LABEL DOFS_RATIO TIME_RATIO "
                             "uniform.csv adaptive.csv")
        yield group[0], float(group[1]), float(group[2]), group[3], group[4:]
        group = []


def main(argv):
    try:
        ok = True
        for label, dofs_ratio, time_ratio, uniform, adaptive in list(
                groups(argv[1:])):
            ok &= compare(label, dofs_ratio, time_ratio, uniform, adaptive)
    except (ReportError, ValueError) as error:
        print(f"adaptivity_table.py: error: {error}", file=sys.stderr)
        return 1
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
