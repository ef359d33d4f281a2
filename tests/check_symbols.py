#!/usr/bin/env python3
"""Checks that each symbol of the documents has one meaning.

Usage::

    check_symbols.py [DOCUMENT ...]
    check_symbols.py --planted

Without arguments the documents are doc/tutorial.md and doc/advanced.md
(relative to the top of the source tree, the parent of the directory of
this script). Each document may hold a symbol table: the first Markdown
table whose header is ``| symbol | meaning |``; its first column lists one
or more symbols in ``$...$``, its second their meaning. The checks:

* every row names a symbol in ``$...$`` or a term in ``*italics*``;
* no symbol stands in two rows, of one table or of two (a symbol given two
  meanings by the tables themselves, or listed again by the second
  document instead of being taken from the first);
* outside the tables (in prose; code spans, fenced blocks and display
  math do not count), no symbol of a table is introduced again with a
  meaning that shares no word with the table's: a defining phrase is
  ``with $X$ the ...``, ``where $X$ is the ...``, ``$X$ is the ...``,
  ``$X$ denotes ...``, ``$X$ stands for ...``, ``let $X$ be ...``, ``$X$
  for ...`` after ``write``, or ``$X:=...``, and it passes if the rest of
  its sentence has a word of four letters or more in common with the
  table's meaning (a definition restated, as "with $U_{\\max}$ the largest
  nodal displacement", is not a second meaning).

Symbols compare with their spaces removed, so ``$W_a$`` and ``$w_a$``
differ, and ``$b$`` and ``$b_K$`` are two symbols.

Prints one line ``FILE:LINE: defect`` per defect and exits with status 1 if
there is one, 0 otherwise (and prints the number of symbols checked).

``--planted`` checks the check: it copies the two documents to a temporary
directory, plants in the copy of the first a second row for the symbol of
the last row of its table that has one, and a sentence that introduces the first symbol of
its table again (``Here $X$ denotes a planted quantity.``), and exits with
status 0 only if both are reported.
"""

import os
import re
import shutil
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOCUMENTS = ["doc/tutorial.md", "doc/advanced.md"]

HEADER = re.compile(r"^\|\s*symbol\s*\|\s*meaning\s*\|\s*$")
MATH = re.compile(r"\$([^$]+)\$")
FENCE = re.compile(r"^ {0,3}(`{3,}|~{3,})")
STOP = {"with", "that", "this", "these", "those", "their", "there", "from",
        "each", "where", "which", "what", "when", "than", "then", "only",
        "also", "into", "over", "under", "both", "same", "other", "every",
        "once", "one", "the", "and", "for", "its", "are", "is", "on", "of",
        "in", "by", "as", "at", "to"}


def normalized(symbol):
    return re.sub(r"\s+", "", symbol)


def words(text):
    """The words of four letters or more of @p text, without those of its
    math, lower case, cut to their first five letters ("force" and
    "forces" are one word)."""
    text = MATH.sub(" ", text)
    return {w[:5] for w in re.findall(r"[a-z]{4,}", text.lower())
            if w not in STOP}


def symbol_table(lines):
    """(first line, last line, rows) of the symbol table of @p lines; each
    row is (line number, [symbols], meaning). None without a table."""
    for start, line in enumerate(lines):
        if HEADER.match(line):
            rows, end = [], start + 1
            while end < len(lines) and lines[end].startswith("|"):
                cells = lines[end].strip().strip("|").split("|")
                if not set(lines[end].strip()) <= set("|-: "):
                    symbols = [normalized(s) for s in MATH.findall(cells[0])]
                    meaning = "|".join(cells[1:])
                    rows.append((end + 1, symbols, meaning))
                end += 1
            return start, end - 1, rows
    return None


def symbol_cell(line):
    """The first cell of a table row."""
    return line.strip().strip("|").split("|")[0]


def prose(lines, table):
    """The lines of @p lines outside fenced blocks, display math and the
    table span @p table (0-based, inclusive), code spans blanked, as
    (line number, text)."""
    fence = None
    for number, line in enumerate(lines):
        match = FENCE.match(line)
        if fence:
            if match and match.group(1)[0] == fence[0] and \
                    len(match.group(1)) >= len(fence):
                fence = None
            continue
        if match:
            fence = match.group(1)
            continue
        if table and table[0] <= number <= table[1]:
            continue
        yield number + 1, re.sub(r"`[^`]*`", "``", line)


def definitions(text, symbol):
    """The defining phrases of @p symbol in @p text: (offset, the rest of
    the sentence)."""
    s = re.escape("$" + symbol + "$")
    patterns = [
        r"(?:\bwith|\bwhere|\band|,|;)\s+" + s + r"\s+(?:is\s+)?(?:the|an?)\s",
        r"(?:^|[.:]\s+)" + s + r"\s+is\s+the\s",
        s + r"\s+(?:denotes|stands\s+for|is\s+defined\s+as|is\s+called)\b",
        r"\b[Ll]et\s+" + s + r"\s+be\b",
        r"\bwrite\s+" + s + r"\s+for\b",
        r"\$" + re.escape(symbol) + r"\s*:=",
    ]
    for pattern in patterns:
        for match in re.finditer(pattern, text):
            rest = text[match.end():]
            end = re.search(r"(?<!\be\.g)(?<!\bi\.e)\.\s", rest)
            yield match.start(), rest[:end.start() if end else 300]


def check(paths):
    documents = []
    for path in paths:
        with open(path, encoding="utf-8") as f:
            lines = f.read().splitlines()
        documents.append((path, lines, symbol_table(lines)))

    defects = []
    meaning_of, where = {}, {}
    for path, lines, table in documents:
        if table is None:
            continue
        for number, symbols, meaning in table[2]:
            if not symbols and not re.search(r"\*\w[^*]*\*", symbol_cell(
                    lines[number - 1])):
                defects.append(f"{path}:{number}: a row without a symbol "
                               "(or a term in *italics*)")
            for symbol in symbols:
                if symbol in where:
                    defects.append(f"{path}:{number}: ${symbol}$ also in "
                                   f"the row of {where[symbol]}")
                else:
                    where[symbol] = f"{path}:{number}"
                    meaning_of[symbol] = meaning

    for path, lines, table in documents:
        # A paragraph at a time, so that a phrase may run over a line break.
        paragraphs, current = [], []
        for number, line in prose(lines, table and table[:2]):
            if line.strip():
                current.append((number, line))
            elif current:
                paragraphs.append(current)
                current = []
        if current:
            paragraphs.append(current)
        for paragraph in paragraphs:
            text = " ".join(line for _, line in paragraph)
            starts, offset = [], 0
            for number, line in paragraph:
                starts.append((offset, number))
                offset += len(line) + 1
            for symbol, meaning in meaning_of.items():
                for position, rest in definitions(text, symbol):
                    if words(rest) & words(meaning):
                        continue
                    number = [n for o, n in starts if o <= position][-1]
                    defects.append(
                        f"{path}:{number}: ${symbol}$ introduced again with "
                        f"another meaning than in {where[symbol]}: "
                        f"\"{rest.strip()[:60]}\"")
    return defects, len(meaning_of)


def planted():
    """0 if the defects planted in copies of the documents are reported."""
    with tempfile.TemporaryDirectory() as directory:
        paths = []
        for name in DOCUMENTS:
            paths.append(os.path.join(directory, os.path.basename(name)))
            shutil.copy(os.path.join(ROOT, name), paths[-1])
        with open(paths[0], encoding="utf-8") as f:
            lines = f.read().splitlines()
        start, end, rows = symbol_table(lines)
        rows = [row for row in rows if row[1]]
        duplicate = f"${rows[-1][1][0]}$"
        redefined = f"${rows[0][1][0]}$"
        lines.insert(end + 1, f"| {duplicate} | a planted second meaning |")
        lines += ["", f"Here {redefined} denotes a planted quantity.", ""]
        with open(paths[0], "w", encoding="utf-8") as f:
            f.write("\n".join(lines) + "\n")
        defects, _ = check(paths)
    wanted = [f"{duplicate} also in the row of",
              f"{redefined} introduced again with another meaning"]
    for defect in defects:
        print(defect)
    missed = [w for w in wanted if not any(w in d for d in defects)]
    for w in missed:
        print(f"planted defect not reported: {w}")
    return 1 if missed else 0


def main(argv):
    if argv[1:] == ["--planted"]:
        return planted()
    paths = argv[1:] or [os.path.relpath(os.path.join(ROOT, d))
                         for d in DOCUMENTS]
    defects, n_symbols = check(paths)
    for defect in defects:
        print(defect)
    if defects:
        return 1
    print(f"{n_symbols} symbols, each with one meaning in "
          f"{', '.join(os.path.relpath(p) for p in paths)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
