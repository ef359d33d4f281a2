#!/usr/bin/env python3
"""Cost per cycle of the active set method against one linear solve.

Usage::

    solver_cost_table.py contact/report.csv nocontact/report.csv [peak_rss_kib]

``contact/report.csv`` is a run of a contact scene, ``nocontact/report.csv`` a
run on the same meshes whose active set stays empty, so that its solve phase
is one CG-AMG solve of the coupled system (see solver_cost.sh). Prints one
row per cycle, the peak memory if given, and a PASS/FAIL line per target:

* at most 4 active-set iterations on every cycle after the first;
* all phases of the finest cycle together (wall_time_s) at most 2.5 times the
  linear solve;
* setup phase of the finest cycle at most 0.5 times the linear solve;
* postprocess phase of the finest cycle at most its solve phase;
* peak memory at most 700 bytes per DoF of the finest cycle (if given).

Exit status 1 if a target is missed, if the no-contact run is not one
active-set iteration with no active vertex on every cycle, or if the two runs
do not have the same DoFs per cycle.
"""

import csv
import sys

MAX_ACTIVE_SET_ITERATIONS = 4
MAX_CYCLE_RATIO = 2.5
MAX_SETUP_RATIO = 0.5
MAX_BYTES_PER_DOF = 700
MIN_FINEST_DOFS = 2_000_000


def read_report(path):
    """The rows of a report.csv as dicts keyed by column name."""
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def number(row, column):
    """The value of @p column in @p row, None where the field is empty."""
    value = row.get(column, "")
    return float(value) if value not in ("", None) else None


def fmt(value, spec):
    return "-" if value is None else format(value, spec)


def print_table(header, rows):
    """Markdown table, columns right aligned to their widest entry."""
    widths = [max(len(str(r[i])) for r in [header] + rows) for i in range(len(header))]

    def line(cells):
        return "| " + " | ".join(str(c).rjust(w) for c, w in zip(cells, widths)) + " |"

    print(line(header))
    print("|" + "|".join("-" * (w + 1) + ":" for w in widths) + "|")
    for row in rows:
        print(line(row))


def main(argv):
    if len(argv) not in (3, 4):
        sys.exit(__doc__)
    contact = read_report(argv[1])
    linear = {int(r["cycle"]): r for r in read_report(argv[2])}
    peak_rss_kib = float(argv[3]) if len(argv) == 4 else None
    if not contact:
        sys.exit(f"solver_cost_table.py: error: {argv[1]} has no rows")

    ok = True
    header = ["cycle", "dofs", "AS its", "CG its", "setup s", "assembly s",
              "solve s", "postproc s", "cycle s", "DoFs/s",
              "lin CG its", "lin solve s", "solve/lin", "cycle/lin"]
    rows = []
    ratios = {}
    for r in contact:
        cycle, dofs = int(r["cycle"]), int(r["dofs"])
        phases = [number(r, c) for c in ("time_setup_s", "time_assembly_s",
                                         "time_solve_s", "time_postprocess_s")]
        total = number(r, "wall_time_s")
        lin = linear.get(cycle)
        lin_solve = number(lin, "time_solve_s") if lin else None
        if lin is None or int(lin["dofs"]) != dofs:
            print(f"CHECK cycle {cycle}: the no-contact run has no row with {dofs} DoFs")
            ok = False
        elif lin["active_set_iterations"] != "1" or lin["active_vertices"] != "0":
            print(f"CHECK cycle {cycle}: the no-contact run has "
                  f"{lin['active_set_iterations']} active-set iterations and "
                  f"{lin['active_vertices']} active vertices, not 1 and 0")
            ok = False
        ratio = phases[2] / lin_solve if phases[2] is not None and lin_solve else None
        ratios[cycle] = total / lin_solve if total is not None and lin_solve else None
        rows.append([cycle, dofs, r["active_set_iterations"], r["linear_iterations"]]
                    + [fmt(p, ".4f") for p in phases]
                    + [fmt(total, ".4f"), fmt(dofs / total if total else None, ".3g"),
                       lin["linear_iterations"] if lin else "-",
                       fmt(lin_solve, ".4f"), fmt(ratio, ".2f"),
                       fmt(ratios[cycle], ".2f")])
    print_table(header, rows)
    print()

    finest = contact[-1]
    finest_cycle, finest_dofs = int(finest["cycle"]), int(finest["dofs"])
    if peak_rss_kib is not None:
        bytes_per_dof = peak_rss_kib * 1024 / finest_dofs
        passed = bytes_per_dof <= MAX_BYTES_PER_DOF
        print(f"{'PASS' if passed else 'FAIL'} peak memory (maximum resident "
              f"set size of the contact run) <= {MAX_BYTES_PER_DOF} bytes per "
              f"DoF of the finest cycle ({finest_dofs} DoFs): "
              f"{peak_rss_kib / 1024:.1f} MiB, {bytes_per_dof:.0f} bytes per DoF")
        ok &= passed
    print(f"{'PASS' if finest_dofs >= MIN_FINEST_DOFS else 'FAIL'} "
          f"finest cycle has >= {MIN_FINEST_DOFS} DoFs: {finest_dofs}")
    ok &= finest_dofs >= MIN_FINEST_DOFS

    later = [(int(r["active_set_iterations"]), int(r["cycle"])) for r in contact[1:]]
    if later:
        worst, at = max(later)
        passed = worst <= MAX_ACTIVE_SET_ITERATIONS
        print(f"{'PASS' if passed else 'FAIL'} active-set iterations <= "
              f"{MAX_ACTIVE_SET_ITERATIONS} on every cycle after the first: "
              f"max {worst} (cycle {at})")
        ok &= passed
    else:
        print("FAIL active-set iterations: the run has a single cycle")
        ok = False

    ratio = ratios[finest_cycle]
    passed = ratio is not None and ratio <= MAX_CYCLE_RATIO
    print(f"{'PASS' if passed else 'FAIL'} all phases of the finest cycle <= "
          f"{MAX_CYCLE_RATIO:g} x one linear CG-AMG solve: ratio {fmt(ratio, '.2f')} "
          f"(cycle {finest_cycle})")
    ok &= passed

    setup = number(finest, "time_setup_s")
    lin = linear.get(finest_cycle)
    lin_solve = number(lin, "time_solve_s") if lin else None
    setup_ratio = setup / lin_solve if setup is not None and lin_solve else None
    passed = setup_ratio is not None and setup_ratio <= MAX_SETUP_RATIO
    print(f"{'PASS' if passed else 'FAIL'} setup phase of the finest cycle <= "
          f"{MAX_SETUP_RATIO:g} x one linear CG-AMG solve: ratio "
          f"{fmt(setup_ratio, '.2f')} (cycle {finest_cycle})")
    ok &= passed

    postprocess = number(finest, "time_postprocess_s")
    solve = number(finest, "time_solve_s")
    passed = postprocess is not None and solve is not None and postprocess <= solve
    print(f"{'PASS' if passed else 'FAIL'} postprocess phase of the finest cycle "
          f"<= its solve phase: {fmt(postprocess, '.2f')} s against "
          f"{fmt(solve, '.2f')} s")
    ok &= passed
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
