#!/usr/bin/env python3
"""Compare selected columns of two membranes report.csv files row by row.

Usage::

    compare_reports.py a.csv b.csv --columns c1,c2,... --rtol R [--atol A]

The files must have the same number of data rows, and for every named column
and every row the two values must satisfy

    |a - b| <= atol + rtol * max(|a|, |b|)        (atol defaults to 0),

so with ``--rtol 0`` (and no ``--atol``) the values must be equal, which is
the right test for integer columns such as ``dofs`` or ``active_vertices``.
Two empty fields agree; an empty field never agrees with a number; NaN never
agrees with anything.  Columns are looked up by name in each file's header.

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


def values_agree(a, b, rtol, atol):
    """Whether two parsed fields agree within the tolerance."""
    if a is None or b is None:
        return a is None and b is None
    if a == b:  # also covers equal infinities
        return True
    return abs(a - b) <= atol + rtol * max(abs(a), abs(b))


def differences(a, b):
    """(|a - b|, |a - b| / max(|a|, |b|)) for reporting; None if undefined."""
    if a is None or b is None or math.isnan(a) or math.isnan(b):
        return None
    if a == b:
        return 0.0, 0.0
    absolute = abs(a - b)
    return absolute, absolute / max(abs(a), abs(b))


def compare_column(column, first, second, rtol, atol):
    """Compare one column; return (passed, message)."""
    (path_a, rows_a), (path_b, rows_b) = first, second
    pairs = list(zip(rows_a, rows_b))
    mismatches = []
    largest = [0.0, 0.0]
    for row, (record_a, record_b) in enumerate(pairs):
        text_a, text_b = record_a[column], record_b[column]
        a = parse_number(text_a, path_a, column)
        b = parse_number(text_b, path_b, column)
        diff = differences(a, b)
        if diff is not None:
            largest = [max(old, new) for old, new in zip(largest, diff)]
        if not values_agree(a, b, rtol, atol):
            mismatches.append(f"row {row}: {text_a or 'empty'} vs "
                              f"{text_b or 'empty'}")
    message = (f"max |a-b| {fmt(largest[0])}, max relative "
               f"{fmt(largest[1])} over {len(pairs)} rows "
               f"(atol {fmt(atol)}, rtol {fmt(rtol)})")
    if mismatches:
        message += "; differ at " + ", ".join(mismatches)
    return not mismatches, message


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
    parser.add_argument("--columns", type=column_list, required=True,
                        metavar="C1,C2,...", help="columns to compare")
    parser.add_argument("--rtol", type=non_negative_float, required=True,
                        help="relative tolerance")
    parser.add_argument("--atol", type=non_negative_float, default=0.0,
                        help="absolute tolerance (default 0)")
    return parser.parse_args(argv)


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
    for column in arguments.columns:
        missing = [path for path, header in ((arguments.first, header_a),
                                             (arguments.second, header_b))
                   if column not in header]
        if missing:
            verdicts.append(report_line(False, column, "unknown column in "
                                        + " and ".join(missing)))
            continue
        try:
            passed, message = compare_column(
                column, (arguments.first, rows_a),
                (arguments.second, rows_b), arguments.rtol, arguments.atol)
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
