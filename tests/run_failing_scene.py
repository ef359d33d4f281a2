#!/usr/bin/env python3
"""Run a scene that must fail: ``run_failing_scene.py OUTDIR WORDS membranes
[args...]``.

As run_scene.py (OUTDIR removed first and passed as ``Output/Directory``),
but the run passes if it ends with exit status 1 and exactly one line on
stderr, ``membranes: error: ...``, that contains every word of WORDS (a
``|``-separated list).
"""
import shutil
import subprocess
import sys


def main():
    if len(sys.argv) < 4:
        sys.exit("usage: run_failing_scene.py OUTDIR WORDS membranes [args...]")
    outdir, words, command = sys.argv[1], sys.argv[2].split("|"), sys.argv[3:]
    shutil.rmtree(outdir, ignore_errors=True)
    command = command[:1] + ["--set", "Output/Directory=" + outdir] + command[1:]
    print(" ".join(command), flush=True)
    result = subprocess.run(command, stderr=subprocess.PIPE, text=True)
    lines = result.stderr.rstrip("\n").split("\n") if result.stderr else []
    print("\n".join(lines))
    problems = []
    if result.returncode != 1:
        problems.append(f"exit status {result.returncode}, not 1")
    if len(lines) != 1 or not lines[0].startswith("membranes: error: "):
        problems.append("stderr is not one 'membranes: error:' line")
    problems += [f"the message does not contain {word!r}" for word in words
                 if not any(word in line for line in lines)]
    for problem in problems:
        print("FAIL " + problem)
    if not problems:
        print("PASS exit status 1, one error line naming " + ", ".join(words))
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
