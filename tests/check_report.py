#!/usr/bin/env python3
"""Check the numbers in a membranes report.csv against bounds (used by ctest).

Usage::

    check_report.py report.csv [checks...]

The whole table is printed first, so that a test log shows the numbers, then
one line ``PASS ...`` or ``FAIL ...`` per check with the measured value(s) and
the bound.  Every check may be given several times; checks run in the order
given on the command line.

Checks (COL is a column name from the header, VALUE a number):

``--rate COL>=VALUE``
    Observed convergence rate in h of COL over the last two rows,
    ``log(e_{k-1} / e_k) / log(sqrt(N_k / N_{k-1}))`` with N the ``dofs``
    column (two dimensions, so h ~ N^{-1/2}).
``--max-rate COL<=VALUE``
    The same rate in h is at most VALUE (a singular solution that uniform
    refinement cannot approximate faster).
``--dof-rate COL>=VALUE``
    Observed rate in DoFs of COL, ``e ~ N^{-rate}``: the least-squares slope
    of log(COL) against log(N) over the last half of the rows (at least
    three), as adaptive meshes grow by irregular factors.
``--band COL<=VALUE``
    max/min of the non-empty values of COL (all positive) is <= VALUE.
``--max COL<=VALUE``
    Every non-empty value of COL is <= VALUE.
``--min COL>=VALUE``
    Every non-empty value of COL is >= VALUE.
``--max-after-first COL<=VALUE``
    As ``--max``, ignoring the first row.
``--max-last COL<=VALUE``
    As ``--max``, on the last row only (the finest mesh).
``--min-last COL>=VALUE``
    As ``--min``, on the last row only.
``--empty COL``
    Every value of COL is empty.
``--filled COL``
    Every value of COL is non-empty.
``--growth COL>=VALUE``
    Every value of COL after the first is at least VALUE times the one
    before (e.g. the growth of ``cells`` per cycle).
``--rows N``
    The file has exactly N data rows.
``--decreasing COL``
    The non-empty values of COL strictly decrease from row to row.
``--hanging-nodes N``
    Each of the last N meshes has hanging nodes: fewer ``cells`` than the
    first mesh refined uniformly to its number of ``levels``,
    cells < cells_0 4^(levels - levels_0) (a refined quadrilateral or
    triangle has four children), so that it has active cells of different
    levels, and where two of them meet, a hanging vertex.

Checks that look at non-empty values (``--max``, ``--min``,
``--max-after-first``, ``--max-last``, ``--min-last``, ``--decreasing``)
fail when there is nothing to look at, so that a quantity that was silently not computed does not pass.  NaN
never satisfies a bound.

Exit status: 0 if every check passes; 1 if a check fails, a column is
unknown, or the file is missing or malformed; 2 on a command-line error.
"""

import argparse
import csv
import math
import sys

PROG = "check_report.py"
DOFS = "dofs"


class ReportError(Exception):
    """The report file is missing or malformed."""


class Report:
    """A report.csv: the header and the rows as raw (stripped) strings."""

    def __init__(self, path):
        self.path = path
        self.header, self.rows = read_csv(path)

    def has(self, column):
        """Whether the header contains ``column``."""
        return column in self.header

    def raw(self, column):
        """The raw strings of ``column``, one per row ('' when empty)."""
        index = self.header.index(column)
        return [row[index] for row in self.rows]

    def values(self, column):
        """The values of ``column`` as floats, None where empty."""
        return [parse_number(text, self.path, column)
                for text in self.raw(column)]


def read_csv(path):
    """Return (header, rows) of a CSV file, raising ReportError on problems."""
    try:
        with open(path, newline="", encoding="utf-8") as stream:
            lines = [row for row in csv.reader(stream) if any(row)]
    except OSError as error:
        raise ReportError(f"cannot read {path}: {error.strerror}") from error
    except (csv.Error, UnicodeDecodeError) as error:
        raise ReportError(f"{path}: not a valid CSV file: {error}") from error
    if not lines:
        raise ReportError(f"{path}: file is empty (no header)")
    header = [name.strip() for name in lines[0]]
    rows = []
    for number, row in enumerate(lines[1:], start=2):
        if len(row) != len(header):
            raise ReportError(f"{path}: line {number} has {len(row)} fields, "
                              f"the header has {len(header)}")
        rows.append([field.strip() for field in row])
    return header, rows


def parse_number(text, path, column):
    """Convert a field to float (None when empty)."""
    if text == "":
        return None
    try:
        return float(text)
    except ValueError:
        raise ReportError(f"{path}: column {column} holds a non-numeric "
                          f"value {text!r}") from None


def print_table(report):
    """Print the report as an aligned table, '-' marking empty fields."""
    columns = [report.header] + [[field or "-" for field in row]
                                 for row in report.rows]
    widths = [max(len(row[i]) for row in columns)
              for i in range(len(report.header))]
    print(f"{report.path}: {len(report.rows)} rows")
    for row in columns:
        print("  ".join(field.rjust(width)
                        for field, width in zip(row, widths)).rstrip())
    print()


def fmt(value):
    """Format a number compactly for a PASS/FAIL line."""
    return "empty" if value is None else f"{value:.6g}"


def split_bound(spec, operator):
    """Split 'COL<=VALUE' (or '>=') into (column, value) for argparse."""
    column, found, value = spec.partition(operator)
    if not found or not column.strip():
        raise argparse.ArgumentTypeError(
            f"expected COLUMN{operator}VALUE, got {spec!r}")
    try:
        return column.strip(), float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"bound in {spec!r} is not a number") from None


def non_negative_int(text):
    """argparse type for --rows."""
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a row count, got {text!r}")
    return value


# Each check takes (report, argument) and returns (passed, message).

def rate_in_h(report, column):
    """(rate or None, message): observed rate in h of a column over the
    last two rows."""
    if len(report.rows) < 2:
        return None, f"needs at least 2 rows, the file has {len(report.rows)}"
    dofs = report.values(DOFS)[-2:]
    errors = report.values(column)[-2:]
    detail = (f"(dofs {fmt(dofs[0])} -> {fmt(dofs[1])}, "
              f"{column} {fmt(errors[0])} -> {fmt(errors[1])})")
    if None in dofs or None in errors:
        return None, f"rate undefined: empty value {detail}"
    if not (0 < dofs[0] < dofs[1]):
        return None, f"rate undefined: dofs must increase {detail}"
    if not (errors[0] > 0 and errors[1] > 0):
        return None, f"rate undefined: errors must be positive {detail}"
    rate = math.log(errors[0] / errors[1]) / math.log(
        math.sqrt(dofs[1] / dofs[0]))
    return rate, f"rate {rate:.4g} {detail}"


def check_rate(report, arg):
    """Observed rate in h of a column over the last two rows >= bound."""
    column, bound = arg
    rate, message = rate_in_h(report, column)
    if rate is None:
        return False, message
    return rate >= bound, f"{message}, bound >= {fmt(bound)}"


def check_max_rate(report, arg):
    """Observed rate in h of a column over the last two rows <= bound."""
    column, bound = arg
    rate, message = rate_in_h(report, column)
    if rate is None:
        return False, message
    return rate <= bound, f"{message}, bound <= {fmt(bound)}"


def check_growth(report, arg):
    """Each value after the first >= bound times the one before."""
    column, bound = arg
    values = report.values(column)
    if len(values) < 2 or None in values or min(values) <= 0:
        return False, f"needs at least 2 positive values, got {values}"
    ratios = [later / earlier for earlier, later in zip(values, values[1:])]
    bad = [f"row {row + 1}: {ratio:.4g}" for row, ratio in enumerate(ratios)
           if not ratio >= bound]
    message = (f"least growth {min(ratios):.4g} over {len(ratios)} steps, "
               f"bound >= {fmt(bound)}")
    if bad:
        message += f"; violated at {', '.join(bad)}"
    return not bad, message


def check_dof_rate(report, arg):
    """Least-squares rate in DoFs of a column over the last half of the rows."""
    column, bound = arg
    count = max(3, (len(report.rows) + 1) // 2)
    if len(report.rows) < count:
        return False, f"needs at least {count} rows, the file has " \
                      f"{len(report.rows)}"
    pairs = list(zip(report.values(DOFS), report.values(column)))[-count:]
    if any(n is None or e is None or n <= 0 or e <= 0 for n, e in pairs):
        return False, f"rate undefined: empty or non-positive values {pairs}"
    xs = [math.log(n) for n, _ in pairs]
    ys = [math.log(e) for _, e in pairs]
    mean_x, mean_y = sum(xs) / count, sum(ys) / count
    spread = sum((x - mean_x) ** 2 for x in xs)
    if spread == 0:
        return False, "rate undefined: dofs do not change"
    rate = -sum((x - mean_x) * (y - mean_y) for x, y in zip(xs, ys)) / spread
    return rate >= bound, (f"rate in DoFs {rate:.4g} over the last {count} "
                           f"rows (dofs {fmt(pairs[0][0])} -> "
                           f"{fmt(pairs[-1][0])}), bound >= {fmt(bound)}")


def check_band(report, arg):
    """max/min of the non-empty (positive) values of a column."""
    column, bound = arg
    values = [v for v in report.values(column) if v is not None]
    if not values or min(values) <= 0:
        return False, f"needs positive values, got {values}"
    ratio = max(values) / min(values)
    return ratio <= bound, (f"max/min {ratio:.4g} (max {fmt(max(values))}, "
                            f"min {fmt(min(values))}), bound <= {fmt(bound)}")


def bound_check(values, bound, satisfied, relation):
    """Compare every non-empty value with a bound; list the violations."""
    present = [(row, value) for row, value in enumerate(values)
               if value is not None]
    if not present:
        return False, "no non-empty values"
    bad = [(row, value) for row, value in present
           if not satisfied(value, bound)]
    numbers = [value for _, value in present]
    extreme = max(numbers) if relation == "<=" else min(numbers)
    if any(math.isnan(value) for value in numbers):
        extreme = math.nan
    label = "max" if relation == "<=" else "min"
    message = (f"{label} {fmt(extreme)} over {len(present)} values, "
               f"bound {relation} {fmt(bound)}")
    if bad:
        rows = ", ".join(f"row {row}: {fmt(value)}" for row, value in bad)
        message += f"; violated at {rows}"
    return not bad, message


def check_max(report, arg):
    """Every non-empty value <= bound."""
    column, bound = arg
    return bound_check(report.values(column), bound,
                       lambda value, limit: value <= limit, "<=")


def check_min(report, arg):
    """Every non-empty value >= bound."""
    column, bound = arg
    return bound_check(report.values(column), bound,
                       lambda value, limit: value >= limit, ">=")


def check_max_after_first(report, arg):
    """Every non-empty value except the first row's <= bound."""
    column, bound = arg
    values = report.values(column)
    if not values:
        return False, "no rows"
    # Keep the row numbering of the file: blank out row 0 instead of slicing.
    return bound_check([None] + values[1:], bound,
                       lambda value, limit: value <= limit, "<=")


def last_row_check(report, arg, relation):
    """Compare the last row's value of a column with a bound."""
    column, bound = arg
    values = report.values(column)
    if not values:
        return False, "no rows"
    satisfied = ((lambda value, limit: value <= limit) if relation == "<="
                 else (lambda value, limit: value >= limit))
    return bound_check([None] * (len(values) - 1) + values[-1:], bound,
                       satisfied, relation)


def check_max_last(report, arg):
    """The last row's value <= bound."""
    return last_row_check(report, arg, "<=")


def check_min_last(report, arg):
    """The last row's value >= bound."""
    return last_row_check(report, arg, ">=")


def check_empty(report, column):
    """Every value empty."""
    filled = [row for row, text in enumerate(report.raw(column)) if text]
    if filled:
        return False, (f"{len(filled)} of {len(report.rows)} values "
                       f"filled (rows {', '.join(map(str, filled))})")
    return True, f"all {len(report.rows)} values empty"


def check_absent(report, column):
    """The column is not in the report (not computed by the run)."""
    if report.has(column):
        return False, "in the report, expected absent"
    return True, "absent"


def check_filled(report, column):
    """Every value non-empty."""
    if not report.rows:
        return False, "no rows"
    empty = [row for row, text in enumerate(report.raw(column)) if not text]
    if empty:
        return False, (f"{len(empty)} of {len(report.rows)} values "
                       f"empty (rows {', '.join(map(str, empty))})")
    return True, f"all {len(report.rows)} values filled"


def check_rows(report, expected):
    """Exact number of data rows."""
    count = len(report.rows)
    return count == expected, f"{count} rows, expected {expected}"


def check_decreasing(report, column):
    """Non-empty values strictly decreasing."""
    present = [value for value in report.values(column) if value is not None]
    shown = ", ".join(fmt(value) for value in present)
    if len(present) < 2:
        return False, f"needs at least 2 non-empty values, got [{shown}]"
    ok = all(later < earlier for earlier, later in zip(present, present[1:]))
    return ok, f"values [{shown}]"


def check_hanging_nodes(report, count):
    """The last N meshes have cells of different levels."""
    cells, levels = report.values("cells"), report.values("levels")
    if count < 1 or len(cells) < count or None in cells + levels:
        return False, f"needs {max(count, 1)} rows with cells and levels"
    uniform = [cells[0] * 4 ** (level - levels[0]) for level in levels]
    last = range(len(cells) - count, len(cells))
    shown = ", ".join(f"{fmt(cells[row])} < {fmt(uniform[row])}"
                      for row in last)
    ok = all(cells[row] < uniform[row] for row in last)
    return ok, f"cells against uniform refinement: {shown}"


# option -> (check function, argparse type, how to print the argument)
CHECKS = {
    "--rate": (check_rate, lambda s: split_bound(s, ">="),
               lambda a: f"{a[0]}>={fmt(a[1])}"),
    "--max-rate": (check_max_rate, lambda s: split_bound(s, "<="),
                   lambda a: f"{a[0]}<={fmt(a[1])}"),
    "--growth": (check_growth, lambda s: split_bound(s, ">="),
                 lambda a: f"{a[0]}>={fmt(a[1])}"),
    "--dof-rate": (check_dof_rate, lambda s: split_bound(s, ">="),
                   lambda a: f"{a[0]}>={fmt(a[1])}"),
    "--band": (check_band, lambda s: split_bound(s, "<="),
               lambda a: f"{a[0]}<={fmt(a[1])}"),
    "--max": (check_max, lambda s: split_bound(s, "<="),
              lambda a: f"{a[0]}<={fmt(a[1])}"),
    "--min": (check_min, lambda s: split_bound(s, ">="),
              lambda a: f"{a[0]}>={fmt(a[1])}"),
    "--max-after-first": (check_max_after_first,
                          lambda s: split_bound(s, "<="),
                          lambda a: f"{a[0]}<={fmt(a[1])}"),
    "--max-last": (check_max_last, lambda s: split_bound(s, "<="),
                   lambda a: f"{a[0]}<={fmt(a[1])}"),
    "--min-last": (check_min_last, lambda s: split_bound(s, ">="),
                   lambda a: f"{a[0]}>={fmt(a[1])}"),
    "--empty": (check_empty, str, str),
    "--absent": (check_absent, str, str),
    "--filled": (check_filled, str, str),
    "--rows": (check_rows, non_negative_int, str),
    "--decreasing": (check_decreasing, str, str),
    "--hanging-nodes": (check_hanging_nodes, non_negative_int, str),
}

METAVARS = {"--rate": "COL>=VALUE", "--max-rate": "COL<=VALUE",
            "--growth": "COL>=VALUE", "--dof-rate": "COL>=VALUE",
            "--band": "COL<=VALUE", "--max": "COL<=VALUE",
            "--min": "COL>=VALUE", "--max-after-first": "COL<=VALUE",
            "--max-last": "COL<=VALUE", "--min-last": "COL>=VALUE",
            "--empty": "COL", "--absent": "COL", "--filled": "COL", "--rows": "N",
            "--decreasing": "COL", "--hanging-nodes": "N"}


class AppendCheck(argparse.Action):
    """Collect (option, argument) pairs in command-line order."""

    def __call__(self, parser, namespace, values, option_string=None):
        checks = getattr(namespace, self.dest) or []
        checks.append((option_string, values))
        setattr(namespace, self.dest, checks)


def parse_arguments(argv):
    """Parse the command line."""
    parser = argparse.ArgumentParser(
        prog=PROG, description=__doc__.split("\n\n")[0],
        epilog="Every check may be given several times.")
    parser.add_argument("report", help="report.csv written by membranes")
    for option, (function, convert, _) in CHECKS.items():
        parser.add_argument(option, dest="checks", action=AppendCheck,
                            type=convert, metavar=METAVARS[option],
                            default=[], help=function.__doc__)
    return parser.parse_args(argv)


def columns_of(option, argument):
    """The columns a check refers to."""
    if option in ("--rate", "--max-rate", "--dof-rate"):
        return [argument[0], DOFS]
    if option in ("--max", "--min", "--max-after-first", "--max-last",
                  "--min-last", "--band", "--growth"):
        return [argument[0]]
    if option in ("--rows", "--absent"):
        return []
    if option == "--hanging-nodes":
        return ["cells", "levels"]
    return [argument]


def run_check(report, option, argument):
    """Run one check, print its PASS/FAIL line and return whether it passed."""
    function, _, describe = CHECKS[option]
    name = f"{option} {describe(argument)}"
    missing = [column for column in columns_of(option, argument)
               if not report.has(column)]
    if missing:
        passed, message = False, f"unknown column {missing[0]!r}"
    else:
        try:
            passed, message = function(report, argument)
        except ReportError as error:
            passed, message = False, str(error)
    print(f"{'PASS' if passed else 'FAIL'} {name}: {message}")
    return passed


def main(argv=None):
    """Entry point; returns the exit status."""
    arguments = parse_arguments(argv)
    try:
        report = Report(arguments.report)
        print_table(report)
        results = [run_check(report, option, argument)
                   for option, argument in arguments.checks]
    except ReportError as error:
        print(f"{PROG}: error: {error}", file=sys.stderr)
        return 1
    failed = results.count(False)
    print(f"\n{len(results) - failed} of {len(results)} checks passed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
