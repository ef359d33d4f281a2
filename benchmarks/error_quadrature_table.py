#!/usr/bin/env python3
"""Tables of the quadrature error of the error norms: ``error_quadrature_table.py RUN...``.

Each RUN is a directory with a report.csv; RUN-reference-4 (and, where it
exists, RUN-reference-5) holds the report of the same run with the error
norms integrated by the composite reference rule of 4^N triangles per
sub-triangle. For each run, per cycle: the DoFs and, for every error
column, the relative difference 100 (e − e_ref) / e_ref in % from the
reference N = 4; under it, where N = 5 was run, the largest difference of
N = 4 from N = 5 over the cycles, per column.
"""
import csv
import os
import sys

COLUMNS = ["err_u1_H1", "err_u2_H1", "err_u1_L2", "err_u2_L2",
           "err_energy", "err_lambda_L2", "err_lambda_L2_omega_h"]


def read(run):
    with open(os.path.join(run, "report.csv"), newline="") as file:
        return list(csv.DictReader(file))


def differences(rows, reference):
    """Per cycle, the relative differences in % of @p rows from @p reference."""
    result = []
    for row, ref in zip(rows, reference):
        if row["dofs"] != ref["dofs"]:
            sys.exit(f"error_quadrature_table.py: the meshes differ: "
                     f"{row['dofs']} and {ref['dofs']} DoFs")
        result.append([100 * (float(row[c]) / float(ref[c]) - 1)
                       for c in COLUMNS])
    return result


def main(runs):
    for run in runs:
        rows = read(run)
        reference = read(run + "-reference-4")
        print(f"{os.path.basename(os.path.normpath(run))}, difference from "
              "the reference N = 4 [%]:")
        print()
        print("| cycle | DoFs | " +
              " | ".join(c[len("err_"):] for c in COLUMNS) + " |")
        print("|--:|--:|" + "--:|" * len(COLUMNS))
        for row, values in zip(rows, differences(rows, reference)):
            print(f"| {row['cycle']} | {row['dofs']} | " +
                  " | ".join(f"{v:+.3f}" for v in values) + " |")
        if os.path.exists(os.path.join(run + "-reference-5", "report.csv")):
            check = differences(reference, read(run + "-reference-5"))
            print("| N = 4 against 5, largest | | " +
                  " | ".join(f"{max(abs(v[k]) for v in check):.3f}"
                             for k in range(len(COLUMNS))) + " |")
        print()


if __name__ == "__main__":
    main(sys.argv[1:])
