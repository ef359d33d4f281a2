#!/usr/bin/env python3
"""Checks that the Markdown of the repository renders on GitHub.

Usage::

    check_markdown.py [FILE ...]

Without arguments, from the top of the source tree (the parent of the
directory of this script):

* every Markdown file of the repository (``git ls-files '*.md'``; without
  git, every ``*.md`` below the top outside ``build*`` directories) must
  hold no control character: none of U+0000-U+001F but the tab and the line
  feed, no U+007F and none of U+0080-U+009F. A LaTeX backslash that became a
  control character (``\\v`` of ``\\varphi`` as a vertical tab, ``\\r`` of
  ``\\rho`` as a carriage return) is such a defect;
* the documents (``doc/*.md``, ``README.md``, ``benchmarks/README.md``) must
  have balanced math: every ``$`` that opens inline math closes in the same
  paragraph, every ``$$`` that opens display math closes before the end of
  the file, and no single ``$`` stands inside display math. ``\\$`` and the
  contents of code spans and fenced code blocks do not count. Inside ``$``
  and ``$$`` math there is no backslash before an ASCII punctuation
  character: GitHub's Markdown removes it before the math is typeset
  (``\\{`` renders as ``{``, ``\\|`` as ``|``, ``\\,`` as ``,``, and
  ``\\\\`` as ``\\``, which joins the rows of ``aligned``). In inline math
  ``\\lbrace``, ``\\rbrace``, ``\\Vert`` and ``\\vert`` render; display
  math belongs in a ```` ```math ```` fence, which GitHub hands to the
  renderer as written.

With FILE arguments, both checks apply to each FILE (to try the checks on a
file of one's own).

Prints one line ``FILE:LINE: defect`` per defect and exits with status 1 if
there is one, 0 otherwise.
"""

import glob
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

CONTROL = re.compile("[\x00-\x08\x0b-\x1f\x7f\x80-\x9f]")
FENCE = re.compile(r"^ {0,3}(`{3,}|~{3,})")
# What GitHub's Markdown unescapes inside math: a backslash before any ASCII
# punctuation character (the backslash escapes of CommonMark).
ESCAPED = tuple("!\"#$%&'()*+,-./:;<=>?@[\\]^_`{|}~")


def markdown_files():
    """The Markdown files of the repository, relative to ROOT."""
    try:
        listed = subprocess.run(["git", "ls-files", "*.md"], cwd=ROOT,
                                check=True, capture_output=True, text=True)
        return [name for name in listed.stdout.splitlines() if name]
    except (OSError, subprocess.CalledProcessError):
        found = []
        for directory, subdirectories, files in os.walk(ROOT):
            subdirectories[:] = [d for d in subdirectories
                                 if not d.startswith((".", "build"))]
            found += [os.path.relpath(os.path.join(directory, f), ROOT)
                      for f in files if f.endswith(".md")]
        return sorted(found)


def documents():
    """The documents whose math must balance, relative to ROOT."""
    names = sorted(os.path.relpath(p, ROOT)
                   for p in glob.glob(os.path.join(ROOT, "doc", "*.md")))
    return names + [n for n in ("README.md", "benchmarks/README.md",
                                "benchmarks/choices.md", "benchmarks/costs.md",
                                "benchmarks/estimators.md",
                                "benchmarks/floors.md",
                                "benchmarks/parallel.md",
                                "benchmarks/solvers.md")
                    if os.path.exists(os.path.join(ROOT, n))]


def read(path):
    with open(path, encoding="utf-8", errors="replace", newline="") as f:
        return f.read()


def control_characters(name, text):
    """One defect per line that holds a control character."""
    defects = []
    for number, line in enumerate(text.split("\n"), start=1):
        match = CONTROL.search(line)
        if match:
            defects.append(f"{name}:{number}: control character "
                           f"U+{ord(match.group()):04X} at column "
                           f"{match.start() + 1}")
    return defects


def unbalanced_math(name, text):
    """The defects of the math delimiters of one document."""
    defects = []
    fence = None          # the opening fence of a code block, if inside one
    code_span = 0         # length of the backtick run that opened a span
    inline = None         # line where the open inline math started
    display = None        # line where the open display math started
    for number, line in enumerate(text.split("\n"), start=1):
        if fence is not None:
            stripped = line.strip()
            if stripped.startswith(fence[0] * len(fence)) and \
                    set(stripped) == {fence[0]}:
                fence = None
            continue
        if inline is None and display is None and code_span == 0:
            match = FENCE.match(line)
            if match:
                fence = match.group(1)
                continue
        if not line.strip():
            if inline is not None:
                defects.append(f"{name}:{inline}: '$' opens inline math "
                               "that the paragraph does not close")
                inline = None
            code_span = 0
            continue
        i = 0
        while i < len(line):
            c = line[i]
            if c == "\\" and inline is None and display is None \
                    and code_span == 0:
                i += 2
                continue
            if c == "\\" and (inline is not None or display is not None):
                escaped = line[i + 1:i + 2]
                if escaped and escaped in ESCAPED:
                    defects.append(
                        f"{name}:{number}: '\\{escaped}' in "
                        + ("inline math: GitHub drops the backslash (use "
                           "\\lbrace, \\rbrace, \\Vert, \\vert, or no "
                           "thin space)" if inline is not None else
                           "display math: GitHub drops the backslash (write "
                           "the formula in a ```math fence)"))
                i += 2
                continue
            if c == "`" and inline is None and display is None:
                run = len(line[i:]) - len(line[i:].lstrip("`"))
                if code_span == 0:
                    code_span = run
                elif run == code_span:
                    code_span = 0
                i += run
                continue
            if code_span:
                i += 1
                continue
            if c == "$":
                double = line.startswith("$$", i)
                if double and inline is None:
                    display = None if display is not None else number
                    i += 2
                    continue
                if display is not None:
                    defects.append(f"{name}:{number}: single '$' inside "
                                   f"the display math opened on line "
                                   f"{display}")
                    i += 1
                    continue
                inline = None if inline is not None else number
            i += 1
    if inline is not None:
        defects.append(f"{name}:{inline}: '$' opens inline math that the "
                       "file does not close")
    if display is not None:
        defects.append(f"{name}:{display}: '$$' opens display math that "
                       "the file does not close")
    if fence is not None:
        defects.append(f"{name}: a code fence {fence} is not closed")
    return defects


def main(arguments):
    if arguments:
        control = math = arguments
        base = os.getcwd()
    else:
        control, math, base = markdown_files(), documents(), ROOT
    defects = []
    for name in control:
        defects += control_characters(name, read(os.path.join(base, name)))
    for name in math:
        defects += unbalanced_math(name, read(os.path.join(base, name)))
    for defect in defects:
        print(defect)
    return 1 if defects else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
