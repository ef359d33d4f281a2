#!/usr/bin/env python3
"""Run a scene and check the rates of the table printed at its end::

    check_terminal_rates.py OUTDIR dofs|h membranes [args...]

The program runs as with run_scene.py (OUTDIR removed, then passed as
``Output/Directory``), its output is echoed. The check: the line above the
table begins by saying that the rates are in DoFs (``dofs``) or in h
(``h``), and the rate printed for ``err_energy`` on every row after the first equals the one
computed from report.csv, ``log(e_{k-1}/e_k) / log(N_k/N_{k-1})`` in DoFs or
twice that in h, to the two decimals printed (tolerance 0.0051).
"""
import csv
import math
import subprocess
import sys

from run_scene import scene_command

HEADERS = {"dofs": "Observed rates (red.rate.log2) in DoFs",
           "h": "Observed rates (red.rate.log2) in h"}
COLUMN = "err_energy"
TOLERANCE = 0.0051


def printed_rates(lines):
    """The err_energy rates of the org-mode table after the header line."""
    header = [cell.strip() for cell in lines[0].strip().strip("|").split("|")]
    index = header.index(COLUMN + "...red.rate.log2")
    rates = []
    for line in lines[1:]:
        if not line.startswith("|"):
            break
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        rates.append(None if cells[index] == "-" else float(cells[index]))
    return rates


def main():
    if len(sys.argv) < 4 or sys.argv[2] not in HEADERS:
        sys.exit("usage: check_terminal_rates.py OUTDIR dofs|h membranes "
                 "[args...]")
    outdir, unit = sys.argv[1], sys.argv[2]
    command = scene_command([outdir] + sys.argv[3:])[1]
    print(" ".join(command), flush=True)
    run = subprocess.run(command, stdout=subprocess.PIPE, text=True)
    print(run.stdout)
    if run.returncode != 0:
        sys.exit(f"FAIL: the run ended with status {run.returncode}")
    lines = run.stdout.splitlines()
    found = [i for i, line in enumerate(lines)
             if line.startswith(tuple(HEADERS.values()))]
    if not found or not lines[found[-1]].startswith(HEADERS[unit]):
        sys.exit(f"FAIL: no line {HEADERS[unit]!r} above the table")
    rates = printed_rates(lines[found[-1] + 1:])

    with open(outdir + "/report.csv", newline="") as stream:
        rows = list(csv.DictReader(stream))
    factor = 1 if unit == "dofs" else 2
    if len(rates) != len(rows) or len(rows) < 3:
        sys.exit(f"FAIL: {len(rates)} table rows, {len(rows)} report rows")
    failed = False
    for row, (previous, current) in enumerate(zip(rows, rows[1:]), start=1):
        expected = factor * math.log(
            float(previous[COLUMN]) / float(current[COLUMN])) / math.log(
                float(current["dofs"]) / float(previous["dofs"]))
        ok = rates[row] is not None and abs(rates[row] - expected) <= TOLERANCE
        failed |= not ok
        print(f"{'PASS' if ok else 'FAIL'} row {row}: printed {rates[row]}, "
              f"from report.csv {expected:.4f} (in {unit})")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
