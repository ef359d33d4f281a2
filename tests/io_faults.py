#!/usr/bin/env python3
"""An output file that cannot be written ends the run in one line::

    io_faults.py CASE MEMBRANES SCENES WORKDIR

SCENES is the directory of the shipped scenes; CASE one of

- file_size: a file-size limit (RLIMIT_FSIZE, as 'ulimit -f' sets it)
  just below the size of solution-04.vtu, measured on a run without limit:
  the write fails with 'File too large' (the signal SIGXFSZ that the
  system sends must not end the process).
- no_space: the output directory on a small tmpfs that fills up during
  the run: 'No space left on device'. Needs to mount a file system (root,
  outside a container that forbids it); skipped otherwise (exit status 77).
- removed: the output directory removed during the run: 'No such file or
  directory'.
- read_only: the output directory made read-only during the run:
  'Permission denied'. Root may write anyway: as root, the program runs as
  the user nobody (skipped, exit status 77, if it cannot).

Each run must end with exit status 1 and exactly one line on stderr,
'membranes: error: ...', shorter than 200 characters, that names the file
and the system's reason; report.csv, where it is left, must have complete
rows only, and no temporary file (*.tmp) may be left.

Prints one PASS/FAIL line per check (SKIP and why, for a case that cannot
run here) and exits 1 on any failure.
"""
import csv
import errno
import os
import pwd
import re
import resource
import shutil
import signal
import subprocess
import sys
import time

from checks import check, failures

# The default scene: 5 cycles in under 1 s, the last file solution-04.vtu
# (16 kB) the largest; 12 cycles in about 2.5 s, 1.5 s of which after the
# second cycle, when the faults during the run strike.
SHORT_RUN = ["--set", "Refinement/Cycles=5"]
LONG_RUN = ["--set", "Refinement/Cycles=12"]
TIMEOUT = 60
SKIP = 77
# The files that a run of the default scene writes.
OUTPUT_FILE = r"(report\.csv|solution-[0-9]{2}\.vtu|solution\.pvd" \
    r"|parameters\.prm|run-info\.txt)"


def skip(why):
    print("SKIP " + why, flush=True)
    sys.exit(SKIP)


def command(membranes, scenes, outdir, cycles):
    return [membranes, "--set", "Output/Directory=" + outdir] + cycles + [
        os.path.join(scenes, "default.prm")]


def start(command, preexec_fn=None, env=None):
    print(" ".join(command), flush=True)
    return subprocess.Popen(command, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True,
                            preexec_fn=preexec_fn, env=env)


def finish(process):
    """Wait for process to end; its stderr."""
    try:
        _, stderr = process.communicate(timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        process.kill()
        _, stderr = process.communicate()
        check(False, "the run ends within %d s" % TIMEOUT)
    return stderr


def temporary_files(directory):
    return [os.path.join(root, name)
            for root, _, files in os.walk(directory)
            for name in files if name.endswith(".tmp")]


def report_lines(directory):
    """The lines of report.csv in directory, the header first, split into
    fields; none if there is no report.csv."""
    path = os.path.join(directory, "report.csv")
    if not os.path.isfile(path):
        return []
    with open(path, newline="") as f:
        return list(csv.reader(f))


def check_fault(process, stderr, outdir, file_name, reason):
    """The four promises of a failed write: one line naming file_name (a
    regular expression) and reason, exit status 1, report.csv with complete
    rows only, no temporary file."""
    print("stderr: %r" % stderr)
    lines = stderr.splitlines()
    line = lines[0] if lines else ""
    check(len(lines) == 1 and line.startswith("membranes: error: ")
          and len(line) < 200,
          "exactly one line 'membranes: error: ...' under 200 characters "
          "(%d lines, the first %d characters)" % (len(lines), len(line)))
    check(re.search(r"\b%s\b" % file_name, line) is not None
          and reason in line,
          "the line names the file (%s) and the reason (%s)"
          % (file_name, reason))
    check(process.returncode == 1, "exit status %d" % process.returncode)
    path = os.path.join(outdir, "report.csv")
    if os.path.isfile(path):
        with open(path, newline="") as f:
            text = f.read()
        lines = report_lines(outdir)
        check(text.endswith("\n") and len(lines) > 1
              and all(len(fields) == len(lines[0]) for fields in lines),
              "report.csv has only complete rows (%d rows)" % (len(lines) - 1))
    else:
        print("no report.csv left")
    check(not temporary_files(outdir),
          "no temporary file left: %s" % temporary_files(outdir))


def stopped(pid):
    """Whether the process pid is stopped by a signal."""
    with open("/proc/%d/stat" % pid) as f:
        return f.read().rsplit(")", 1)[1].split()[0] in ("T", "t")


def pause_between_writes(process, outdir):
    """Once report.csv has 2 rows, stop process (SIGSTOP) at a moment when
    it writes no file (no *.tmp in outdir); whether it could."""
    deadline = time.time() + TIMEOUT
    while len(report_lines(outdir)) < 1 + 2 and process.poll() is None \
            and time.time() < deadline:
        time.sleep(0.005)
    while process.poll() is None and time.time() < deadline:
        process.send_signal(signal.SIGSTOP)
        while not stopped(process.pid):
            time.sleep(0.001)
        if not temporary_files(outdir):
            return True
        process.send_signal(signal.SIGCONT)
        time.sleep(0.001)
    return False


def fault_during_run(membranes, scenes, outdir, fault, preexec_fn=None):
    """A run of several cycles, paused after its second one for fault(); the
    process and its stderr after it ended."""
    process = start(command(membranes, scenes, outdir, LONG_RUN), preexec_fn)
    if check(pause_between_writes(process, outdir),
             "the run is paused between two writes after its second cycle"):
        fault()
        process.send_signal(signal.SIGCONT)
    return process, finish(process)


def file_size(membranes, scenes, workdir):
    reference = os.path.join(workdir, "reference")
    process = start(command(membranes, scenes, reference, SHORT_RUN))
    check(not finish(process) and process.returncode == 0,
          "the run without limit completes")
    last = "solution-04.vtu"
    limit = os.path.getsize(os.path.join(reference, last)) - 1
    largest = max(os.path.getsize(os.path.join(reference, name))
                  for name in os.listdir(reference) if name != last)
    check(largest <= limit, "its other files (%d bytes at most) fit in the "
          "limit of %d bytes" % (largest, limit))

    def limit_file_size():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    # Open MPI keeps the data of its start-up in shared files of some MB
    # (PMIx's "dstore"), which fails under a smaller limit before the
    # program runs: its plain store ("hash") instead.
    outdir = os.path.join(workdir, "out")
    process = start(command(membranes, scenes, outdir, SHORT_RUN),
                    limit_file_size, dict(os.environ, PMIX_MCA_gds="hash"))
    stderr = finish(process)
    check_fault(process, stderr, outdir, re.escape(last),
                os.strerror(errno.EFBIG))
    check(len(report_lines(outdir)) == 1 + 5,
          "report.csv has the 5 rows written before %s" % last)
    check(not os.path.exists(os.path.join(outdir, last)), "no %s" % last)


def no_space(membranes, scenes, workdir):
    mount_point = os.path.join(workdir, "tmpfs")
    os.makedirs(mount_point)
    mount = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=300k",
                            "tmpfs", mount_point],
                           stderr=subprocess.PIPE, text=True)
    if mount.returncode != 0:
        skip("no_space: cannot mount a tmpfs here: %s"
             % " ".join(mount.stderr.split()))
    try:
        outdir = os.path.join(mount_point, "out")
        process = start(command(membranes, scenes, outdir, LONG_RUN))
        stderr = finish(process)
        check_fault(process, stderr, outdir, OUTPUT_FILE,
                    os.strerror(errno.ENOSPC))
    finally:
        subprocess.run(["umount", mount_point])


def removed(membranes, scenes, workdir):
    outdir = os.path.join(workdir, "out")
    process, stderr = fault_during_run(membranes, scenes, outdir,
                                       lambda: shutil.rmtree(outdir))
    check_fault(process, stderr, outdir, OUTPUT_FILE,
                os.strerror(errno.ENOENT))


def read_only(membranes, scenes, workdir):
    run_as = None
    if os.geteuid() == 0:
        nobody = pwd.getpwnam("nobody")
        os.chown(workdir, nobody.pw_uid, nobody.pw_gid)

        def become_nobody():
            os.setgroups([])
            os.setgid(nobody.pw_gid)
            os.setuid(nobody.pw_uid)

        run_as = become_nobody
        scene = os.path.join(scenes, "default.prm")
        if subprocess.run(["test", "-x", membranes, "-a", "-r", scene,
                           "-a", "-w", workdir],
                          preexec_fn=run_as).returncode != 0:
            skip("read_only: root may write anyway, and the user nobody "
                 "cannot run %s on %s in %s" % (membranes, scene, workdir))
    outdir = os.path.join(workdir, "out")
    try:
        process, stderr = fault_during_run(
            membranes, scenes, outdir, lambda: os.chmod(outdir, 0o555), run_as)
        check_fault(process, stderr, outdir, OUTPUT_FILE,
                    os.strerror(errno.EACCES))
    finally:
        if os.path.isdir(outdir):
            os.chmod(outdir, 0o755)


CASES = {"file_size": file_size, "no_space": no_space, "removed": removed,
         "read_only": read_only}


def main():
    if len(sys.argv) != 5 or sys.argv[1] not in CASES:
        sys.exit("usage: io_faults.py %s MEMBRANES SCENES WORKDIR"
                 % "|".join(CASES))
    case, membranes, scenes, workdir = sys.argv[1:5]
    workdir = os.path.join(workdir, case)
    shutil.rmtree(workdir, ignore_errors=True)
    os.makedirs(workdir)
    CASES[case](membranes, scenes, workdir)
    print("%s: %d failed" % (case, len(failures)))
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
