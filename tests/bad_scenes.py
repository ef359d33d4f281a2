#!/usr/bin/env python3
"""Bad scenes and bad command lines::

    bad_scenes.py membranes WORKDIR [MPI_LAUNCHER]

Every case must end with a non-zero exit status, exactly one line on stderr
that starts with ``membranes: error:`` and names the offending parameter, and
no output directory. With MPI_LAUNCHER (e.g. 'mpiexec -n', completed by
the number of processes), the cases of MPI_CASES run on two processes as
well (only the program's own lines of stderr count there: the launcher adds
its report of the exit status).
A few good command lines (--help, --print-parameters) are checked as well.
Prints one PASS/FAIL line per case, exits 1 on any failure.
"""
import os
import shutil
import subprocess
import sys

# (name, scene text, command-line extras, words the message must contain)
CASES = [
    ("unknown entry",
     "subsection Problem\n  set mu3 = 1\nend\n", [], ["mu3"]),
    ("unknown subsection",
     "subsection Physics\n  set mu1 = 1\nend\n", [], ["Physics"]),
    ("wrong type",
     "subsection Problem\n  set mu1 = soft\nend\n", [], ["mu1"]),
    ("mu1 = 0",
     "subsection Problem\n  set mu1 = 0\nend\n", [], ["Problem/mu1"]),
    ("mu2 < 0",
     "subsection Problem\n  set mu2 = -1\nend\n", [], ["Problem/mu2"]),
    ("g < 0 on the boundary",
     "subsection Problem\n  set g = x - 0.5\nend\n", [], ["Problem/g"]),
    ("g - g2 < 0 on the boundary",
     "subsection Problem\n  set g = 1\n  set g2 = 1 + y^2\nend\n", [],
     ["Problem/g2"]),
    ("expression that does not parse",
     "subsection Problem\n  set f1 = 2*(x+\nend\n", [], ["Problem/f1"]),
    ("unknown name in an expression",
     "subsection Problem\n  set f2 = z\nend\n", [], ["Problem/f2"]),
    ("exact solution that does not parse",
     "subsection Exact solution\n  set Known = true\n  set lambda = )\nend\n",
     [], ["Exact solution/lambda"]),
    ("exact gradient with one expression",
     "subsection Exact solution\n  set Known = true\n"
     "  set u1 gradient = 2*x\nend\n", [], ["Exact solution/u1 gradient"]),
    ("misspelled error norm",
     "subsection Exact solution\n  set Known = true\n"
     "  set Norms = err_u1_H1, err_lambda_H-1\nend\n", [],
     ["Exact solution/Norms", "err_lambda_H-1", "err_lambda_Hm1",
      "err_lambda_L2_omega_h"]),
    ("manufactured data with f1 set",
     "subsection Problem\n  set f1 = 1\nend\n"
     "subsection Exact solution\n  set Manufactured data = true\nend\n", [],
     ["Problem/f1", "Manufactured data"]),
    ("manufactured data with g2 set",
     "subsection Problem\n  set g2 = -1\nend\n"
     "subsection Exact solution\n  set Manufactured data = true\nend\n", [],
     ["Problem/g2", "Manufactured data"]),
    ("manufactured data with the parser",
     "subsection Problem\n  set Expression evaluation = parser\nend\n"
     "subsection Exact solution\n  set Manufactured data = true\nend\n", [],
     ["Exact solution/Manufactured data", "parser"]),
    ("unknown expression evaluation",
     "subsection Problem\n  set Expression evaluation = jit\nend\n", [],
     ["Problem/Expression evaluation", "auto", "compiled", "parser"]),
    ("gradient entry that is not the derivative",
     "subsection Exact solution\n  set Known = true\n  set u1 = x^2\n"
     "  set u1 gradient = x; 0\nend\n", [],
     ["Exact solution/u1 gradient", "derivative"]),
    ("bad function constants",
     "subsection Problem\n  set Function constants = R:0.5\nend\n", [],
     ["Problem/Function constants"]),
    ("missing mesh file",
     "subsection Geometry\n  set Domain = file\n"
     "  set Mesh file = does-not-exist.msh\nend\n", [], ["Geometry/Mesh file"]),
    ("garbage mesh file",
     "subsection Geometry\n  set Domain = file\n"
     "  set Mesh file = garbage.msh\nend\n", [], ["Geometry/Mesh file"]),
    ("triangle mesh file with Cell type = quadrilateral",
     "subsection Geometry\n  set Domain = file\n"
     "  set Mesh file = %s\nend\n" % os.path.join(
         os.path.dirname(os.path.abspath(__file__)), "..", "parameters",
         "meshes", "square-triangles.msh"), [], ["Geometry/Cell type"]),
    ("unknown domain",
     "subsection Geometry\n  set Domain = torus\nend\n", [], ["Domain"]),
    ("coarsening triangles",
     "subsection Geometry\n  set Cell type = triangle\nend\n"
     "subsection Refinement\n  set Strategy = adaptive\n"
     "  set Coarsen fraction = 0.1\nend\n", [],
     ["Refinement/Coarsen fraction"]),
    ("Bulk parameter = 0",
     "subsection Refinement\n  set Bulk parameter = 0\nend\n", [],
     ["Refinement/Bulk parameter"]),
    # The former name of fixed number, deal.II's name of the bulk criterion:
    # refused with both of what to write instead.
    ("Marking = fixed fraction",
     "subsection Refinement\n  set Marking = fixed fraction\nend\n", [],
     ["Refinement/Marking", "'fixed number'", "'Refinement fraction'",
      "'bulk'", "'Bulk parameter'"]),
    ("Marking = fixed fraction by --set",
     "", ["--set", "Refinement/Marking=fixed fraction"],
     ["Refinement/Marking", "'fixed number'", "'bulk'"]),
    ("Refinement fraction = 0",
     "subsection Refinement\n  set Marking = fixed number\n"
     "  set Refinement fraction = 0\nend\n", [],
     ["Refinement/Refinement fraction"]),
    # The share of the other marking: the scene meant that marking.
    ("Bulk parameter with Marking = fixed number",
     "subsection Refinement\n  set Marking = fixed number\n"
     "  set Bulk parameter = 0.3\nend\n", [],
     ["Refinement/Bulk parameter", "Refinement fraction"]),
    ("Refinement fraction with Marking = bulk",
     "subsection Refinement\n  set Refinement fraction = 0.3\nend\n", [],
     ["Refinement/Refinement fraction", "Bulk parameter"]),
    ("Minimum growth below 1",
     "subsection Refinement\n  set Minimum growth = 0.5\nend\n", [],
     ["Refinement/Minimum growth"]),
    ("Target estimator negative",
     "", ["--set", "Refinement/Target estimator=-1"],
     ["Refinement/Target estimator"]),
    ("Balance fraction = 1",
     "subsection Solver\n  set Stopping = balanced\n"
     "  set Balance fraction = 1\nend\n", [], ["Solver/Balance fraction"]),
    ("Balance fraction = 0",
     "subsection Solver\n  set Balance fraction = 0\nend\n", [],
     ["Solver/Balance fraction"]),
    ("unknown Stopping",
     "subsection Solver\n  set Stopping = early\nend\n", [], ["Stopping"]),
    ("Max dofs below the first mesh",
     "subsection Refinement\n  set Max dofs = 10\nend\n", [],
     ["Refinement/Max dofs"]),
    ("bad --set entry",
     "", ["--set", "Problem/mu4=1"], ["mu4"]),
    ("bad --set value",
     "", ["--set", "Refinement/Cycles=many"], ["Cycles"]),
    ("missing scene file",
     None, [], ["no-such-scene.prm"]),
]

# Cases run on two processes as well: the refusals of mesh files and of
# triangle scenes, which every process reaches with its own copy of the
# mesh and must end alike (one line, from the first process).
MPI_CASES = [case for case in CASES if case[0] in (
    "garbage mesh file", "triangle mesh file with Cell type = quadrilateral",
    "coarsening triangles")]


def run(command):
    return subprocess.run(command, capture_output=True, text=True, timeout=60)


def check_case(membranes, workdir, name, scene, extra, words, launcher=()):
    outdir = os.path.join(workdir, "output")
    shutil.rmtree(outdir, ignore_errors=True)
    if scene is None:
        scene_file = os.path.join(workdir, "no-such-scene.prm")
    else:
        scene_file = os.path.join(workdir, "scene.prm")
        with open(scene_file, "w") as out:
            out.write(scene + "subsection Output\n  set Directory = %s\nend\n"
                      % outdir)
    result = run(list(launcher) + [membranes] + extra + [scene_file])
    lines = [line for line in result.stderr.strip().splitlines()
             if not launcher or line.startswith("membranes")]
    problems = []
    if result.returncode == 0:
        problems.append("exit status 0")
    if len(lines) != 1 or not lines[0].startswith("membranes: error: "):
        problems.append("stderr is not one 'membranes: error:' line: %r"
                        % result.stderr)
    elif not all(word in lines[0] for word in words):
        problems.append("message does not name %s" % words)
    if os.path.exists(outdir):
        problems.append("output directory was created")
    print("%s %s: %s" % ("FAIL" if problems else "PASS", name,
                         "; ".join(problems) if problems else lines[0]))
    return not problems


def check_good_command_lines(membranes):
    ok = True
    help_run = run([membranes, "--help"])
    ok &= help_run.returncode == 0 and "Usage" in help_run.stdout
    printed = run([membranes, "--print-parameters"])
    names = ["Domain", "Mesh file", "Cell type", "Initial refinement", "mu1",
             "mu2", "Function constants", "f1", "f2", "g", "g2", "Known",
             "Expression evaluation", "lambda", "u1 gradient", "u2 gradient",
             "Manufactured data", "Method",
             "Linear solver", "Tolerance", "Max active set iterations",
             "Stopping", "Balance fraction",
             "Strategy", "Cycles", "Marking",
             "Bulk parameter", "Refinement fraction", "Coarsen fraction",
             "Minimum growth",
             "Max dofs", "Estimator", "Target estimator", "Directory",
             "Report",
             "Write vtu", "Write nodal values", "Flux reconstruction"]
    missing = [n for n in names if "set %s " % n not in printed.stdout]
    ok &= printed.returncode == 0 and not missing
    print("%s --help and --print-parameters%s" %
          ("PASS" if ok else "FAIL",
           "" if not missing else ": missing " + ", ".join(missing)))
    return ok


def main():
    membranes, workdir = sys.argv[1], sys.argv[2]
    os.makedirs(workdir, exist_ok=True)
    with open(os.path.join(workdir, "garbage.msh"), "w") as out:
        out.write("$MeshFormat\nthis is not a mesh\n")
    results = [check_case(membranes, workdir, *case) for case in CASES]
    if len(sys.argv) > 3:
        launcher = sys.argv[3].split() + ["2"]
        results += [check_case(membranes, workdir, *case, launcher=launcher)
                    for case in MPI_CASES]
    results.append(check_good_command_lines(membranes))
    print("%d passed, %d failed" % (results.count(True), results.count(False)))
    sys.exit(0 if all(results) else 1)


if __name__ == "__main__":
    main()
