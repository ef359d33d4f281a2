#!/usr/bin/env python3
"""Compare selected columns of two CSV files row by row: membranes
report.csv files, or the nodal-values-NN.csv files of two runs.

Usage::

    compare_reports.py a.csv b.csv [--columns c1,c2,...] [--empty c1,c2,...]
                       --rtol R [--atol A] [--scale value|column]
                       [--one-sided]

(``--columns``, ``--empty`` or both.)

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
expected to be empty in every row of both files, and fail otherwise.  With ``--one-sided`` only b - a is bounded so
(b <= a always agrees): b costs or errs at most that much more than a, e.g.
``--rtol 0 --one-sided`` on an iteration count says b <= a.  Columns are
looked up by name in each file's header.

One line ``PASS ...`` or ``FAIL ...`` is printed for the row count and for
each column, giving the largest difference found and the tolerance.  Exit
status: 0 if everything agrees, 1 otherwise (including a missing or
malformed file or an unknown column), 2 on a command-line error.
"""

import argparse
import math
import sys

from check_report import ReportError, parse_number, read_csv

PROG = "compare_reports.py"


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
    arguments = parser.parse_args(argv)
    if not arguments.columns and not arguments.empty:
        parser.error("no columns: give --columns, --empty or both")
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
        verdicts = compare(arguments)
    except ReportError as error:
        print(f"{PROG}: error: {error}", file=sys.stderr)
        return 1
    return 0 if all(verdicts) else 1


if __name__ == "__main__":
    sys.exit(main())
