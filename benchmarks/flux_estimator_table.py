#!/usr/bin/env python3
"""Table of the flux estimator runs: ``flux_estimator_table.py RUN...``.

Each RUN is a directory with the report.csv of a run with the flux
reconstruction and a known exact solution. For each run, on its last cycle:
DoFs, energy error, the effectivity of the residual and of the flux
estimator, the largest defects of (4.17), (4.18) and of the balance of
Lemma 17 over all cycles, and the share of the flux reconstruction and flux
estimator (time_flux_s) in the wall time of a cycle (median, last and
largest over the cycles with wall_time_s >= 0.05 s, below which the timers
measure fixed costs). Then one PASS/FAIL line per target:

- flux effectivity >= 1 on every cycle of every run;
- flux effectivity <= 1.2 on the last cycle (fine mesh) of every run;
- flux share <= 30 % of a cycle in every run.

Exit status 1 if a line says FAIL.
"""
import csv
import os
import statistics
import sys


def read(run):
    with open(os.path.join(run, "report.csv"), newline="") as file:
        return list(csv.DictReader(file))


def number(row, column):
    return float(row[column]) if row[column] else float("nan")


def main(runs):
    print("| run | DoFs | err_energy | residual eff. | flux eff. (last) "
          "| flux eff. (range) | measure | conservation | balance "
          "| flux share (median / last / max) |")
    print("|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|")
    failures = []
    for run in runs:
        rows = read(run)
        last = rows[-1]
        flux = [number(row, "flux_effectivity") for row in rows]
        shares = [number(row, "time_flux_s") / number(row, "wall_time_s")
                  for row in rows if number(row, "wall_time_s") >= 0.05]
        defects = {column: max(number(row, column) for row in rows)
                   for column in ("measure_defect", "conservation_defect",
                                  "balance_defect")}
        name = os.path.basename(os.path.normpath(run))
        share = max(shares) if shares else float("nan")
        median = statistics.median(shares) if shares else float("nan")
        last_share = shares[-1] if shares else float("nan")
        print(f"| {name} | {last['dofs']} "
              f"| {number(last, 'err_energy'):.3e} "
              f"| {number(last, 'effectivity'):.2f} | {flux[-1]:.3f} "
              f"| {min(flux):.3f}..{max(flux):.3f} "
              f"| {defects['measure_defect']:.1e} "
              f"| {defects['conservation_defect']:.1e} "
              f"| {defects['balance_defect']:.1e} "
              f"| {100 * median:.1f} / {100 * last_share:.1f} "
              f"/ {100 * share:.1f} % |")
        if not min(flux) >= 1:
            failures.append(f"{name}: flux effectivity {min(flux):.3f} < 1")
        if not flux[-1] <= 1.2:
            failures.append(f"{name}: flux effectivity {flux[-1]:.3f} > 1.2 "
                            "on the last cycle")
        if not share <= 0.3:
            failures.append(f"{name}: flux share {100 * share:.1f} % > 30 %")
    print()
    for target in ("flux effectivity >= 1 on every cycle",
                   "flux effectivity <= 1.2 on the last cycle",
                   "flux share <= 30 % of a cycle"):
        print(f"target: {target}")
    for failure in failures:
        print(f"FAIL {failure}")
    if not failures:
        print("PASS all targets")
    return 1 if failures else 0


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: flux_estimator_table.py RUN...")
    sys.exit(main(sys.argv[1:]))
