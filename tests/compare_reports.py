#!/usr/bin/env python3
"""Compare two CSV files row by row, in selected columns or (--report) in
every column: membranes report.csv files, or the nodal-values-NN.csv files
of two runs.

Usage::

    compare_reports.py a.csv b.csv [--columns c1,c2,...] [--empty c1,c2,...]
                       --rtol R [--atol A] [--scale value|column]
                       [--one-sided]
    compare_reports.py a.csv b.csv --report --rtol R [--factor F]

(``--columns``, ``--empty`` or both, or ``--report``.)

The files must have the same number of data rows, and for every named column
and every row the two values must satisfy

    |a - b| <= atol + rtol * S                    (atol defaults to 0),

with S = max(|a|, |b|) (``--scale value``, the default), or S the largest
|a| or |b| over the whole column (``--scale column``: the difference relative
to the max norm, the right measure for nodal values that pass through zero).
With ``--rtol 0`` (and no ``--atol``) the values must be equal, which is
the right test for integer columns such as ``dofs`` or ``active_vertices``.
Two empty fields agree (a column such as ``eta_linearization`` is empty on
the first mesh); an empty field never agrees with a number; NaN never agrees
with anything.  A column empty in every row of both files compares nothing,
and fails, unless ``--empty`` names it: the columns ``--empty`` names are
expected to be empty in every row of both files, and fail otherwise; an
error or effectivity column that ``--empty`` names may also be absent from
both (a run leaves out what it does not compute).
With ``--one-sided`` only b - a is bounded so (b <= a always agrees): b
costs or errs at most that much more than a, e.g. ``--rtol 0 --one-sided``
on an iteration count says b <= a.  Columns are looked up by name in each
file's header.

With ``--report`` the files are two membranes report.csv files of one
scene, a.csv on one process and b.csv on more, and every column of the
report is compared as its kind in REPORT_COLUMNS says, with R = ``--rtol``
and F = ``--factor`` (default 10):

``count``, a = b
    cycle, cells, dofs, levels, active_set_iterations, active_vertices.
``value``, |a - b| <= R max(|a|, |b|)
    The errors, the estimators and their effectivities, the flux, the
    oscillation and the boundary data parts of the flux estimator,
    eta_linearization.
``contact part``, |a - b| <= 1000 R max(|a|, |b|)
    flux_estimator_contact, (2 B)^(1/2) with B the sum over the cells of
    the positive parts of the integrals of lambda_h (u1h - u2h): away from
    the contact zone, the positive parts of the round-off or algebraic
    error of lambda_a (see min_lambda) times w of size 1. With CG, one
    process at Solver/Tolerance 1e-10 and at 1e-14 differs in it by 5e-6
    relative.
``round-off``, |b - a| <= F S
    kkt_residual, prop12_defect, complementarity_defect, min_w, min_lambda,
    eta_algebraic: zero in exact arithmetic, round-off with the direct
    solver, the residual where CG stops with CG. S is the largest |a| of
    the column in a.csv, the size of its round-off on one process; where
    that column is zero in every row (min_w with contact: w = 0 at the
    active vertices), S = eps = 2.2e-16, the round-off of a number of size
    1, the size of the data of the shipped scenes.
``identity defect``, |a - b| <= R max(|a|, |b|) + F eps
    measure_defect, conservation_defect, balance_defect: the defects of
    (4.17), (4.18) and Lemma 17 relative to the data, round-off on
    triangles, values of the discretization on quadrilaterals (1e-2 to
    1e-5).
``varies``, not compared
    processes; linear_iterations (ML's AMG aggregates and smooths per
    process).
``cost``, not compared
    The wall times (wall_time_s, cumulative_wall_time_s, time_*_s) and
    memory_mb.

Two empty fields agree, and so does a column empty in every row of both
files (a quantity the run does not compute); an empty field never agrees
with a number. A column of either report that REPORT_COLUMNS does not
classify fails, and so does one that it classifies and a report lacks: a
new column of the report must be given a kind before it passes. Only the
errors and effectivities, which a run leaves out when it does not compute
them (``Exact solution/Norms``), may be absent, and then from both.

One line ``PASS ...`` or ``FAIL ...`` is printed for the row count and for
each column (``SKIP ...`` and why for a column not compared), giving the
largest difference found and the tolerance.  Exit status: 0 if everything
agrees, 1 otherwise (including a missing or malformed file or an unknown
column), 2 on a command-line error.
"""

import argparse
import math
import sys

from check_report import ReportError, parse_number, read_csv

PROG = "compare_reports.py"

COUNT, VALUE, CONTACT, ROUND_OFF, IDENTITY, VARIES, COST = (
    "count", "value", "contact part", "round-off", "identity defect",
    "varies", "cost")

# --report: the kind of every column of report.csv (module docstring).
REPORT_COLUMNS = {
    **dict.fromkeys(("cycle", "cells", "dofs", "levels",
                     "active_set_iterations", "active_vertices"), COUNT),
    **dict.fromkeys(("err_u1_H1", "err_u2_H1", "err_u1_L2", "err_u2_L2",
                     "err_lambda_L2", "err_lambda_L2_omega_h",
                     "err_lambda_Hm1", "err_energy",
                     "estimator", "effectivity", "flux_estimator",
                     "flux_effectivity", "flux_estimator_flux",
                     "flux_estimator_oscillation", "flux_estimator_boundary",
                     "eta_linearization"), VALUE),
    "flux_estimator_contact": CONTACT,
    **dict.fromkeys(("kkt_residual", "prop12_defect",
                     "complementarity_defect", "min_w", "min_lambda",
                     "eta_algebraic"), ROUND_OFF),
    **dict.fromkeys(("measure_defect", "conservation_defect",
                     "balance_defect"), IDENTITY),
    "processes": VARIES,
    "linear_iterations": VARIES,
    **dict.fromkeys(("wall_time_s", "cumulative_wall_time_s", "time_setup_s",
                     "time_assembly_s", "time_solve_s", "time_postprocess_s",
                     "time_estimate_s", "time_flux_s", "time_errors_s",
                     "memory_mb"), COST),
}

# The columns against the exact solution, which a run that does not compute
# them leaves out of report.csv: absent from both reports, they are skipped.
VERIFICATION = {column for column in REPORT_COLUMNS
                if column.startswith("err_") or column.endswith("effectivity")}

# Why a column of the kind varies or cost is not compared (COST: the
# times).
NOT_COMPARED = {
    "processes": "the number of processes itself",
    "linear_iterations": "CG iterations: ML's AMG aggregates and smooths "
                         "per process",
    "memory_mb": "the peak memory, summed over the processes",
    COST: "a wall time",
}

# The rtol of a kind, as a multiple of --rtol.
RTOL_FACTOR = {COUNT: 0.0, VALUE: 1.0, CONTACT: 1000.0, IDENTITY: 1.0}
EPSILON = sys.float_info.epsilon


def read_report(path):
    """Return (header, rows) of a CSV file, rows as dicts of strings."""
    header, rows = read_csv(path)
    return header, [dict(zip(header, row)) for row in rows]


def fmt(value):
    """Format a number compactly ('empty' for None)."""
    return "empty" if value is None else f"{value:.6g}"


def values_agree(a, b, rtol, atol, scale, one_sided=False):
    """Whether two parsed fields agree within the tolerance; ``scale`` is
    S of the module docstring, or None for max(|a|, |b|); ``one_sided``:
    b <= a always agrees."""
    if a is None or b is None:
        return a is None and b is None
    if a == b or (one_sided and b < a):  # also covers equal infinities
        return True
    if scale is None:
        scale = max(abs(a), abs(b))
    return abs(a - b) <= atol + rtol * scale


def differences(a, b, scale):
    """(|a - b|, |a - b| / S) for reporting; None if undefined."""
    if a is None or b is None or math.isnan(a) or math.isnan(b):
        return None
    if a == b:
        return 0.0, 0.0
    absolute = abs(a - b)
    return absolute, absolute / (max(abs(a), abs(b)) if scale is None
                                 else scale)


def column_scale(values):
    """The largest |value| of a column (None values skipped)."""
    return max((abs(v) for v in values if v is not None), default=0.0)


def compare_column(column, first, second, rtol, atol, scale_by_column,
                   one_sided=False):
    """Compare one column; return (passed, message)."""
    (path_a, rows_a), (path_b, rows_b) = first, second
    pairs = [(record_a[column], record_b[column])
             for record_a, record_b in zip(rows_a, rows_b)]
    numbers = [(parse_number(text_a, path_a, column),
                parse_number(text_b, path_b, column))
               for text_a, text_b in pairs]
    scale = (column_scale([v for pair in numbers for v in pair])
             if scale_by_column else None)
    if all(a is None and b is None for a, b in numbers):
        return False, (f"empty in both files over {len(pairs)} rows: nothing "
                       "to compare (--empty names a column expected empty)")
    mismatches = []
    largest = [0.0, 0.0]
    for row, ((text_a, text_b), (a, b)) in enumerate(zip(pairs, numbers)):
        diff = differences(a, b, scale)
        if diff is not None:
            largest = [max(old, new) for old, new in zip(largest, diff)]
        if not values_agree(a, b, rtol, atol, scale, one_sided):
            mismatches.append(f"row {row}: {text_a or 'empty'} vs "
                              f"{text_b or 'empty'}")
    relative_to = ("" if scale is None else
                   f" (to the column's max {fmt(scale)})")
    message = (f"max |a-b| {fmt(largest[0])}, max relative "
               f"{fmt(largest[1])}{relative_to} over {len(pairs)} rows "
               f"(atol {fmt(atol)}, rtol {fmt(rtol)})")
    if mismatches:
        shown = 5
        message += (f"; differ at {len(mismatches)} rows: "
                    + ", ".join(mismatches[:shown])
                    + (", ..." if len(mismatches) > shown else ""))
    return not mismatches, message


def check_empty_column(column, first, second):
    """Whether a column is empty in every row of both files; return
    (passed, message)."""
    filled = [f"{path} row {row}: {record[column]}"
              for path, rows in (first, second)
              for row, record in enumerate(rows) if record[column].strip()]
    if filled:
        return False, (f"expected empty, has {len(filled)} values: "
                       + ", ".join(filled[:5])
                       + (", ..." if len(filled) > 5 else ""))
    return True, "empty in both files, as expected"


def report_tolerances(column, kind, first, rtol, factor):
    """(rtol, atol, what) of a compared column of --report, ``what`` saying
    how the absolute bound was found ('' if it is zero)."""
    if kind == ROUND_OFF:
        path, rows = first
        largest = column_scale([parse_number(record[column], path, column)
                                for record in rows])
        what = (f"{fmt(factor)} x max |a| {fmt(largest)}" if largest > 0 else
                f"{fmt(factor)} x eps: zero in every row of {path}")
        return 0.0, factor * (largest if largest > 0 else EPSILON), what
    if kind == IDENTITY:
        return rtol, factor * EPSILON, f"{fmt(factor)} x eps"
    return RTOL_FACTOR[kind] * rtol, 0.0, ""


def compare_report_column(column, first, second, rtol, factor):
    """Compare one column of two reports as REPORT_COLUMNS classifies it;
    return (passed, message), passed None for a column not compared."""
    kind = REPORT_COLUMNS[column]
    if kind in (VARIES, COST):
        return None, (f"not compared ({kind}): "
                      + NOT_COMPARED.get(column, NOT_COMPARED[COST]))
    empty, _ = check_empty_column(column, first, second)
    if empty:
        return True, f"{kind}: empty in both files"
    column_rtol, atol, what = report_tolerances(column, kind, first, rtol,
                                                factor)
    passed, message = compare_column(column, first, second, column_rtol,
                                     atol, False)
    return passed, f"{kind}{f' (atol {what})' if what else ''}: {message}"


def compare_whole_reports(arguments):
    """--report: every column; return the list of verdicts."""
    header_a, rows_a = read_report(arguments.first)
    header_b, rows_b = read_report(arguments.second)
    first = (arguments.first, rows_a)
    second = (arguments.second, rows_b)
    print(f"comparing {arguments.first} and {arguments.second}: every "
          f"column (rtol {fmt(arguments.rtol)}, round-off factor "
          f"{fmt(arguments.factor)})")
    verdicts = [report_line(len(rows_a) == len(rows_b), "rows",
                            f"{len(rows_a)} vs {len(rows_b)}")]
    for column in dict.fromkeys(header_a + header_b + list(REPORT_COLUMNS)):
        missing = [path for path, header in ((arguments.first, header_a),
                                             (arguments.second, header_b))
                   if column not in header]
        if column not in REPORT_COLUMNS:
            passed, message = False, ("not classified: give it a kind in "
                                      f"REPORT_COLUMNS of {PROG}")
        elif len(missing) == 2 and column in VERIFICATION:
            passed, message = None, "in neither report (not computed)"
        elif missing:
            passed, message = False, ("classified, but not in "
                                      + " and ".join(missing))
        else:
            try:
                passed, message = compare_report_column(
                    column, first, second, arguments.rtol, arguments.factor)
            except ReportError as error:
                passed, message = False, str(error)
        if passed is None:
            print(f"SKIP {column}: {message}")
        else:
            verdicts.append(report_line(passed, column, message))
    return verdicts


def non_negative_float(text):
    """argparse type for tolerances."""
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not value >= 0:
        raise argparse.ArgumentTypeError(
            f"expected a non-negative number, got {text!r}")
    return value


def column_list(text):
    """argparse type for --columns: a comma separated list of names."""
    columns = [name.strip() for name in text.split(",") if name.strip()]
    if not columns:
        raise argparse.ArgumentTypeError("no column names given")
    return columns


def parse_arguments(argv):
    """Parse the command line."""
    parser = argparse.ArgumentParser(prog=PROG,
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("first", metavar="a.csv")
    parser.add_argument("second", metavar="b.csv")
    parser.add_argument("--columns", type=column_list, default=[],
                        metavar="C1,C2,...", help="columns to compare")
    parser.add_argument("--rtol", type=non_negative_float, required=True,
                        help="relative tolerance")
    parser.add_argument("--atol", type=non_negative_float, default=0.0,
                        help="absolute tolerance (default 0)")
    parser.add_argument("--scale", choices=("value", "column"),
                        default="value",
                        help="relative to max(|a|, |b|) of each row (value) "
                        "or of the whole column (column)")
    parser.add_argument("--one-sided", action="store_true",
                        help="bound only b - a: b <= a always agrees")
    parser.add_argument("--empty", type=column_list, default=[],
                        metavar="C1,C2,...",
                        help="columns expected to be empty in both files")
    parser.add_argument("--report", action="store_true",
                        help="every column of two membranes report.csv "
                        "files, each as REPORT_COLUMNS classifies it")
    parser.add_argument("--factor", type=non_negative_float, default=10.0,
                        help="--report: the bound of a round-off column in "
                        "units of its largest |a| (default 10)")
    arguments = parser.parse_args(argv)
    if arguments.report:
        given = [option for option, default in (
            ("--columns", []), ("--empty", []), ("--atol", 0.0),
            ("--scale", "value"), ("--one-sided", False))
            if getattr(arguments, option[2:].replace("-", "_")) != default]
        if given:
            parser.error("--report compares every column: no "
                         + ", ".join(given))
    elif not arguments.columns and not arguments.empty:
        parser.error("no columns: give --columns, --empty or both, or "
                     "--report")
    return arguments


def report_line(passed, name, message):
    """Print one PASS/FAIL line and return the verdict."""
    print(f"{'PASS' if passed else 'FAIL'} {name}: {message}")
    return passed


def compare(arguments):
    """Run all comparisons; return the list of verdicts."""
    header_a, rows_a = read_report(arguments.first)
    header_b, rows_b = read_report(arguments.second)
    print(f"comparing {arguments.first} and {arguments.second}")
    verdicts = [report_line(len(rows_a) == len(rows_b), "rows",
                            f"{len(rows_a)} vs {len(rows_b)}")]
    for column in dict.fromkeys(arguments.columns + arguments.empty):
        missing = [path for path, header in ((arguments.first, header_a),
                                             (arguments.second, header_b))
                   if column not in header]
        if (len(missing) == 2 and column in arguments.empty
                and column in VERIFICATION):
            verdicts.append(report_line(True, column, "in neither file "
                                        "(not computed), as expected"))
            continue
        if missing:
            verdicts.append(report_line(False, column, "unknown column in "
                                        + " and ".join(missing)))
            continue
        first = (arguments.first, rows_a)
        second = (arguments.second, rows_b)
        try:
            if column in arguments.empty:
                passed, message = check_empty_column(column, first, second)
            else:
                passed, message = compare_column(
                    column, first, second, arguments.rtol, arguments.atol,
                    arguments.scale == "column", arguments.one_sided)
        except ReportError as error:
            passed, message = False, str(error)
        verdicts.append(report_line(passed, column, message))
    return verdicts


def main(argv=None):
    """Entry point; returns the exit status."""
    arguments = parse_arguments(argv)
    try:
        verdicts = (compare_whole_reports(arguments) if arguments.report
                    else compare(arguments))
    except ReportError as error:
        print(f"{PROG}: error: {error}", file=sys.stderr)
        return 1
    return 0 if all(verdicts) else 1


if __name__ == "__main__":
    sys.exit(main())
