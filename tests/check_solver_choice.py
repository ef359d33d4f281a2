#!/usr/bin/env python3
"""Run a scene and check the linear solver that `Linear solver = auto`
chose on every cycle::

    check_solver_choice.py LIMIT OUTDIR membranes [args...]

The program runs with ``Output/Directory=OUTDIR`` and its output is echoed.
On every cycle, whose line ``Cycle k: ... N DoFs`` gives the DoFs of the
pair (u1h, u2h), the scalar problems of the decoupled method have N/2
unknowns each; every active set iteration of the cycle must say
``UMFPACK`` (the direct solver of one process) if N/2 <= LIMIT and
``cg-amg`` otherwise, the choice that LinearSolver documents. The run, on
one process, must have cycles on both sides of LIMIT.
"""
import re
import subprocess
import sys

from checks import check, failures

limit = int(sys.argv[1])
command = sys.argv[3:] + ["--set", "Output/Directory=" + sys.argv[2]]
output = subprocess.run(command, check=True, stdout=subprocess.PIPE,
                        text=True).stdout
print(output)

unknowns = None
sides = set()
for line in output.splitlines():
    cycle = re.match(r"Cycle (\d+): \d+ cells, (\d+) DoFs", line)
    if cycle:
        unknowns = int(cycle.group(2)) // 2
        sides.add(unknowns <= limit)
        continue
    iteration = re.search(r"active set iteration (\d+):.*decoupled, (\S+) \(",
                          line)
    if iteration:
        wanted = "UMFPACK" if unknowns <= limit else "cg-amg"
        check(iteration.group(2) == wanted,
              "%d unknowns, iteration %s: %s (documented: %s)" % (
                  unknowns, iteration.group(1), iteration.group(2), wanted))
check(sides == {True, False},
      "cycles on both sides of %d unknowns" % limit)
sys.exit(1 if failures else 0)
