#!/usr/bin/env python3
"""Table of the flux estimator's effectivity: ``flux_effectivity_table.py RUN...``.

Each RUN is a directory with the report.csv of a run with the flux
estimator and a known exact solution. For each run: the DoFs of the last
cycle, the effectivity η/|||e||| of the flux estimator there, its range
over all cycles, and the parts of η on the last cycle relative to the
energy error |||e|||: flux (Σ_i η_F,i²)^½, oscillation (Σ_i η_R,i²)^½,
contact (2B)^½; the part with the largest share is named. Since
η² = Σ_i (η_F,i + η_R,i)² + 2B, η/|||e||| − 1 is what the parts exceed
the error by. Last, the boundary data part (flux_estimator_boundary, not
in η) relative to the error.
"""
import csv
import os
import sys


def read(run):
    with open(os.path.join(run, "report.csv"), newline="") as file:
        return list(csv.DictReader(file))


def number(row, column):
    return float(row[column]) if row.get(column) else float("nan")


def main(runs):
    print("| run | DoFs | effectivity (last) | effectivity (range) "
          "| flux/err | oscillation/err | contact/err | dominant "
          "| boundary/err |")
    print("|---|--:|--:|--:|--:|--:|--:|---|--:|")
    for run in runs:
        rows = read(run)
        last = rows[-1]
        eff = [number(row, "flux_effectivity") for row in rows]
        error = number(last, "err_energy")
        parts = {part: number(last, "flux_estimator_" + part) / error
                 for part in ("flux", "oscillation", "contact")}
        dominant = max(parts, key=lambda part: parts[part])
        print(f"| {os.path.basename(os.path.normpath(run))} | {last['dofs']} "
              f"| {eff[-1]:.3f} | {min(eff):.3f}..{max(eff):.3f} "
              f"| {parts['flux']:.3f} | {parts['oscillation']:.3f} "
              f"| {parts['contact']:.3f} | {dominant} "
              f"| {number(last, 'flux_estimator_boundary') / error:.3f} |")


if __name__ == "__main__":
    main(sys.argv[1:])
