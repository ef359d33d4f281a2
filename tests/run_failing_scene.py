#!/usr/bin/env python3
"""Run a scene that must fail::

    run_failing_scene.py OUTDIR WORDS [--launcher LAUNCHER... --] membranes [args...]

As run_scene.py (OUTDIR removed first and passed as ``Output/Directory``,
an optional MPI launcher), but the run passes if it ends with exit status 1
and exactly one line on stderr, ``membranes: error: ...``, that contains
every word of WORDS (a ``|``-separated list). Under a launcher, only the
program's own lines of stderr count (the launcher adds its report of the
exit status) and any non-zero exit status of the launcher is accepted.
"""
import subprocess
import sys

from run_scene import scene_command


def main():
    if len(sys.argv) < 4:
        sys.exit("usage: run_failing_scene.py OUTDIR WORDS "
                 "[--launcher LAUNCHER... --] membranes [args...]")
    words = sys.argv[2].split("|")
    launcher, command = scene_command(sys.argv[1:2] + sys.argv[3:])
    print(" ".join(command), flush=True)
    result = subprocess.run(command, stderr=subprocess.PIPE, text=True)
    lines = [line for line in result.stderr.splitlines()
             if not launcher or line.startswith("membranes")]
    print("\n".join(lines))
    problems = []
    if result.returncode == 0 or (not launcher and result.returncode != 1):
        problems.append(f"exit status {result.returncode}, not 1")
    if len(lines) != 1 or not lines[0].startswith("membranes: error: "):
        problems.append("stderr is not one 'membranes: error:' line")
    problems += [f"the message does not contain {word!r}" for word in words
                 if not any(word in line for line in lines)]
    for problem in problems:
        print("FAIL " + problem)
    if not problems:
        print(f"PASS exit status {result.returncode}, one error line naming "
              + ", ".join(words))
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
