#!/usr/bin/env python3
"""Checks that tests/check_code_size.py finds what it is there to find.

Usage::

    check_code_size_planted.py

Writes a tiny source tree into a temporary directory, with three planted
violations at the limits and their clean twins one line short of them:

* source/planted.cc: a free function of 100 lines (clean, with braces in a
  string, a character literal and a comment that a naive brace count would
  take for code) and a member function, inline in a class, of 101 lines;
* source/planted.py: a function of 100 lines (clean) and a method of 101;
* doc/long.md of 801 lines and doc/short.md of 800 (clean);
* include/planted.h, so that the library is the two files under source/ and
  include/ of C++.

Runs the checker on it and compares: exit status 1, exactly the three
violations (path, line and length), and the size of the library. Prints
PASS or FAIL lines; exit status 1 if one fails.
"""

import os
import subprocess
import sys
import tempfile

CHECKER = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                       "check_code_size.py")


def cxx_function(head, n_lines, indent):
    """A C++ function of @p n_lines lines: @p head (its return type and
    name, on two lines), the braces, and statements in between."""
    pad = " " * indent
    body = [pad + "  const char *brace = \"}\"; // a } in a comment",
            pad + "  x += brace[0] + '{';",
            pad + "  /* } */"]
    body += [pad + "  x += 1;"] * (n_lines - 4 - len(body) - 1)
    return ([pad + head[0], pad + head[1], pad + "{"] + body
            + [pad + "  return x;", pad + "}"])


def python_function(head, n_lines, indent):
    """A Python function of @p n_lines lines from its def to its return."""
    pad = " " * indent
    body = [pad + '    """A } in a docstring."""']
    body += [pad + "    x += 1"] * (n_lines - 3)
    return [pad + head] + body + [pad + "    return x"]


def planted_tree(top):
    """Writes the tree into @p top; returns the expected violations and
    the lines of the library."""
    cc = (["// A planted file of check_code_size_planted.py.",
           "namespace planted", "{"]
          + cxx_function(["int", "clean(int x)"], 100, 2)
          + ["", "  class Holder", "  {", "  public:"])
    long_member_line = len(cc) + 1
    cc += (cxx_function(["int", "long_member(int x)"], 101, 4)
           + ["  };", "} // namespace planted"])
    py = python_function("def clean(x):", 100, 0) + ["", "", "class Holder:"]
    long_method_line = len(py) + 1
    py += python_function("def long_method(self, x):", 101, 4)
    files = {"source/planted.cc": cc, "source/planted.py": py,
             "include/planted.h": ["int clean(int x);"],
             "doc/long.md": ["line"] * 801, "doc/short.md": ["line"] * 800}
    for name, lines in files.items():
        os.makedirs(os.path.join(top, os.path.dirname(name)), exist_ok=True)
        with open(os.path.join(top, name), "w") as f:
            f.write("\n".join(lines) + "\n")
    expected = [
        f"source/planted.cc:{long_member_line}: function long_member: "
        "101 lines",
        f"source/planted.py:{long_method_line}: function long_method: "
        "101 lines",
        "doc/long.md:1: 801 lines"]
    return expected, len(cc) + 1


def main():
    failures = 0

    def check(what, passed):
        nonlocal failures
        failures += not passed
        print(("PASS " if passed else "FAIL ") + what)

    with tempfile.TemporaryDirectory() as top:
        expected, library = planted_tree(top)
        run = subprocess.run([sys.executable, CHECKER, top],
                             capture_output=True, text=True)
    print(run.stdout + run.stderr, end="")
    reported = [line for line in run.stdout.splitlines()
                if not line.startswith("library:")]
    check("exit status 1", run.returncode == 1)
    for violation in expected:
        check(f"reported: {violation}",
              any(line.startswith(violation) for line in reported))
    check("nothing else reported (the clean twins at the limits)",
          len(reported) == len(expected))
    check(f"library: {library} lines",
          f"library: {library} lines" in run.stdout)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
