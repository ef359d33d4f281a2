#!/usr/bin/env python3
"""Run one scene for a test: ``run_scene.py OUTDIR membranes [args...]``.

OUTDIR is removed first (so that no file of an earlier run can make a later
check pass) and passed to the program as ``Output/Directory``.
"""
import shutil
import subprocess
import sys


def main():
    if len(sys.argv) < 3:
        sys.exit("usage: run_scene.py OUTDIR membranes [args...]")
    outdir, command = sys.argv[1], sys.argv[2:]
    shutil.rmtree(outdir, ignore_errors=True)
    command = command[:1] + ["--set", "Output/Directory=" + outdir] + command[1:]
    print(" ".join(command), flush=True)
    sys.exit(subprocess.call(command))


if __name__ == "__main__":
    main()
