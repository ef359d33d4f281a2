#!/usr/bin/env python3
"""The table of benchmarks/mpi_scaling.sh::

    mpi_scaling_table.py np1/report.csv np2/report.csv

For the last cycle of both runs: the wall time of each phase on one and on
two processes, the speed-up t1/t2 and the efficiency t1/(2 t2); the peak
memory per DoF (memory_mb, summed over the processes, divided by the
DoFs); and whether the runs agree (same DoFs and active vertices, energy
errors equal to 1e-8 relative). Exit status 1 if they do not agree.
"""
import csv
import sys

PHASES = [("setup (DoFs, constraints, transfer)", "time_setup_s"),
          ("assembly", "time_assembly_s"),
          ("solve (linear solves, active set updates)", "time_solve_s"),
          ("postprocess (lambda_h, identities, errors)", "time_postprocess_s"),
          ("estimate", "time_estimate_s"),
          ("cycle", "wall_time_s")]


def last_row(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))[-1]


def main():
    one, two = (last_row(path) for path in sys.argv[1:3])
    dofs = int(one["dofs"])
    print(f"Case M, Q1, last cycle: {dofs} DoFs, {one['cells']} cells, "
          f"{one['active_vertices']} active vertices, "
          f"{one['active_set_iterations']} active set iterations "
          f"({two['active_set_iterations']} on two processes)\n")
    print("| phase | 1 process (s) | 2 processes (s) | speed-up | efficiency |")
    print("|---|--:|--:|--:|--:|")
    for name, column in PHASES:
        t1, t2 = float(one[column]), float(two[column])
        speedup = t1 / t2 if t2 > 0 else float("nan")
        print(f"| {name} | {t1:.2f} | {t2:.2f} | {speedup:.2f} | "
              f"{speedup / 2:.0%} |")
    for label, row in (("1 process", one), ("2 processes", two)):
        memory = float(row["memory_mb"])
        print(f"\nPeak memory, {label}: {memory:.0f} MB, "
              f"{memory * 2**20 / dofs:.0f} bytes per DoF")

    agree = (one["dofs"] == two["dofs"] and
             one["active_vertices"] == two["active_vertices"] and
             abs(float(one["err_energy"]) - float(two["err_energy"])) <=
             1e-8 * float(one["err_energy"]))
    print(f"\nSame DoFs, active vertices and energy error (1e-8): "
          f"{'yes' if agree else 'NO'} (err_energy {one['err_energy']} vs "
          f"{two['err_energy']})")
    sys.exit(0 if agree else 1)


if __name__ == "__main__":
    main()
