#!/usr/bin/env python3
"""The tables of several runs of one benchmark program, as medians::

    median_tables.py run1.md run2.md ...

Prints the first file with every number in a table row (a line starting
with "| ") replaced by the median of that cell over the files, with as
many decimals as the first file prints; text cells and other lines stay
as they are. The runs must print the same lines in the same order.
"""
import statistics
import sys

runs = [open(name).read().splitlines() for name in sys.argv[1:]]
for k, line in enumerate(runs[0]):
    if not line.startswith("| "):
        print(line)
        continue
    cells = [run[k].strip("|").split(" | ") for run in runs]
    row = []
    for c, text in enumerate(cells[0]):
        try:
            value = statistics.median(float(cell[c]) for cell in cells)
            decimals = len(text.strip().split(".")[1]) if "." in text else 0
            row.append(f"{value:.{decimals}f}")
        except ValueError:
            row.append(text.strip())
    print("| " + " | ".join(row) + " |")
