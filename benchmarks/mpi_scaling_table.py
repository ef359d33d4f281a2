#!/usr/bin/env python3
"""The table of benchmarks/mpi_scaling.sh::

    mpi_scaling_table.py LABEL np1/report.csv np2/report.csv [LABEL ...]

For each LABEL (a cell type) and each of the last two cycles of its runs on
one and on two processes: the wall time of each phase, the speed-up t1/t2
and the efficiency t1/(2 t2). Then the peak memory (memory_mb, summed over
the processes): per DoF on one process, per process on two, and the memory
that the second process adds, per cell: on triangles every process holds
the whole mesh, so this is what the replicated mesh costs. Last, whether
the runs agree (same DoFs and active vertices on every cycle, energy errors
equal to 1e-8 relative). Exit status 1 if they do not agree.
"""
import csv
import sys

PHASES = [("setup (DoFs, constraints, transfer)", "time_setup_s"),
          ("assembly", "time_assembly_s"),
          ("solve (linear solves, active set updates)", "time_solve_s"),
          ("postprocess (lambda_h, identities)", "time_postprocess_s"),
          ("estimate", "time_estimate_s"),
          ("cycle", "wall_time_s")]


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def agree(one, two):
    return all(a["dofs"] == b["dofs"] and
               a["active_vertices"] == b["active_vertices"] and
               abs(float(a["err_energy"]) - float(b["err_energy"])) <=
               1e-8 * float(a["err_energy"])
               for a, b in zip(one, two)) and len(one) == len(two)


def phase_table(label, one, two):
    print(f"{label}, {one['dofs']} DoFs, {one['cells']} cells, "
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
    print()


def main():
    arguments = sys.argv[1:]
    if len(arguments) == 0 or len(arguments) % 3 != 0:
        sys.exit("usage: mpi_scaling_table.py LABEL np1.csv np2.csv "
                 "[LABEL np1.csv np2.csv ...]")
    runs = [(arguments[i], rows(arguments[i + 1]), rows(arguments[i + 2]))
            for i in range(0, len(arguments), 3)]
    for label, one, two in runs:
        for k in range(max(0, len(one) - 2), len(one)):
            phase_table(label, one[k], two[k])

    print("| cells | DoFs | 1 process: MB | bytes per DoF "
          "| 2 processes: MB per process | added by the second process: "
          "bytes per cell |")
    print("|---|--:|--:|--:|--:|--:|")
    for label, one, two in runs:
        m1, m2 = float(one[-1]["memory_mb"]), float(two[-1]["memory_mb"])
        dofs, cells = int(one[-1]["dofs"]), int(one[-1]["cells"])
        print(f"| {label} | {dofs} | {m1:.0f} | {m1 * 2**20 / dofs:.0f} | "
              f"{m2 / 2:.0f} | {(m2 - m1) * 2**20 / cells:.0f} |")

    ok = True
    print()
    for label, one, two in runs:
        same = agree(one, two)
        ok = ok and same
        print(f"{label}: same DoFs, active vertices and energy error (1e-8) "
              f"on every cycle: {'yes' if same else 'NO'} (last err_energy "
              f"{one[-1]['err_energy']} vs {two[-1]['err_energy']})")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
