#!/usr/bin/env python3
"""A study resumed from its checkpoint gives the report of the study run
without interruption, and a resume that cannot be done ends in one line::

    resume.py CASE MEMBRANES SCENE WORKDIR PROCESSES K N [SETTING ...]

runs the scene SCENE (a parameter file) with the SETTINGs (``Sub/Entry=
value``, as --set takes them) and ``Output/Write vtu = false`` on PROCESSES
processes (if more than one, by the launcher that LAUNCHER in the
environment names with its flag for the number of processes, default
"mpiexec -n"), in directories below WORKDIR. CASE is one of

- kill: the study of N cycles with ``Output/Checkpoint every = 1``, killed
  with SIGKILL (its whole process group) at a random point after its K-th
  row of report.csv, and resumed with ``--resume``; its report.csv must
  equal that of the same study run without interruption
  (compare_reports.py --report --rtol 1e-10: integers exactly, values to
  1e-10);
- extend: K cycles with a checkpoint, then ``--resume`` with ``Refinement/
  Cycles = N``: the same comparison;
- hostile: after K cycles with a checkpoint, each of these resumes must end
  with exit status 1 and one line on stderr naming the problem, and leave
  report.csv as it was: a directory without a study, another scene
  (``Problem/mu1 = 2``), the largest file of the checkpoint truncated, no
  checkpoint, and a directory whose lock another process holds.

Prints one PASS/FAIL line per check and exits 1 on any failure.
"""
import fcntl
import os
import random
import shutil
import signal
import subprocess
import sys
import time

from checks import check, failures

TIMEOUT = 300
HERE = os.path.dirname(os.path.abspath(__file__))


def command(membranes, scene, processes, directory, cycles, settings,
            extra=()):
    launcher = []
    if processes > 1:
        launcher = os.environ.get("LAUNCHER", "mpiexec -n").split() + \
            [str(processes)]
    arguments = [membranes, "--set", "Output/Write vtu=false",
                 "--set", f"Refinement/Cycles={cycles}",
                 "--set", f"Output/Directory={directory}"]
    for setting in list(settings) + list(extra):
        arguments += ["--set", setting]
    return launcher + arguments + [scene]


def run(arguments, resume=False):
    if resume:
        arguments = arguments[:-1] + ["--resume", arguments[-1]]
    return subprocess.run(arguments, capture_output=True, text=True,
                          timeout=TIMEOUT)


def rows(directory):
    try:
        with open(os.path.join(directory, "report.csv")) as report:
            return max(sum(1 for _ in report) - 1, 0)
    except OSError:
        return 0


def descendants(pid):
    """The processes below @p pid (/proc), e.g. the ranks of mpiexec, which
    Open MPI starts in process groups of their own."""
    children = {}
    for entry in os.listdir("/proc"):
        try:
            with open(f"/proc/{entry}/stat") as stat:
                fields = stat.read().rsplit(")", 1)[1].split()
            children.setdefault(int(fields[1]), []).append(int(entry))
        except (OSError, ValueError, IndexError):
            continue
    found, todo = [], [pid]
    while todo:
        below = children.get(todo.pop(), [])
        found += below
        todo += below
    return found


def kill_job(study, directory):
    """SIGKILL to @p study and every process below it at once, as a batch
    system ends a job; back when the output directory's lock is free."""
    for pid in [study.pid] + descendants(study.pid):
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    study.wait()
    with open(os.path.join(directory, ".membranes-lock"), "a") as lock:
        start = time.time()
        while time.time() - start < TIMEOUT:
            try:
                fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
                fcntl.flock(lock, fcntl.LOCK_UN)
                return
            except OSError:
                time.sleep(0.01)


def watched(arguments, directory):
    """Run @p arguments; the times at which each row of report.csv in
    @p directory appeared, from the start."""
    start = time.time()
    study = subprocess.Popen(arguments, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    times = []
    while study.poll() is None:
        while rows(directory) > len(times):
            times.append(time.time() - start)
        time.sleep(0.002)
    times += [time.time() - start] * (rows(directory) - len(times))
    return study.returncode, times


def same_report(first, second, what):
    compared = subprocess.run(
        [sys.executable, os.path.join(HERE, "compare_reports.py"),
         "--report", "--rtol", "1e-10",
         os.path.join(first, "report.csv"),
         os.path.join(second, "report.csv")],
        capture_output=True, text=True)
    print(compared.stdout, end="")
    check(compared.returncode == 0, what)


def reference(membranes, scene, processes, work, n, settings):
    """The uninterrupted study: its directory, and the times at which its
    rows appeared."""
    directory = os.path.join(work, "uninterrupted")
    shutil.rmtree(directory, ignore_errors=True)
    status, times = watched(
        command(membranes, scene, processes, directory, n, settings),
        directory)
    check(status == 0, "the uninterrupted study runs")
    return directory, times


def kill(membranes, scene, processes, work, k, n, settings):
    expected, times = reference(membranes, scene, processes, work, n,
                                settings)
    directory = os.path.join(work, "killed")
    shutil.rmtree(directory, ignore_errors=True)
    arguments = command(membranes, scene, processes, directory, n, settings,
                        ["Output/Checkpoint every=1"])
    study = subprocess.Popen(arguments, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    start = time.time()
    while rows(directory) < k and study.poll() is None and \
            time.time() - start < TIMEOUT:
        time.sleep(0.002)
    # A random point of the next cycle, whose duration the uninterrupted
    # study measured.
    seed = random.randrange(1 << 30)
    delay = random.Random(seed).uniform(0, times[k] - times[k - 1])
    time.sleep(delay)
    killed_at = rows(directory)
    check(study.poll() is None,
          f"killed {delay:.3f} s after row {k} (seed {seed}, the cycle "
          f"took {times[k] - times[k - 1]:.3f} s), {killed_at} rows "
          "written, before the study ended")
    kill_job(study, directory)
    resumed = run(arguments, resume=True)
    print(resumed.stdout.splitlines()[0] if resumed.stdout else "", flush=True)
    check(resumed.returncode == 0,
          "the resumed study runs " + resumed.stderr.strip())
    same_report(directory, expected,
                "the resumed report is the uninterrupted one")


def extend(membranes, scene, processes, work, k, n, settings):
    expected = reference(membranes, scene, processes, work, n, settings)[0]
    directory = os.path.join(work, "extended")
    shutil.rmtree(directory, ignore_errors=True)
    first = run(command(membranes, scene, processes, directory, k, settings,
                        ["Output/Checkpoint every=1"]))
    check(first.returncode == 0, f"the study of {k} cycles runs")
    resumed = run(command(membranes, scene, processes, directory, n,
                          settings, ["Output/Checkpoint every=1"]),
                  resume=True)
    check(resumed.returncode == 0,
          f"the study resumed to {n} cycles runs " + resumed.stderr.strip())
    same_report(directory, expected,
                "the extended report is the uninterrupted one")


def refused(arguments, directory, what, message):
    """The resume of @p arguments ends in one line with @p message."""
    report = os.path.join(directory, "report.csv")
    before = open(report).read() if os.path.exists(report) else None
    done = run(arguments, resume=True)
    lines = done.stderr.strip().splitlines()
    print(done.stderr, end="")
    check(done.returncode == 1, f"{what}: exit status 1")
    check(len(lines) == 1 and message in lines[0],
          f"{what}: one line naming it ('{message}')")
    after = open(report).read() if os.path.exists(report) else None
    check(before == after, f"{what}: report.csv as it was")


def hostile(membranes, scene, processes, work, k, n, settings):
    directory = os.path.join(work, "hostile")
    shutil.rmtree(directory, ignore_errors=True)
    arguments = command(membranes, scene, processes, directory, n, settings)
    refused(arguments, directory, "a directory without a study",
            "holds no study to resume")
    first = run(command(membranes, scene, processes, directory, k, settings,
                        ["Output/Checkpoint every=1"]))
    check(first.returncode == 0, f"the study of {k} cycles runs")
    refused(command(membranes, scene, processes, directory, n, settings,
                    ["Problem/mu1=2"]),
            directory, "another scene", "'Problem/mu1' is '2' here")

    with open(os.path.join(directory, ".membranes-lock"), "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        refused(arguments, directory, "a directory in use", "in use")

    checkpoint = os.path.join(directory, "checkpoint")
    files = [os.path.join(checkpoint, name) for name in
             os.listdir(checkpoint)]
    largest = max(files, key=os.path.getsize)
    with open(largest, "r+b") as truncated:
        truncated.truncate(os.path.getsize(largest) // 2)
    refused(arguments, directory, "a truncated checkpoint", "is damaged")
    shutil.rmtree(checkpoint)
    refused(arguments, directory, "no checkpoint", "no checkpoint")


def main(arguments):
    case, membranes, scene, work = arguments[:4]
    processes, k, n = (int(a) for a in arguments[4:7])
    settings = arguments[7:]
    os.makedirs(work, exist_ok=True)
    {"kill": kill, "extend": extend, "hostile": hostile}[case](
        membranes, scene, processes, work, k, n, settings)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
