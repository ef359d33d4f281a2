#!/usr/bin/env python3
"""Check which files a run left: ``check_output_files.py DIR [--present GLOB]
[--absent GLOB]...``.

Every ``--present`` pattern must match at least one file in DIR, every
``--absent`` pattern none. Prints one PASS/FAIL line per pattern and exits 1
on any failure.
"""
import argparse
import glob
import os
import sys


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("directory")
    parser.add_argument("--present", action="append", default=[])
    parser.add_argument("--absent", action="append", default=[])
    args = parser.parse_args()

    failed = False
    for pattern, wanted in ([(p, True) for p in args.present] +
                            [(p, False) for p in args.absent]):
        found = sorted(glob.glob(os.path.join(args.directory, pattern)))
        ok = bool(found) == wanted
        failed |= not ok
        print("%s %s %s: %s" % ("PASS" if ok else "FAIL",
                                "present" if wanted else "absent", pattern,
                                ", ".join(map(os.path.basename, found))
                                or "no file"))
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
