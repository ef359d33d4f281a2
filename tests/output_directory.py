#!/usr/bin/env python3
"""An output directory holds one run, all of it, and says how it was made::

    output_directory.py CASE MEMBRANES SCENES WORKDIR [MPI_LAUNCHER]

SCENES is the directory of the shipped scenes; CASE one of

- race: a second run on the directory of a running one is refused (exit
  status 1, one line 'membranes: error:' naming the directory and that it
  is in use), before it computes or removes anything; with MPI_LAUNCHER
  (e.g. 'mpiexec -n') also on two processes. The first run completes
  untouched: all its rows, all its files, its own parameters.prm.
- rerun: a run with fewer cycles than the one before leaves exactly its
  own files: none of the earlier run's (later cycles, dual mesh, nodal
  values, unconverged/, temporary files of an interrupted write), and every
  file that the program did not write.
- kill: a run killed (SIGKILL) once it has written two cycles does not
  block the next run on its directory, which leaves no file of the killed
  one.
- kill_mpi: the same with one process of a run on two (MPI_LAUNCHER) killed,
  the one that does not hold the directory: the launcher ends the run (no
  process waits for the killed one) with a non-zero exit status.
- reproduce: the parameters.prm of a run (a scene with a relative mesh
  file, settings from the command line) makes the same run, as another
  directory (--set Output/Directory) and, after it ended, in its own
  directory: the same report.csv, time and memory columns aside.

Prints one PASS/FAIL line per check and exits 1 on any failure.
"""
import csv
import os
import re
import shutil
import signal
import subprocess
import sys
import time

from checks import check, failures

# A run of the race and kill cases: case M on quadrilaterals, 7 cycles,
# about 5 s on one core (the 7th cycle alone takes 3.5 s).
LONG_RUN = ["--set", "Refinement/Cycles=7"]
TIMEOUT = 120
# Seconds within which the launcher ends a job of which one process died.
KILLED_JOB_TIMEOUT = 20


def start(command, cwd=None):
    print(" ".join(command), flush=True)
    return subprocess.Popen(command, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True, cwd=cwd)


def run(command, cwd=None):
    print(" ".join(command), flush=True)
    return subprocess.run(command, stdout=subprocess.DEVNULL,
                          stderr=subprocess.PIPE, text=True, cwd=cwd,
                          timeout=TIMEOUT)


def wait_for(condition, process):
    """Wait until condition() holds while process runs; whether it does."""
    deadline = time.time() + TIMEOUT
    while not condition() and process.poll() is None \
            and time.time() < deadline:
        time.sleep(0.05)
    return condition()


def report_rows(directory):
    path = os.path.join(directory, "report.csv")
    if not os.path.isfile(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def listing(directory):
    """Every file and directory below directory, as relative paths."""
    found = set()
    for root, dirs, files in os.walk(directory):
        for name in dirs + files:
            found.add(os.path.relpath(os.path.join(root, name), directory))
    return found


def program_lines(stderr):
    """The lines of the program on stderr (a launcher adds its own)."""
    return [line for line in stderr.splitlines()
            if line.startswith("membranes")]


def race(membranes, scenes, workdir, launcher):
    outdir = os.path.join(workdir, "race")
    scene = os.path.join(scenes, "case-m-quadrilateral.prm")
    first = start([membranes, "--set", "Output/Directory=" + outdir]
                  + LONG_RUN + [scene])
    check(wait_for(lambda: os.path.isfile(
        os.path.join(outdir, "parameters.prm")), first),
        "the first run claims the directory")
    seconds = [("one process",
                [membranes, "--set", "Geometry/Cell type=triangle"])]
    if launcher:
        seconds.append(("two processes", launcher.split() + ["2", membranes]))
    for name, command in seconds:
        second = run(command + ["--set", "Output/Directory=" + outdir,
                                "--set", "Refinement/Cycles=2", scene])
        lines = program_lines(second.stderr)
        check(second.returncode != 0, "the second run (%s) exits with "
              "status %d" % (name, second.returncode))
        check(len(lines) == 1 and lines[0].startswith("membranes: error: ")
              and outdir in lines[0] and "in use" in lines[0],
              "the second run (%s) says in one line that %s is in use: %r"
              % (name, outdir, second.stderr))
    check(first.poll() is None,
          "the first run was still running when the second ones ended")
    first.wait(timeout=TIMEOUT)
    check(first.returncode == 0 and not first.stderr.read(),
          "the first run completes (exit status %d)" % first.returncode)
    rows = report_rows(outdir)
    check([row["cycle"] for row in rows] == [str(c) for c in range(7)],
          "report.csv has the 7 rows of the first run")
    expected = {"solution-%02d.vtu" % c for c in range(7)} | {
        "solution.pvd", "report.csv", "parameters.prm", "run-info.txt",
        ".membranes-lock"}
    check(listing(outdir) == expected, "the directory holds the files of "
          "the first run: %s" % sorted(listing(outdir)))
    with open(os.path.join(outdir, "parameters.prm")) as f:
        prm = f.read()
    check(re.search(r"set Cycles += 7", prm) and "= quadrilateral" in prm,
          "parameters.prm is that of the first run")


def rerun(membranes, scenes, workdir, launcher):
    outdir = os.path.join(workdir, "rerun")
    scene = os.path.join(scenes, "case-m-quadrilateral.prm")
    first = run([membranes, "--set", "Output/Directory=" + outdir,
                 "--set", "Refinement/Cycles=4",
                 "--set", "Output/Flux reconstruction=true",
                 "--set", "Output/Write nodal values=true", scene])
    check(first.returncode == 0, "the first run, 4 cycles, completes")
    # What an interrupted write and an unconverged run leave, and files the
    # program does not write.
    planted = {
        "solution-07.vtu.tmp": "<VTKFile",
        "report.csv.tmp": "cycle,",
        "unconverged/solution-03.vtu": "<VTKFile",
        "unconverged/solution-03.0001.vtu": "<VTKFile",
        "unconverged/solution-03.pvtu": "<VTKFile",
        "unconverged/nodal-values-03.csv": "x,y",
        "unconverged/solution.pvd.tmp": "<VTKFile",
        "notes.txt": "mine",
        "report.csv.bak": "mine",
        "my-solution-01.vtu": "mine",
        "solution-1.vtu": "mine",
        "convergence.png": "mine",
        "images/solution-00.vtu": "mine",
    }
    for name, text in planted.items():
        os.makedirs(os.path.dirname(os.path.join(outdir, name)),
                    exist_ok=True)
        with open(os.path.join(outdir, name), "w") as out:
            out.write(text)
    second = run([membranes, "--set", "Output/Directory=" + outdir,
                  "--set", "Refinement/Cycles=2", scene])
    check(second.returncode == 0 and not second.stderr,
          "the second run, 2 cycles, completes")
    foreign = {name for name in planted if not name.endswith(".tmp")
               and not name.startswith("unconverged/")} | {"images"}
    expected = foreign | {"solution-00.vtu", "solution-01.vtu",
                          "solution.pvd", "report.csv", "parameters.prm",
                          "run-info.txt", ".membranes-lock"}
    found = listing(outdir)
    check(found == expected, "the directory holds the second run's files "
          "and the foreign ones: extra %s, missing %s"
          % (sorted(found - expected), sorted(expected - found)))
    for name in foreign - {"images"}:
        with open(os.path.join(outdir, name)) as f:
            check(f.read() == "mine", "%s is untouched" % name)
    check(len(report_rows(outdir)) == 2, "report.csv has 2 rows")
    with open(os.path.join(outdir, "solution.pvd")) as f:
        check(f.read().count("<DataSet") == 2, "solution.pvd lists 2 cycles")


def next_run_after_kill(membranes, scene, outdir):
    """The next run on the directory of a killed run completes and leaves
    no file of the killed one."""
    print("left by the killed run: %s" % sorted(listing(outdir)))
    second = run([membranes, "--set", "Output/Directory=" + outdir,
                  "--set", "Refinement/Cycles=1", scene])
    check(second.returncode == 0 and not second.stderr,
          "the next run completes: %r" % second.stderr)
    expected = {"solution-00.vtu", "solution.pvd", "report.csv",
                "parameters.prm", "run-info.txt", ".membranes-lock"}
    check(listing(outdir) == expected, "the directory holds the next run's "
          "files only: %s" % sorted(listing(outdir)))
    check(len(report_rows(outdir)) == 1, "report.csv has 1 row")


def kill(membranes, scenes, workdir, launcher):
    outdir = os.path.join(workdir, "kill")
    scene = os.path.join(scenes, "case-m-quadrilateral.prm")
    first = start([membranes, "--set", "Output/Directory=" + outdir,
                   "--set", "Output/Write nodal values=true"]
                  + LONG_RUN + [scene])
    check(wait_for(lambda: len(report_rows(outdir)) >= 2, first),
          "the first run writes 2 rows")
    first.send_signal(signal.SIGKILL)
    first.wait(timeout=TIMEOUT)
    check(first.returncode == -signal.SIGKILL, "the first run is killed")
    next_run_after_kill(membranes, scene, outdir)


def ranks(launcher_pid):
    """The processes that the launcher launcher_pid started, by their MPI
    rank (read from their environment): rank -> pid."""
    found, parents = {}, [launcher_pid]
    while parents:
        parent = parents.pop()
        with open("/proc/%d/task/%d/children" % (parent, parent)) as f:
            children = [int(pid) for pid in f.read().split()]
        parents += children
        for pid in children:
            with open("/proc/%d/environ" % pid, "rb") as f:
                variables = dict(v.split(b"=", 1)
                                 for v in f.read().split(b"\0") if b"=" in v)
            rank = variables.get(b"OMPI_COMM_WORLD_RANK",
                                 variables.get(b"PMI_RANK"))
            if rank is not None:
                found[int(rank)] = pid
    return found


def ended(pid):
    """Whether the process pid ends (or is a zombie) within
    KILLED_JOB_TIMEOUT."""
    deadline = time.time() + KILLED_JOB_TIMEOUT
    while time.time() < deadline:
        try:
            with open("/proc/%d/stat" % pid) as f:
                if f.read().rsplit(")", 1)[1].split()[0] == "Z":
                    return True
        except FileNotFoundError:
            return True
        time.sleep(0.05)
    return False


def kill_mpi(membranes, scenes, workdir, launcher):
    outdir = os.path.join(workdir, "kill-mpi")
    scene = os.path.join(scenes, "case-m-quadrilateral.prm")
    first = start(launcher.split() + [
        "2", membranes, "--set", "Output/Directory=" + outdir,
        "--set", "Output/Write nodal values=true"] + LONG_RUN + [scene])
    check(wait_for(lambda: len(report_rows(outdir)) >= 2, first),
          "the first run, on two processes, writes 2 rows")
    processes = ranks(first.pid)
    if not check(sorted(processes) == [0, 1],
                 "the launcher runs ranks 0 and 1: %s" % processes):
        first.kill()
        return
    os.kill(processes[1], signal.SIGKILL)
    try:
        first.wait(timeout=KILLED_JOB_TIMEOUT)
    except subprocess.TimeoutExpired:
        first.kill()
        os.kill(processes[0], signal.SIGKILL)
        first.wait()
    check(first.returncode != 0, "the launcher ends within %d s of the "
          "kill of rank 1, with exit status %d (not 0)"
          % (KILLED_JOB_TIMEOUT, first.returncode))
    check(ended(processes[0]), "rank 0 ends")
    next_run_after_kill(membranes, scene, outdir)


def same_reports(a, b, what):
    """report.csv of the directories a and b agree to the last digit, in
    every column but the times and the memory."""
    rows_a, rows_b = report_rows(a), report_rows(b)
    columns = [c for c in (rows_a[0] if rows_a else [])
               if not c.endswith("_s") and c != "memory_mb"]
    differing = sorted({c for ra, rb in zip(rows_a, rows_b)
                        for c in columns if ra[c] != rb.get(c)})
    check(len(rows_a) == len(rows_b) > 0 and not differing,
          "%s: the same report.csv, %d rows (differing columns: %s)"
          % (what, len(rows_a), differing))


def settings(path):
    """The entries of the parameter file path: Subsection/Entry -> value."""
    found, subsections = {}, []
    with open(path) as f:
        for line in f:
            statement = line.split("#")[0].strip()
            if statement.startswith("subsection "):
                subsections.append(statement[len("subsection "):].strip())
            elif statement == "end":
                subsections.pop()
            elif statement.startswith("set "):
                entry, value = statement[len("set "):].split("=", 1)
                found["/".join(subsections + [entry.strip()])] = value.strip()
    return found


def reproduce(membranes, scenes, workdir, launcher):
    original = os.path.join(workdir, "reproduce-original")
    again = os.path.join(workdir, "reproduce-again")
    # The scene names its mesh file relative to itself; the run starts
    # elsewhere, with settings on the command line.
    first = run([membranes, "--set", "Output/Directory=" + original,
                 "--set", "Refinement/Cycles=3", "--set", "Problem/mu2=3",
                 "--set", "Output/Write vtu=false",
                 os.path.join(scenes, "case-m-gmsh-triangles.prm")],
                cwd=workdir)
    check(first.returncode == 0, "the run completes")
    recorded = os.path.join(original, "parameters.prm")
    with open(os.path.join(original, "run-info.txt")) as f:
        info = f.read()
    check("version: " in info and "Problem/mu2=3" in info,
          "run-info.txt has the version and the command line")

    second = run([membranes, "--set", "Output/Directory=" + again, recorded],
                 cwd=os.path.join(scenes, ".."))
    check(second.returncode == 0 and not second.stderr,
          "parameters.prm with another Output/Directory runs: %r"
          % second.stderr)
    same_reports(original, again, "another directory")
    a, b = settings(recorded), settings(os.path.join(again, "parameters.prm"))
    differing = sorted(e for e in a.keys() | b.keys() if a.get(e) != b.get(e))
    check(len(a) > 30 and differing == ["Output/Directory"],
          "its parameters.prm sets the same %d entries, but Output/Directory"
          " (differing: %s)" % (len(a), differing))

    kept = os.path.join(workdir, "reproduce-first-report")
    os.makedirs(kept)
    shutil.copy(os.path.join(original, "report.csv"), kept)
    third = run([membranes, recorded], cwd=again)
    check(third.returncode == 0 and not third.stderr,
          "parameters.prm runs in its own directory: %r" % third.stderr)
    same_reports(kept, original, "its own directory")


CASES = {"race": race, "rerun": rerun, "kill": kill, "kill_mpi": kill_mpi,
         "reproduce": reproduce}


def main():
    if len(sys.argv) < 5 or sys.argv[1] not in CASES:
        sys.exit("usage: output_directory.py %s MEMBRANES SCENES WORKDIR "
                 "[MPI_LAUNCHER]" % "|".join(CASES))
    case, membranes, scenes, workdir = sys.argv[1:5]
    launcher = sys.argv[5] if len(sys.argv) > 5 else ""
    workdir = os.path.join(workdir, case)
    shutil.rmtree(workdir, ignore_errors=True)
    os.makedirs(workdir)
    CASES[case](membranes, scenes, workdir, launcher)
    print("%s: %d failed" % (case, len(failures)))
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
