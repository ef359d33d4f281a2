#!/usr/bin/env python3
"""Adaptive against uniform refinement on the L-shape (see adaptivity.sh).

Usage::

    adaptivity_table.py LABEL uniform/report.csv adaptive/report.csv
                        [LABEL uniform/report.csv adaptive/report.csv ...]

One triple per cell type, e.g. ``Q1 q1-uniform/report.csv
q1-adaptive/report.csv``. For each triple, prints one table per run, then the
comparison:

* the energy error of the finest uniform cycle, and the first adaptive cycle
  whose energy error is at most that, with its DoFs and cumulative wall time
  as ratios of the finest uniform cycle's DoFs and cumulative wall time;
* least-squares rates in DoFs: r in err_energy ~ N^(-r), fitted to the last
  half of the cycles of each run;
* the effectivity band (max / min of estimator / err_energy) of each run;
* the most active-set iterations on a cycle after the first;
* the largest share of the estimator in the wall time of a cycle.

and one PASS/FAIL line per target:

* the adaptive run reaches the finest uniform energy error with at most 1/10
  of its DoFs and at most 1/5 of its cumulative wall time;
* at most 4 active-set iterations on every cycle after the first (each run);
* the estimator costs at most 30 % of the wall time of a cycle (each run;
  cycles shorter than 0.05 s are left out, their timings are noise);
* effectivity band max/min at most 2 (each run).

Exit status 1 if a target is missed or a report lacks a column it needs.
"""

import csv
import math
import sys

from solver_cost_table import fmt, number, print_table

MAX_DOFS_RATIO = 1 / 10
MAX_TIME_RATIO = 1 / 5
MAX_ACTIVE_SET_ITERATIONS = 4
MAX_ESTIMATOR_SHARE = 0.30
MIN_TIMED_CYCLE_S = 0.05
MAX_EFFECTIVITY_BAND = 2.0

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
    header = ["cycle", "dofs", "err_energy", "estimator", "effectivity",
              "AS its", "wall s", "estimate s", "estimate share", "cumulative s"]
    body = []
    for r in rows:
        share = estimator_share(r)
        body.append([r["cycle"], r["dofs"],
                     fmt(number(r, "err_energy"), ".4e"),
                     fmt(number(r, "estimator"), ".4e"),
                     fmt(number(r, "effectivity"), ".3f"),
                     r["active_set_iterations"],
                     fmt(number(r, "wall_time_s"), ".3f"),
                     fmt(number(r, "time_estimate_s"), ".3f"),
                     "-" if share is None else f"{100 * share:.1f} %",
                     fmt(number(r, "cumulative_wall_time_s"), ".3f")])
    print_table(header, body)
    print()


def rate(rows):
    """(r, first cycle, last cycle): least-squares fit of
    log err_energy = c - r log N over the last half of the cycles."""
    points = [(math.log(number(r, "dofs")), math.log(number(r, "err_energy")), r["cycle"])
              for r in rows[len(rows) // 2:]
              if (number(r, "err_energy") or 0) > 0 and (number(r, "dofs") or 0) > 0]
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


def effectivity_band(rows):
    """(max/min, min, max) of the effectivity over the cycles."""
    values = [v for v in (number(r, "effectivity") for r in rows) if v and v > 0]
    if not values:
        return None, None, None
    return max(values) / min(values), min(values), max(values)


def max_active_set_iterations(rows):
    """(most active-set iterations, cycle) after the first cycle."""
    later = [(int(r["active_set_iterations"]), int(r["cycle"])) for r in rows[1:]]
    return max(later) if later else (None, None)


def max_estimator_share(rows, min_wall=0.0):
    """(largest estimator share, cycle) over cycles with wall_time_s >= min_wall."""
    shares = [(estimator_share(r), int(r["cycle"])) for r in rows
              if (number(r, "wall_time_s") or 0) >= min_wall
              and estimator_share(r) is not None]
    return max(shares) if shares else (None, None)


def ratio(value):
    """A ratio, also as 1/x when below one."""
    return f"{value:.3f}" + (f" = 1/{1 / value:.1f}" if 0 < value < 1 else "")


def verdict(passed):
    return "PASS" if passed else "FAIL"


def compare(label, uniform, adaptive):
    """Print the comparison and the PASS/FAIL lines; True if all pass."""
    ok = True
    finest = uniform[-1]
    target = number(finest, "err_energy")
    n_uniform = number(finest, "dofs")
    t_uniform = number(finest, "cumulative_wall_time_s")
    print(f"### {label}: comparison")
    print()
    print(f"finest uniform cycle {finest['cycle']}: {int(n_uniform)} DoFs, "
          f"err_energy {fmt(target, '.4e')}, cumulative wall time "
          f"{fmt(t_uniform, '.3f')} s")
    reached = next((r for r in adaptive
                    if target is not None and number(r, "err_energy") is not None
                    and number(r, "err_energy") <= target), None)
    if reached is not None:
        n_ratio = number(reached, "dofs") / n_uniform
        t_ratio = number(reached, "cumulative_wall_time_s") / t_uniform
        print(f"first adaptive cycle with err_energy <= that: cycle "
              f"{reached['cycle']}, {reached['dofs']} DoFs, err_energy "
              f"{fmt(number(reached, 'err_energy'), '.4e')}, cumulative wall "
              f"time {fmt(number(reached, 'cumulative_wall_time_s'), '.3f')} s")
        print(f"  DoFs ratio adaptive/uniform {ratio(n_ratio)}, "
              f"cumulative wall time ratio adaptive/uniform {ratio(t_ratio)}")
    else:
        last = adaptive[-1]
        print(f"no adaptive cycle reaches err_energy <= {fmt(target, '.4e')}: "
              f"the finest, cycle {last['cycle']} with {last['dofs']} DoFs "
              f"({number(last, 'dofs') / n_uniform:.3f} of the uniform DoFs), "
              f"has {fmt(number(last, 'err_energy'), '.4e')}")
        n_ratio = t_ratio = None
    for name, rows in (("uniform", uniform), ("adaptive", adaptive)):
        r, first, last = rate(rows)
        band, low, high = effectivity_band(rows)
        print(f"{name}: err_energy ~ N^-{fmt(r, '.3f')} (least squares over "
              f"cycles {first}..{last}), effectivity {fmt(low, '.3f')}.."
              f"{fmt(high, '.3f')}, band max/min {fmt(band, '.3f')}")
    print()

    passed = n_ratio is not None and n_ratio <= MAX_DOFS_RATIO
    print(f"{verdict(passed)} {label}: adaptive reaches the finest uniform "
          f"err_energy with <= 1/{1 / MAX_DOFS_RATIO:g} of its DoFs: "
          + (f"ratio {ratio(n_ratio)}" if n_ratio is not None else "not reached"))
    ok &= passed
    passed = t_ratio is not None and t_ratio <= MAX_TIME_RATIO
    print(f"{verdict(passed)} {label}: adaptive reaches the finest uniform "
          f"err_energy with <= 1/{1 / MAX_TIME_RATIO:g} of its cumulative wall "
          f"time: " + (f"ratio {ratio(t_ratio)}" if t_ratio is not None else "not reached"))
    ok &= passed

    for name, rows in (("uniform", uniform), ("adaptive", adaptive)):
        worst, at = max_active_set_iterations(rows)
        passed = worst is not None and worst <= MAX_ACTIVE_SET_ITERATIONS
        print(f"{verdict(passed)} {label} {name}: active-set iterations <= "
              f"{MAX_ACTIVE_SET_ITERATIONS} on every cycle after the first: "
              + (f"max {worst} (cycle {at})" if worst is not None
                 else "the run has a single cycle"))
        ok &= passed
    for name, rows in (("uniform", uniform), ("adaptive", adaptive)):
        share, at = max_estimator_share(rows, MIN_TIMED_CYCLE_S)
        all_share, all_at = max_estimator_share(rows)
        passed = share is not None and share <= MAX_ESTIMATOR_SHARE
        print(f"{verdict(passed)} {label} {name}: estimator <= "
              f"{100 * MAX_ESTIMATOR_SHARE:g} % of a cycle's wall time "
              f"(cycles with wall_time_s >= {MIN_TIMED_CYCLE_S:g} s): "
              + (f"max {100 * share:.1f} % (cycle {at})" if share is not None
                 else "no such cycle")
              + (f"; over all cycles {100 * all_share:.1f} % (cycle {all_at})"
                 if all_share is not None else ""))
        ok &= passed
    for name, rows in (("uniform", uniform), ("adaptive", adaptive)):
        band, _, _ = effectivity_band(rows)
        passed = band is not None and band <= MAX_EFFECTIVITY_BAND
        print(f"{verdict(passed)} {label} {name}: effectivity band max/min <= "
              f"{MAX_EFFECTIVITY_BAND:g}: {fmt(band, '.3f')}")
        ok &= passed
    print()
    return ok


def main(argv):
    arguments = argv[1:]
    if not arguments or len(arguments) % 3:
        sys.exit(__doc__)
    ok = True
    for i in range(0, len(arguments), 3):
        label, uniform_path, adaptive_path = arguments[i:i + 3]
        try:
            uniform = read_report(uniform_path)
            adaptive = read_report(adaptive_path)
        except (ReportError, ValueError) as error:
            print(f"adaptivity_table.py: error: {error}", file=sys.stderr)
            return 1
        print(f"## {label}")
        print()
        run_table(f"{label} uniform ({uniform_path})", uniform)
        run_table(f"{label} adaptive ({adaptive_path})", adaptive)
        ok &= compare(label, uniform, adaptive)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
