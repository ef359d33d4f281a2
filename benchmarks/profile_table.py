#!/usr/bin/env python3
"""Where the samples of one profiled run go, by library group and by function.

Usage::

    profile_table.py [--program NAME] scene.report.txt

``scene.report.txt`` is the text of::

    perf report --stdio --no-children -g none --sort dso,sym -n --percent-limit 0

on one ``perf record`` of the program (see profile.sh); ``-n`` (a column of
sample counts) is required, so that the shares are counted in samples, not
read back from perf's rounded percentages. ``--program NAME`` is the name
of the program's executable as perf shows it (its file name, default
``membranes``). Prints three Markdown tables, every share in % of all
samples of the run:

1. by group of libraries (the file name of the shared object, ``*`` any
   text), in this order, the groups adding up to 100 %:

   * linear algebra: Trilinos (``libtrilinos_*``), the direct solvers and
     their orderings (MUMPS ``libdmumps*``, ``libmumps*``, ScaLAPACK,
     UMFPACK and the rest of SuiteSparse, SuperLU, METIS, Scotch), BLAS,
     LAPACK (``libblas*``, ``liblapack*``, ``libopenblas*``) and the
     Fortran runtime they use; the rows "of which" split it into Epetra
     (``libtrilinos_epetra*``, EpetraExt included), ML
     (``libtrilinos_ml*``), the direct solvers (``libtrilinos_amesos*``
     with its KLU, ``libtrilinos_trilinosss*``, and the libraries above)
     and the rest (BLAS, LAPACK, Ifpack, AztecOO, Teuchos, Zoltan...);
   * deal.II (``libdeal.ii*``, ``libdeal_II*``);
   * the program's own code (the executable NAME);
   * compiled expressions (``expressions-*.so``, the scene's expressions
     compiled at run time);
   * threads (``libtbb.so*``, not ``libtbbmalloc*``; ``libgomp*``);
   * C library and allocator (``libc.so*``, ``libm.so*``, ``libmvec*``,
     ``libstdc++*``, ``libgcc_s*``, ``libpthread*``, ``libtbbmalloc*``);
   * dynamic loader (``ld-linux*``, ``ld-*.so*``);
   * kernel (every sample perf marks ``[k]``, ``[kernel.kallsyms]``);
   * other: the rest, whose largest libraries are named below the table;

2. the 15 largest functions of the program's own code by self share;
3. the 10 largest functions of the whole process by self share, with their
   library.

Function names are demangled and shortened to ``namespace::Class::function``:
template arguments, parameter lists, qualifiers, return types and clone
suffixes (``[clone .cold]``, ``.isra.0``) and ABI tags are dropped, so the
instantiations, overloads and clones of one name make one row (``×n``
after a name counts them). Samples of a library without symbols, shown as
addresses by perf, make one row ``(no symbol)`` per library (deal.II's
functions that it does not export, for one).

Exit status 1 if the report has no samples or does not parse.
"""

import re
import sys
from collections import defaultdict
from fnmatch import fnmatch

PROGRAM_ROWS = 15
OVERALL_ROWS = 10

# (group, what the libraries column says, file name patterns); the "of
# which" rows split the first group. A library belongs to the first group
# one of whose patterns its file name matches.
LINEAR_ALGEBRA_PARTS = [
    ("of which Epetra", "Epetra, EpetraExt", ["libtrilinos_epetra*"]),
    ("of which ML", "ML", ["libtrilinos_ml*"]),
    ("of which direct solver", "Amesos, MUMPS, ScaLAPACK, SuiteSparse, SuperLU, orderings",
     ["libtrilinos_amesos*", "libtrilinos_trilinosss*", "libdmumps*", "libmumps*", "libscalapack*",
      "libumfpack*", "libcholmod*", "libklu*", "libbtf*", "libspqr*",
      "libamd*", "libcamd*", "libcolamd*", "libccolamd*",
      "libsuitesparse*", "libsuperlu*", "libmetis*", "libparmetis*",
      "libscotch*", "libptscotch*", "libesmumps*"]),
    ("of which other", "BLAS, LAPACK, Ifpack, AztecOO, Teuchos, other Trilinos",
     ["libblas*", "libcblas*", "liblapack*", "libopenblas*", "libblis*",
      "libmkl*", "libgfortran*", "libquadmath*", "libtrilinos_*"]),
]
GROUPS = [
    ("deal.II", "libdeal.ii", ["libdeal.ii*", "libdeal_II*"]),
    ("membranes", "the program", []),
    ("compiled expressions", "expressions-*.so", ["expressions-*.so"]),
    ("threads", "TBB, OpenMP", ["libtbb.so*", "libtbb-*", "libtbb_*", "libgomp*"]),
    ("C library and allocator", "libc, libm, libstdc++, libgcc_s",
     ["libc.so*", "libc-*", "libm.so*", "libm-*", "libmvec*", "libstdc++*",
      "libgcc_s*", "libpthread*", "libdl.so*", "libdl-*", "librt.so*",
      "librt-*", "libtbbmalloc*"]),
    ("dynamic loader", "ld-linux", ["ld-linux*", "ld-*.so*"]),
    ("kernel", "[kernel.kallsyms]", []),
    ("other", "the rest", []),
]

LINE = re.compile(r"^\s*([\d.]+)%\s+(\d+)\s+(\S+)\s+\[(.)\]\s+(.*?)\s*$")
HEADER = re.compile(r"^# Samples: (\d+)([KMG]?)\s+of event '([^']*)'")
LOST = re.compile(r"^# Total Lost Samples: (\d+)")
ADDRESS = re.compile(r"^0x[0-9a-f]+$")
CLONE = re.compile(r" \[clone [^\]]*\]|\[abi:\w+\]|\.(?:isra|constprop|part|cold|lto_priv)(?:\.\d+)*$")
OPERATOR = re.compile(
    r"operator\s*(?:\(\)|\[\]|->\*?|<=>|<<=|>>=|<<|>>|<=|>=|==|!=|&&|\|\||"
    r"\+\+|--|new\[\]|delete\[\]|new\b|delete\b|\"\"\s*\w+|"
    r"[-+*/%^&|~!=<>,]=?|[\w:]+(?:\s*[*&]+)?)")
QUALIFIER = re.compile(r"\s+(?:const|volatile|&&|&)(?=\s|::|$)")


def group_of(dso, kernel, program):
    """The row of Table 1 a library belongs to, and its linear algebra part."""
    if kernel:
        return "kernel", None
    if dso == program:
        return "membranes", None
    for part, _, patterns in LINEAR_ALGEBRA_PARTS:
        if any(fnmatch(dso, p) for p in patterns):
            return "linear algebra", part
    for group, _, patterns in GROUPS:
        if any(fnmatch(dso, p) for p in patterns):
            return group, None
    return "other", None


def short_name(symbol):
    """@p symbol without template arguments, parameter lists, qualifiers,
    return type and clone suffixes: `namespace::Class::function`."""
    if ADDRESS.match(symbol):
        return "(no symbol)"
    symbol = CLONE.sub("", symbol).replace("(anonymous namespace)", "{anonymous}")
    out = []
    angle = paren = brace = 0
    i = 0
    while i < len(symbol):
        c = symbol[i]
        if (angle == paren == 0 and symbol.startswith("operator", i)
                and (i == 0 or not (symbol[i - 1].isalnum() or symbol[i - 1] == "_"))):
            match = OPERATOR.match(symbol, i)
            if match:
                # Spaces of an operator (operator new, operator double) are
                # kept apart from those before the name (the return type).
                out.append(match.group(0).replace(" ", "\0"))
                i = match.end()
                continue
        if c == "<" and paren == 0:
            angle += 1
        elif c == ">" and angle > 0 and paren == 0 and symbol[i - 1] != "-":
            angle -= 1
        elif c == "(" and angle == 0:
            paren += 1
        elif c == ")" and paren > 0 and angle == 0:
            paren -= 1
        elif angle == paren == 0:
            if c == "{":
                brace += 1
            elif c == "}":
                brace -= 1
            out.append("\0" if c == " " and brace > 0 else c)
        i += 1
    words = QUALIFIER.sub("", "".join(out)).split()
    return words[-1].replace("\0", " ") if words else symbol


def read_report(path):
    """Samples per (group, part) and per (dso, short name, symbol)."""
    rows = []
    header_samples = None
    event = "?"
    lost = 0
    with open(path, errors="replace") as f:
        for line in f:
            header = HEADER.match(line)
            if header:
                scale = {"": 1, "K": 1e3, "M": 1e6, "G": 1e9}[header.group(2)]
                header_samples = (int(header.group(1)) * scale, scale)
                event = header.group(3)
                continue
            lost_match = LOST.match(line)
            if lost_match:
                lost = int(lost_match.group(1))
                continue
            if line.startswith("#") or not line.strip():
                continue
            match = LINE.match(line)
            if not match:
                sys.exit(f"profile_table.py: error: {path}: cannot read the line "
                         f"'{line.strip()[:80]}' (made by perf report -n --sort dso,sym?)")
            _, samples, dso, kind, symbol = match.groups()
            rows.append((int(samples), dso, kind == "k", symbol))
    total = sum(r[0] for r in rows)
    if total == 0:
        sys.exit(f"profile_table.py: error: {path} has no samples")
    if header_samples is not None:
        expected, scale = header_samples
        # perf prints 10533 samples as 10K.
        if not expected <= total < expected + scale:
            sys.exit(f"profile_table.py: error: {path}: the rows add up to {total} "
                     f"samples, the header says {expected:.0f}")
    return rows, total, event, lost


def print_table(header, rows, left=()):
    """Markdown table; the columns in @p left left aligned, the others right."""
    widths = [max(len(str(r[i])) for r in [header] + rows) for i in range(len(header))]

    def line(cells):
        return "| " + " | ".join(str(c).ljust(w) if i in left else str(c).rjust(w)
                                 for i, (c, w) in enumerate(zip(cells, widths))) + " |"

    print(line(header))
    print("|" + "|".join((":" + "-" * (w + 1)) if i in left else ("-" * (w + 1) + ":")
                         for i, w in enumerate(widths)) + "|")
    for row in rows:
        print(line(row))


def share(samples, total):
    return f"{100 * samples / total:.1f}"


def function_rows(rows, total, keep, count, with_library):
    """The @p count largest functions of the rows kept by @p keep, with the
    instantiations, overloads and clones of one short name in one row."""
    samples = defaultdict(int)
    symbols = defaultdict(set)
    for n, dso, _, symbol in rows:
        if keep(dso):
            key = (short_name(symbol), dso)
            samples[key] += n
            symbols[key].add(symbol)
    largest = sorted(samples.items(), key=lambda item: (-item[1], item[0]))[:count]
    table = []
    for rank, ((name, dso), n) in enumerate(largest, 1):
        merged = len(symbols[(name, dso)])
        if name == "(no symbol)":
            label = f"{name}, {merged} address{'es' if merged > 1 else ''}"
        else:
            label = f"`{name}`" + (f" ×{merged}" if merged > 1 else "")
        table.append([rank, label] + ([dso] if with_library else [])
                     + [n, share(n, total)])
    return table


def main(argv):
    args = argv[1:]
    program = "membranes"
    if len(args) == 3 and args[0] == "--program":
        program, args = args[1], args[2:]
    if len(args) != 1:
        sys.exit(__doc__)
    rows, total, event, lost = read_report(args[0])

    by_group = defaultdict(int)
    by_part = defaultdict(int)
    other = defaultdict(int)
    for n, dso, kernel, _ in rows:
        group, part = group_of(dso, kernel, program)
        by_group[group] += n
        if part:
            by_part[part] += n
        if group == "other":
            other[dso] += n

    print(f"{total} samples of event {event}"
          + (f", {lost} lost" if lost else "") + ".")
    print()
    table = [["linear algebra", "Trilinos, direct solvers, BLAS, LAPACK",
              by_group["linear algebra"], share(by_group["linear algebra"], total)]]
    for part, libraries, _ in LINEAR_ALGEBRA_PARTS:
        table.append([part, libraries, by_part[part], share(by_part[part], total)])
    for group, libraries, _ in GROUPS:
        if group == "membranes":
            libraries = f"`{program}`"
        table.append([group, libraries, by_group[group], share(by_group[group], total)])
    grouped = sum(by_group.values())
    table.append(["total", "", grouped, share(grouped, total)])
    print_table(["group", "libraries", "samples", "share [%]"], table, left=(0, 1))
    if other:
        largest = sorted(other.items(), key=lambda item: -item[1])[:5]
        print()
        print("Largest in other (samples): " + ", ".join(
            f"{dso} {n}" for dso, n in largest) + ".")
    print()

    print(f"The {PROGRAM_ROWS} largest functions of `{program}` by self share:")
    print()
    print_table(["#", "function", "samples", "share [%]"],
                function_rows(rows, total, lambda dso: dso == program,
                              PROGRAM_ROWS, False), left=(1,))
    print()
    print(f"The {OVERALL_ROWS} largest functions of the process by self share:")
    print()
    print_table(["#", "function", "library", "samples", "share [%]"],
                function_rows(rows, total, lambda dso: True, OVERALL_ROWS, True),
                left=(1, 2))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
