#!/usr/bin/env python3
"""Checks the action error of the full-contact scene against the strip.

Usage::

    check_strip.py report.csv

The scene full-contact.prm has lambda = 2 + xy on omega = (-1, 1)^2, on
uniform Q1 meshes of square cells of side h = 2 / sqrt(cells). The dual
cell D_a of an interior vertex a is the square of side h centred at a, so
omega_h, their union, is the square (-c, c)^2 with c = 1 - h/2, and
lambda_h = 0 on the strip omega minus omega_h (4.36). There,
independently of the program,

    ||lambda||^2_{L2(strip)} = int_omega lambda^2 - int_omega_h lambda^2
                             = (16 + 4/9) - (16 c^2 + 4 c^6 / 9).

For every row of the report the check asks

* err_lambda_L2^2 - err_lambda_L2_omega_h^2 = ||lambda||^2_{L2(strip)}
  to a relative 1e-4 (the three-point rule of degree 2 of the program on
  each sub-triangle integrates the polynomial lambda^2, of degree 4, to
  2e-5 on the coarsest mesh of 16 cells and 3e-7 on the next; a strip of
  the wrong width is off by O(1));
* err_lambda_L2 >= ||lambda||_{L2(strip)}.

Catches: an error on omega_h reported as the error on omega, a strip of the
wrong width (dual cells of other vertices), lambda_h not zero on the strip.
Prints one line per row; exit status 1 if a row fails.
"""

import math
import sys

from check_report import ReportError, read_csv

RTOL = 1e-4


def strip_norm(cells):
    """||lambda||_{L2(omega minus omega_h)} on the uniform mesh of cells."""
    c = 1 - 1 / math.sqrt(cells)
    return math.sqrt((16 + 4 / 9) - (16 * c**2 + 4 * c**6 / 9))


def main(argv):
    if len(argv) != 2:
        print(__doc__.split("\n\n")[1].strip(), file=sys.stderr)
        return 2
    try:
        header, rows = read_csv(argv[1])
    except ReportError as error:
        print(f"check_strip.py: error: {error}", file=sys.stderr)
        return 1
    column = {name: header.index(name) for name in
              ("cells", "err_lambda_L2", "err_lambda_L2_omega_h")}
    failed = False
    for row in rows:
        cells = int(row[column["cells"]])
        omega = float(row[column["err_lambda_L2"]])
        omega_h = float(row[column["err_lambda_L2_omega_h"]])
        strip = strip_norm(cells)
        defect = abs(omega**2 - omega_h**2 - strip**2) / strip**2
        ok = defect <= RTOL and omega >= strip
        failed |= not ok
        print(f"{'PASS' if ok else 'FAIL'} cells {cells}: err_lambda_L2 "
              f"{omega:.9g} >= ||lambda||_strip {strip:.9g}; "
              f"|err^2 - err_omega_h^2 - strip^2| / strip^2 = {defect:.2g} "
              f"(<= {RTOL:g})")
    return 1 if failed or not rows else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
