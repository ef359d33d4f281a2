#!/usr/bin/env python3
"""Checks the size limits of the repository: no file over 800 lines, no
function over 100 lines.

Usage::

    check_code_size.py [TOP]

TOP is the top of a source tree (default: the parent of the directory of
this script). Its files are those that git tracks (``git ls-files``;
without git, every file below TOP outside hidden and ``build*``
directories).

* File length: every C++ file (``.cc``, ``.h``, ``.cc.in``, ``.h.in``),
  Python file (``.py``), shell script (``.sh``, or a file whose first line
  is ``#!``), CMake file (``CMakeLists.txt``, ``.cmake``) and Markdown file
  (``.md``) holds at most 800 lines, except the documents of
  DOCUMENT_LIMITS, which hold at most the lines given there.
* Function length, counted from the first line of its head (the template
  line or the return type above the name, decorators not included) to the
  line of its closing brace or its last statement, both included; at most
  100 lines.

  - Python: every ``def`` (nested ones too, each on its own) as the ``ast``
    module delimits it (``lineno`` to ``end_lineno``).
  - C++: comments, string and character literals (raw strings too) and
    preprocessor lines are blanked, then the braces are matched. Outside a
    function body, the text since the last ``;``, ``{``, ``}`` or access
    specifier (``public:``) is the head of the next ``{``. The brace opens
    a function body if the head ends with its parameter list (``)``,
    possibly followed by ``const``, ``override``, ``noexcept``, ``final``,
    ``mutable`` or a trailing return type ``-> T``) and does not start
    with a control keyword; a namespace or a ``class``/``struct``/``union``
    body is searched for functions in turn; any other brace (an
    initializer such as ``= {1, 2}`` or a member initializer ``c{d}`` of a
    constructor) is part of the head. A lambda inside a function is part
    of that function.

Prints one line ``PATH:LINE: what`` per violation, then one informational
line with the size of the library (the lines of the ``.cc`` and ``.h``
files under ``source/`` and ``include/``). Exit status 1 if there is a
violation, 0 otherwise.
"""

import ast
import os
import re
import subprocess
import sys

MAX_FILE_LINES = 800
MAX_FUNCTION_LINES = 100

# Documents with a limit of their own: the tutorial, which is read from
# beginning to end as deal.II's tutorials are.
DOCUMENT_LIMITS = {"doc/tutorial.md": 1150}

CXX_SUFFIXES = (".cc", ".h", ".cc.in", ".h.in")
OTHER_SUFFIXES = (".py", ".sh", ".cmake", ".md")

CONTROL_KEYWORDS = {"if", "for", "while", "switch", "catch", "do", "else",
                    "try", "return", "case", "default"}
HEX_DIGITS = set("0123456789abcdefABCDEF")
ACCESS_SPECIFIERS = {"public", "protected", "private"}
CONTAINER = re.compile(r"^(template\s*<.*>\s*)?(class|struct|union)\b", re.S)
NAMESPACE = re.compile(r"^(inline\s+)?namespace\b|^extern\s*\"C\"")
# The end of a function head: its parameter list and what may follow it.
FUNCTION_END = re.compile(
    r"\)\s*(const|volatile|override|final|noexcept(\s*\([^()]*\))?|mutable"
    r"|&&?|->\s*[\w:<>,\s*&]+?)*\s*$")


def tracked_files(top):
    """The files of the tree at @p top, relative to it."""
    try:
        listed = subprocess.run(["git", "ls-files"], cwd=top, check=True,
                                capture_output=True, text=True)
        names = [name for name in listed.stdout.splitlines() if name]
        if names:
            return names
    except (OSError, subprocess.CalledProcessError):
        pass
    found = []
    for directory, subdirectories, files in os.walk(top):
        subdirectories[:] = sorted(d for d in subdirectories
                                   if not d.startswith((".", "build")))
        found += [os.path.relpath(os.path.join(directory, f), top)
                  for f in sorted(files)]
    return found


def read(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return f.read()


def is_script(path):
    """Whether the first line of @p path is a #! line."""
    try:
        with open(path, "rb") as f:
            return f.read(2) == b"#!"
    except OSError:
        return False


def kind(name, path):
    """'c++', 'python', 'text' (length alone) or None (not checked)."""
    if name.endswith(CXX_SUFFIXES):
        return "c++"
    if name.endswith(".py"):
        return "python"
    if name.endswith(OTHER_SUFFIXES) or \
            os.path.basename(name) == "CMakeLists.txt" or is_script(path):
        return "text"
    return None


def blank_cxx(text):
    """@p text with comments, literals and preprocessor lines replaced by
    spaces, newlines kept, so that line numbers stay."""
    out = []
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if line_start and c == "#":
            # A preprocessor line, with its continuation lines.
            while i < n and text[i] != "\n":
                if text[i] == "\\" and i + 1 < n and text[i + 1] == "\n":
                    out.append(" \n")
                    i += 2
                    continue
                out.append(" ")
                i += 1
            continue
        if c == "\n":
            out.append(c)
            line_start = True
            i += 1
            continue
        if c in " \t":
            out.append(c)
            i += 1
            continue
        line_start = False
        if text.startswith("//", i):
            end = text.find("\n", i)
            end = n if end < 0 else end
        elif text.startswith("/*", i):
            end = text.find("*/", i + 2)
            end = n if end < 0 else end + 2
        elif c == "R" and text.startswith('"', i + 1) and \
                (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            open_paren = text.find("(", i + 2)
            delimiter = ")" + text[i + 2:open_paren] + '"'
            end = text.find(delimiter, open_paren)
            end = n if end < 0 else end + len(delimiter)
        elif c in "\"'":
            if c == "'" and 0 < i < n - 1 and text[i - 1] in HEX_DIGITS \
                    and text[i + 1].isalnum():
                # A digit separator (1'000), not a character literal.
                out.append(" ")
                i += 1
                continue
            end = i + 1
            while end < n and text[end] != c and text[end] != "\n":
                end += 2 if text[end] == "\\" else 1
            end = min(end + 1, n)
        else:
            out.append(c)
            i += 1
            continue
        out.append("".join(ch if ch == "\n" else " " for ch in text[i:end]))
        i = end
    return "".join(out)


def cxx_functions(text):
    """(name, first line, last line) of each function body of the C++
    @p text that stands outside another function."""
    code = blank_cxx(text)
    functions = []
    head = []           # characters of the head, with their line numbers
    line = 1
    i, n = 0, len(code)
    while i < n:
        c = code[i]
        if c == "\n":
            line += 1
        if c == ";" or c == "}" or (c == ":" and "".join(
                ch for ch, _ in head).strip() in ACCESS_SPECIFIERS):
            head = []
        elif c == "{":
            text_of_head = "".join(ch for ch, _ in head).strip()
            first_word = re.match(r"\w*", text_of_head).group()
            if FUNCTION_END.search(text_of_head) and \
                    first_word not in CONTROL_KEYWORDS:
                start = next(number for ch, number in head if not ch.isspace())
                i, line = skip_block(code, i, line)
                functions.append((function_name(text_of_head), start, line))
                head = []
            elif CONTAINER.match(text_of_head) or \
                    NAMESPACE.match(text_of_head):
                head = []
            else:
                # An initializer: part of the head of what follows.
                start, start_line = i, line
                i, line = skip_block(code, i, line)
                head += [(ch, start_line) for ch in code[start:i + 1]]
        else:
            head.append((c, line))
        i += 1
    return functions


def function_name(head):
    """The qualified name before the parameter list of a function head."""
    name = re.search(r"((?:\w+(?:<[^<>()]*>)?::)*~?\w+)\s*$",
                     head[:head.find("(")])
    return name.group(1) if name else "(lambda)"


def skip_block(code, i, line):
    """The position of the brace that closes the one at @p i, and its line
    (@p line the line of position @p i)."""
    depth = 0
    while i < len(code):
        if code[i] == "{":
            depth += 1
        elif code[i] == "}":
            depth -= 1
            if depth == 0:
                return i, line
        elif code[i] == "\n":
            line += 1
        i += 1
    return i, line


def python_functions(text, name):
    """(name, first line, last line) of each def of the Python @p text."""
    try:
        tree = ast.parse(text, filename=name)
    except SyntaxError as error:
        raise ValueError(f"{name}:{error.lineno}: not Python: {error.msg}")
    return [(node.name, node.lineno, node.end_lineno)
            for node in ast.walk(tree)
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))]


def violations(top, names):
    """The violations of the files @p names of the tree at @p top."""
    found = []
    for name in names:
        path = os.path.join(top, name)
        what = kind(name, path)
        if what is None or not os.path.isfile(path):
            continue
        text = read(path)
        n_lines = len(text.splitlines())
        limit = DOCUMENT_LIMITS.get(name, MAX_FILE_LINES)
        if n_lines > limit:
            found.append(f"{name}:1: {n_lines} lines, over the limit of "
                         f"{limit} lines of this file")
        try:
            functions = (cxx_functions(text) if what == "c++" else
                         python_functions(text, name) if what == "python"
                         else [])
        except ValueError as error:
            found.append(str(error))
            continue
        for function, first, last in functions:
            length = last - first + 1
            if length > MAX_FUNCTION_LINES:
                found.append(f"{name}:{first}: function {function}: "
                             f"{length} lines, over the limit of "
                             f"{MAX_FUNCTION_LINES} lines per function")
    return found


def library_lines(top, names):
    """The lines of the .cc and .h files under source/ and include/."""
    return sum(len(read(os.path.join(top, name)).splitlines())
               for name in names
               if name.startswith(("source/", "include/"))
               and name.endswith((".cc", ".h"))
               and os.path.isfile(os.path.join(top, name)))


def main(arguments):
    top = arguments[0] if arguments else \
        os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    names = tracked_files(top)
    found = violations(top, names)
    for violation in found:
        print(violation)
    print(f"library: {library_lines(top, names)} lines of .cc and .h under "
          "source/ and include/")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
