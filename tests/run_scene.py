#!/usr/bin/env python3
"""Run one scene for a test::

    run_scene.py OUTDIR [--launcher 'mpiexec -n 2' --] membranes [args...]

OUTDIR is removed first (so that no file of an earlier run can make a later
check pass) and passed to the program as ``Output/Directory``. With
``--launcher``, the words up to ``--`` start the program (an MPI launcher
and its options).
"""
import shutil
import subprocess
import sys


def scene_command(arguments):
    """OUTDIR [--launcher WORDS... --] membranes [args...] → (launcher
    words, the command to run), with OUTDIR removed."""
    outdir, command = arguments[0], arguments[1:]
    launcher = []
    if command[0] == "--launcher":
        end = command.index("--")
        launcher, command = command[1:end], command[end + 1:]
    shutil.rmtree(outdir, ignore_errors=True)
    return launcher, (launcher + command[:1]
                      + ["--set", "Output/Directory=" + outdir] + command[1:])


def main():
    if len(sys.argv) < 3:
        sys.exit("usage: run_scene.py OUTDIR [--launcher WORDS... --] "
                 "membranes [args...]")
    command = scene_command(sys.argv[1:])[1]
    print(" ".join(command), flush=True)
    sys.exit(subprocess.call(command))


if __name__ == "__main__":
    main()
