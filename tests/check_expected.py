#!/usr/bin/env python3
"""Compare a membranes report.csv with the expected output stored under
tests/expected/ (used by ctest, in the manner of deal.II's ``.output``
files and numdiff).

Usage::

    check_expected.py report.csv expected.output

The expected file is the report of a reviewed run, rounded to seven
significant digits: a whitespace-separated table with a header line, one
line per cycle, ``-`` for an empty field, and ``#`` comment lines. It holds
the columns that the method determines (below); the times, the memory and
the linear iterations are left out, and so are the KKT residual and the
defects of Prop. 12 and (4.8), which the active set method bounds by
Solver/Tolerance before a run can succeed. Every row and every column of
the expected file must be matched by the report:

    |report - expected| <= atol + rtol |expected|,

with the tolerances of the column's kind:

=========================  =========  =====  ================================
kind                       rtol       atol   columns
=========================  =========  =====  ================================
counts                     0          0      cycle, cells, dofs, levels,
                                             active_vertices, processes
iterations                 0          1      active_set_iterations
values                     1e-6       0      errors, estimators and their
                                             parts, effectivities
near zero                  1e-6       atol   err_lambda_L2,
                                             err_lambda_L2_omega_h and
                                             err_lambda_Hm1 (1e-9: no
                                             contact), min_w (1e-9),
                                             min_lambda (1e-5: the noise of
                                             a residual divided by d_a),
                                             flux_estimator_contact (1e-6),
                                             eta_algebraic (1e-9: with the
                                             direct solver it is the
                                             round-off of the solve,
                                             1e-14 to 1e-11),
                                             flux_estimator_boundary and
                                             the identity defects of the
                                             flux reconstruction (1e-12:
                                             round-off on triangles)
=========================  =========  =====  ================================

rtol 1e-6 covers the seven stored digits (5e-7) and the solver tolerance
(the errors of the direct and the CG-AMG solves agree to 1e-8); the
absolute tolerances are in the units of the shipped scenes, whose data are
of size 1. An empty expected field must be empty in the report, and the
other way round: a quantity computed where it should not be, or silently
not computed, fails. A column that the run does not compute at all (an
error norm that the scene's ``Exact solution/Norms`` leaves out, or every
error and effectivity without exact solution) is absent from report.csv;
the expected file names it in a comment line ``# absent: column ...``, and
a report that has it fails, as one that lacks a stored column does.

With the environment variable MEMBRANES_UPDATE_EXPECTED=1 the expected file
is written anew from the report instead (``MEMBRANES_UPDATE_EXPECTED=1
ctest -L expected`` after a change that moves numbers on purpose); the
change then shows as a diff of tests/expected/ to review and commit.

One line ``PASS ...`` or ``FAIL ...`` per column, with the largest
difference; a failing column lists its first differing rows. Exit status 0
if everything agrees, 1 otherwise (a missing file or an unknown column
too).
"""

import math
import os
import sys

from check_report import ReportError, parse_number, read_csv

PROG = "check_expected.py"

COUNTS = ("cycle", "cells", "dofs", "levels", "active_vertices",
          "processes")
VALUES = ("err_u1_H1", "err_u2_H1", "err_u1_L2", "err_u2_L2", "err_energy",
          "estimator", "effectivity", "flux_estimator", "flux_effectivity",
          "flux_estimator_flux", "flux_estimator_oscillation",
          "eta_linearization")

# column: (rtol, atol)
TOLERANCES = {
    **{column: (0.0, 0.0) for column in COUNTS},
    "active_set_iterations": (0.0, 1.0),
    **{column: (1e-6, 0.0) for column in VALUES},
    "err_lambda_L2": (1e-6, 1e-9),
    "err_lambda_L2_omega_h": (1e-6, 1e-9),
    "err_lambda_Hm1": (1e-6, 1e-9),
    "min_w": (1e-6, 1e-9),
    "min_lambda": (1e-6, 1e-5),
    "flux_estimator_contact": (1e-6, 1e-6),
    "eta_algebraic": (1e-6, 1e-9),
    "flux_estimator_boundary": (1e-6, 1e-12),
    **{column: (1e-6, 1e-12) for column in
       ("conservation_defect", "measure_defect", "balance_defect")},
}

EMPTY = "-"


ABSENT = "# absent:"


def read_expected(path):
    """(header, rows, absent) of an expected file, rows as lists of strings
    ('' for an empty field), absent the columns the report must not
    have."""
    try:
        with open(path, encoding="utf-8") as stream:
            text = stream.read().splitlines()
    except OSError as error:
        raise ReportError(f"cannot read {path}: {error.strerror}") from error
    lines = [line.split() for line in text
             if line.strip() and not line.startswith("#")]
    absent = [column for line in text if line.startswith(ABSENT)
              for column in line[len(ABSENT):].split()]
    if not lines:
        raise ReportError(f"{path}: no header")
    header, rows = lines[0], lines[1:]
    for number, row in enumerate(rows, start=1):
        if len(row) != len(header):
            raise ReportError(f"{path}: row {number} has {len(row)} fields, "
                              f"the header has {len(header)}")
    return header, [["" if field == EMPTY else field for field in row]
                    for row in rows], absent


def rounded(text, column):
    """A report field as stored: counts as integers, values to seven
    significant digits, '-' when empty."""
    if text == "":
        return EMPTY
    value = float(text)
    if column in COUNTS or column == "active_set_iterations":
        return str(int(value))
    return f"{value:.7g}"


def write_expected(report_path, expected_path, test_name):
    """Write the stored columns of a report as an expected file."""
    header, rows = read_csv(report_path)
    columns = [column for column in header if column in TOLERANCES]
    absent = [column for column in TOLERANCES if column not in header]
    table = [columns] + [[rounded(row[header.index(column)], column)
                          for column in columns] for row in rows]
    widths = [max(len(line[i]) for line in table)
              for i in range(len(columns))]
    with open(expected_path, "w", encoding="utf-8") as stream:
        stream.write(f"# Expected report of the test {test_name} "
                     "(tests/check_expected.py)\n")
        if absent:
            stream.write(f"{ABSENT} {' '.join(absent)}\n")
        for line in table:
            stream.write("  ".join(field.rjust(width) for field, width
                                   in zip(line, widths)).rstrip() + "\n")


def compare_column(column, expected, actual, path):
    """Compare one column; return (passed, message)."""
    rtol, atol = TOLERANCES[column]
    largest = 0.0
    mismatches = []
    for row, (text_e, text_a) in enumerate(zip(expected, actual)):
        e = parse_number(text_e, path, column)
        a = parse_number(text_a, path, column)
        if e is None or a is None:
            agree = e is None and a is None
        else:
            difference = abs(a - e)
            agree = difference <= atol + rtol * abs(e)
            if not math.isnan(difference):
                largest = max(largest, difference)
        if not agree:
            mismatches.append(f"row {row}: expected {text_e or EMPTY}, "
                              f"got {text_a or EMPTY}")
    message = (f"max |difference| {largest:.3g} (rtol {rtol:g}, "
               f"atol {atol:g})")
    if mismatches:
        message += (f"; {len(mismatches)} rows differ: "
                    + ", ".join(mismatches[:4])
                    + (", ..." if len(mismatches) > 4 else ""))
    return not mismatches, message


def compare(report_path, expected_path):
    """All comparisons; return the list of verdicts."""
    header_e, rows_e, absent = read_expected(expected_path)
    header_a, rows_a = read_csv(report_path)
    print(f"comparing {report_path} with {expected_path}")
    verdicts = [len(rows_e) == len(rows_a)]
    print(f"{'PASS' if verdicts[0] else 'FAIL'} rows: {len(rows_a)}, "
          f"expected {len(rows_e)}")
    for column in absent:
        passed = column not in header_a
        print(f"{'PASS' if passed else 'FAIL'} {column}: "
              + ("absent" if passed else "in the report, expected absent"))
        verdicts.append(passed)
    for column in header_e:
        if column not in TOLERANCES or column not in header_a:
            print(f"FAIL {column}: "
                  + ("no tolerance for this column" if column
                     not in TOLERANCES else "not in the report"))
            verdicts.append(False)
            continue
        index_e, index_a = header_e.index(column), header_a.index(column)
        passed, message = compare_column(
            column, [row[index_e] for row in rows_e],
            [row[index_a] for row in rows_a], report_path)
        print(f"{'PASS' if passed else 'FAIL'} {column}: {message}")
        verdicts.append(passed)
    return verdicts


def main(argv):
    if len(argv) != 2:
        print(f"usage: {PROG} report.csv expected.output", file=sys.stderr)
        return 2
    report_path, expected_path = argv
    try:
        if os.environ.get("MEMBRANES_UPDATE_EXPECTED") == "1":
            name = os.path.splitext(os.path.basename(expected_path))[0]
            write_expected(report_path, expected_path, name)
            print(f"wrote {expected_path}")
            return 0
        verdicts = compare(report_path, expected_path)
    except ReportError as error:
        print(f"{PROG}: error: {error}", file=sys.stderr)
        return 1
    return 0 if all(verdicts) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
