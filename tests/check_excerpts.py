#!/usr/bin/env python3
"""Checks that the code excerpts of a document are the program's code.

Usage::

    check_excerpts.py DOCUMENT

Every fenced ``cpp`` block of DOCUMENT must start with a comment line naming
one file of the source tree (``// source/active_set/active_set.cc``). The lines after
it must occur in that file, in order: the block is cut into pieces at the
lines ``// ...`` (code left out), each piece must stand in the file as
consecutive lines (blank lines and the indentation of each line do not
count), and each piece after the end of the one before. So an excerpt that
no longer matches the code fails, and so does one whose pieces were
reordered.

Prints one line per excerpt, ``PASS FILE:LINE`` (where its first piece
starts) or ``FAIL ...``. Exit status 1 if an excerpt fails or the document
holds none.
"""

import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OPEN = re.compile(r"^\s*```cpp\s*$")
CLOSE = re.compile(r"^\s*```\s*$")
ELISION = "// ..."


def excerpts(text):
    """(line number of the fence, lines) of each cpp block of @p text."""
    found, block, start = [], None, 0
    for number, line in enumerate(text.splitlines(), start=1):
        if block is None and OPEN.match(line):
            block, start = [], number
        elif block is not None and CLOSE.match(line):
            found.append((start, block))
            block = None
        elif block is not None:
            block.append(line)
    return found


def pieces(lines):
    """The lines of an excerpt, stripped, cut at the elisions; no blanks."""
    cut = [[]]
    for line in lines:
        stripped = line.strip()
        if stripped == ELISION:
            cut.append([])
        elif stripped:
            cut[-1].append(stripped)
    return [piece for piece in cut if piece]


def find(piece, code, start):
    """The first index >= @p start where @p piece stands in @p code."""
    for i in range(start, len(code) - len(piece) + 1):
        if code[i:i + len(piece)] == piece:
            return i
    return -1


def check(document, number, lines):
    """None if the excerpt at line @p number matches, else the defect."""
    header = lines[0].strip() if lines else ""
    if not header.startswith("// ") or " " in header[3:]:
        return "the first line does not name a file (// source/FILE.cc)"
    name = header[3:]
    try:
        with open(os.path.join(ROOT, name), encoding="utf-8") as stream:
            numbered = [(n, line.strip()) for n, line in
                        enumerate(stream.read().splitlines(), start=1)
                        if line.strip()]
    except OSError:
        return f"no file {name}"
    code = [line for _, line in numbered]
    at, first = 0, None
    for piece in pieces(lines[1:]):
        index = find(piece, code, at)
        if index < 0:
            return (f"{name}: the lines from '{piece[0]}' are not in the "
                    f"file (after line {numbered[at - 1][0] if at else 0})")
        first = first if first is not None else numbered[index][0]
        at = index + len(piece)
    if first is None:
        return "no code"
    print(f"PASS {document}:{number}: {name}:{first}")
    return None


def main(argv):
    if len(argv) != 2:
        print(__doc__.split("\n\n")[1].strip(), file=sys.stderr)
        return 2
    with open(argv[1], encoding="utf-8") as stream:
        found = excerpts(stream.read())
    failed = False
    for number, lines in found:
        defect = check(argv[1], number, lines)
        if defect:
            print(f"FAIL {argv[1]}:{number}: {defect}")
            failed = True
    if not found:
        print(f"FAIL {argv[1]}: no cpp excerpt")
    return 1 if failed or not found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
