#!/usr/bin/env python3
"""Hostile input: ``hostile_input.py MEMBRANES SOURCE_DIR WORKDIR FAMILY...``.

Feeds the program hundreds of generated malformed scenes, mesh files, output
directories and command lines, and checks every run:

- it ends within a time limit (no hang) and not by a signal (no crash);
- an error is exit status 1 with exactly one line on stderr,
  ``membranes: error: ...``, that contains the words the case names (the
  parameter as ``Subsection/Entry``, or the line of the scene);
- a success (only where the case allows one, e.g. a scene truncated at a
  line boundary) is exit status 0 with nothing on stderr and complete
  output files;
- no partially written file is left: no ``*.tmp``, every report.csv has a
  full header and full rows, every VTU and .pvd file is closed; and a scene
  that is rejected leaves no output directory at all (only cases that
  prepare the directory themselves may leave it, with nothing partial in it).

The cases are generated deterministically (fixed offsets and seeds) from the
scenes and meshes shipped in ``parameters/``. FAMILY selects groups of cases
(see FAMILIES below), so that ctest can run them as separate tests. Prints
one PASS/FAIL line per case and exits 1 on any failure.
"""
import concurrent.futures
import csv
import glob
import os
import random
import re
import shutil
import subprocess
import sys

# Seconds per case: every case runs one or two tiny meshes. A checking
# build (sanitizers, Debug) is many times slower and sets a longer limit
# with the environment variable HOSTILE_INPUT_TIMEOUT.
TIMEOUT = float(os.environ.get("HOSTILE_INPUT_TIMEOUT", "20"))
# The first columns of every report (the errors and effectivities follow
# only where the scene computes them).
REPORT_COLUMNS = ["cycle", "cells", "dofs", "active_set_iterations",
                  "active_vertices", "wall_time_s", "cumulative_wall_time_s"]

# Whether a case must fail, must succeed, or may do either (the program
# decides; either way no crash, no hang, no partial file).
FAIL, SUCCEED, EITHER = "fail", "succeed", "either"


class Case:
    """One run of the program.

    scene: text (str or bytes) of scene.prm, or None for none.
    settings: ``Subsection/Entry=value`` given with --set after the scene's
        own (the output directory and a single cycle unless overridden).
    argv: the whole command line after the program name, instead of the
        settings and the scene (for command-line cases); ``{scene}`` and
        ``{dir}`` in it are replaced by the scene file and the case directory.
    files: name -> bytes, written into the case directory.
    words: what the error line must contain.
    prepare: called with the case directory before the run.
    keeps_directory: the case makes its output directory itself.
    late: the error may come after the first cycle has started (data that
        fail only on a later mesh, files that cannot be written); every
        other error must come before it: no line ``Cycle `` on stdout.
    """

    def __init__(self, name, scene="", expect=FAIL, words=(), settings=None,
                 argv=None, files=None, prepare=None, keeps_directory=False,
                 late=False):
        self.name = name
        self.scene = scene
        self.expect = expect
        self.words = list(words)
        self.settings = {"Refinement/Cycles": "1",
                         "Output/Write vtu": "false"}
        self.settings.update(settings or {})
        self.argv = argv
        self.files = files or {}
        self.prepare = prepare
        self.keeps_directory = keeps_directory
        self.late = late


def section(name, **entries):
    """A scene subsection with the given entries (underscores for blanks)."""
    lines = ["subsection %s" % name]
    lines += ["  set %s = %s" % (k.replace("_", " "), v)
              for k, v in entries.items()]
    return "\n".join(lines + ["end", ""])


# ---------------------------------------------------------------------------
# Truncated scenes and meshes

def structure_at_end(text):
    """(subsections still open at the end of the text, number and statement
    of the last line, unless it is complete)."""
    path = []
    lines = text.split("\n")
    for line in lines:
        statement = line.split("#")[0].strip()
        if statement.startswith("subsection "):
            path.append(statement[len("subsection "):].strip())
        elif statement == "end" and path:
            path.pop()
    last = lines[-1].split("#")[0].strip()
    return path, len(lines), "" if last == "end" else last


def truncated_scenes(source):
    """Every shipped scene cut at 4 evenly spaced byte offsets and after 2
    of its 'end' lines. A cut inside a subsection must give an error naming
    the subsection; a cut at top level in the middle of a statement one
    naming its line; a cut between statements leaves a valid scene that
    must run cleanly (or fail cleanly, e.g. an incomplete exact solution)."""
    cases = []
    for scene in sorted(glob.glob(os.path.join(source, "parameters",
                                               "*.prm"))):
        data = open(scene, "rb").read()
        offsets = {len(data) * k // 5 for k in range(1, 5)}
        ends = [match.end() for match in re.finditer(rb"\nend\n", data)]
        offsets.update(ends[:2])
        for offset in sorted(offsets):
            text = data[:offset].decode("utf-8", "replace")
            path, line, unfinished = structure_at_end(text)
            if path:
                expect, words = FAIL, [path[-1]]
            elif unfinished:
                expect, words = FAIL, ["line %d" % line]
            else:
                expect, words = EITHER, []
            cases.append(Case("%s cut at byte %d" % (os.path.basename(scene),
                                                     offset),
                              scene=data[:offset], expect=expect, words=words,
                              settings={"Output/Write vtu": "true"}))
    return cases


def mesh_scene(mesh, cell_type="triangle"):
    return section("Geometry", Domain="file", Mesh_file=mesh,
                   Cell_type=cell_type, Initial_refinement="1")


def bad_mesh(name, content, cell_type="triangle", expect=FAIL,
             words=("Geometry/Mesh file",)):
    return Case(name, scene=mesh_scene("mesh.msh", cell_type), expect=expect,
                words=words, files={"mesh.msh": content})


MSH_HEADER = b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
MSH_SQUARE_NODES = (b"$Nodes\n4\n1 -1 -1 0\n2 1 -1 0\n3 1 1 0\n4 -1 1 0\n"
                    b"$EndNodes\n")


def msh_two_triangles(first):
    """The square as two triangles, the first with the given nodes."""
    return (MSH_HEADER + MSH_SQUARE_NODES + b"$Elements\n2\n1 2 2 0 1 " +
            first.encode() + b"\n2 2 2 0 1 1 3 4\n$EndElements\n")


def msh_quadrilateral(nodes):
    """The square as one quadrilateral with the given nodes."""
    return (MSH_HEADER + MSH_SQUARE_NODES + b"$Elements\n1\n1 3 2 0 1 " +
            nodes.encode() + b"\n$EndElements\n")


def meshes(source):
    """Garbage, truncated and geometrically invalid Gmsh files."""
    rng = random.Random(20240521)
    cases = [bad_mesh("empty mesh file", b""),
             Case("mesh file is a directory", scene=mesh_scene("meshdir"),
                  words=["Geometry/Mesh file"],
                  prepare=lambda d: os.mkdir(os.path.join(d, "meshdir"))),
             Case("mesh file is /dev/zero", scene=mesh_scene("/dev/zero"),
                  words=["Geometry/Mesh file"]),
             Case("mesh file is /dev/null", scene=mesh_scene("/dev/null"),
                  words=["Geometry/Mesh file"])]
    for size in (64, 4096):
        cases.append(bad_mesh("random mesh file of %d bytes" % size,
                              bytes(rng.randrange(256) for _ in range(size))))
    cases.append(bad_mesh("random text after a valid header", MSH_HEADER +
                          bytes(rng.choice(b"0123456789 -.\n$")
                                for _ in range(2000))))
    for name in ("square-triangles.msh", "square-quadrilaterals.msh"):
        data = open(os.path.join(source, "parameters", "meshes", name),
                    "rb").read()
        cell_type = "triangle" if "triangles" in name else "quadrilateral"
        for k in range(1, 5):
            offset = len(data) * k // 5
            cases.append(bad_mesh("%s cut at byte %d" % (name, offset),
                                  data[:offset], cell_type))
    cases += [
        # Gmsh writes the cells of a surface whose normal points down
        # clockwise: GridIn turns them, and the run goes on.
        bad_mesh("clockwise triangle", msh_two_triangles("1 3 2"),
                 expect=SUCCEED),
        bad_mesh("degenerate triangle (three collinear vertices)",
                 msh_two_triangles("1 2 2")),
        bad_mesh("clockwise quadrilateral", msh_quadrilateral("1 4 3 2"),
                 "quadrilateral", expect=SUCCEED),
        bad_mesh("one clockwise triangle among counterclockwise ones",
                 msh_two_triangles("1 2 3").replace(b"1 3 4", b"1 4 3"),
                 expect=SUCCEED),
        bad_mesh("nearly flat triangle (valid)",
                 msh_two_triangles("1 2 3").replace(b"3 1 1 0",
                                                    b"3 1 -0.999999 0"),
                 expect=EITHER),
        bad_mesh("node count 1e8 in a small file",
                 MSH_HEADER + b"$Nodes\n100000000\n1 0 0 0\n"),
        bad_mesh("self-intersecting quadrilateral",
                 msh_quadrilateral("1 3 2 4"), "quadrilateral"),
        bad_mesh("element refers to a missing node",
                 msh_two_triangles("1 2 99")),
        bad_mesh("node count 4e9",
                 MSH_HEADER + b"$Nodes\n4000000000\n1 0 0 0\n"),
        bad_mesh("negative node count",
                 MSH_HEADER + b"$Nodes\n-4\n1 0 0 0\n$EndNodes\n"),
        bad_mesh("element count 4e9", msh_two_triangles("1 2 3").replace(
            b"$Elements\n2\n", b"$Elements\n4000000000\n")),
        bad_mesh("nan coordinates",
                 msh_two_triangles("1 2 3").replace(b"3 1 1 0", b"3 nan nan 0")),
        bad_mesh("coordinate 1e300",
                 msh_two_triangles("1 2 3").replace(b"3 1 1 0", b"3 1e300 1 0")),
        bad_mesh("unknown element type",
                 msh_two_triangles("1 2 3").replace(b"1 2 2 0 1",
                                                    b"1 99 2 0 1")),
        bad_mesh("only line elements",
                 MSH_HEADER + MSH_SQUARE_NODES +
                 b"$Elements\n1\n1 1 2 0 1 1 2\n$EndElements\n"),
        bad_mesh("binary flag on a text file",
                 msh_two_triangles("1 2 3").replace(b"2.2 0 8", b"2.2 1 8"),
                 expect=EITHER),
        bad_mesh("missing $EndNodes",
                 msh_two_triangles("1 2 3").replace(b"$EndNodes\n", b"")),
        Case("relative mesh file missing", scene=mesh_scene("no-mesh.msh"),
             words=["Geometry/Mesh file"]),
        Case("Domain = file without a mesh file",
             scene=section("Geometry", Domain="file"),
             words=["Geometry/Mesh file"]),
    ]
    return cases


# ---------------------------------------------------------------------------
# Values: wrong types, huge and tiny numbers, absurd limits

TYPED_ENTRIES = [
    "Geometry/Domain", "Geometry/Cell type", "Geometry/Initial refinement",
    "Problem/mu1", "Problem/mu2", "Exact solution/Known", "Solver/Method",
    "Solver/Linear solver", "Solver/Tolerance",
    "Solver/Max active set iterations", "Solver/Stopping",
    "Solver/Balance fraction", "Refinement/Strategy",
    "Refinement/Cycles", "Refinement/Marking", "Refinement/Bulk parameter",
    "Refinement/Refinement fraction", "Refinement/Coarsen fraction",
    "Refinement/Max dofs",
    "Refinement/Estimator", "Output/Report", "Output/Write vtu",
    "Output/Flux reconstruction"]

# Numbers for the numeric entries, and for each entry those that are valid
# (tensions in [1e-50, 1e50] with a ratio of at most 1e12; the others as
# their patterns say).
NUMBERS = ["1e308", "1e-308", "-0", "1e400", "nan", "2.5"]
NUMERIC_ENTRIES = {
    "Problem/mu1": {"2.5"},
    "Solver/Tolerance": set(),
    "Solver/Balance fraction": set(),
    "Refinement/Bulk parameter": set(),
    "Refinement/Refinement fraction": set(),
    "Geometry/Initial refinement": {"-0"},
    "Refinement/Cycles": set(),
}


def scene_with(entry, value):
    """A scene that sets one entry (and Known = true for an exact
    solution, Marking = fixed number for its share, so that it is used)."""
    subsection, name = entry.split("/")
    entries = {name.replace(" ", "_"): value}
    if subsection == "Exact solution" and name != "Known":
        entries["Known"] = "true"
    if name == "Refinement fraction":
        entries["Marking"] = "fixed number"
    return section(subsection, **entries)


def values():
    cases = []
    for entry in TYPED_ENTRIES:
        cases.append(Case("%s = banana" % entry,
                          scene=scene_with(entry, "banana"), words=[entry]))
    for entry in ("Problem/mu2", "Refinement/Cycles"):
        cases.append(Case("%s empty" % entry, scene=scene_with(entry, ""),
                          words=[entry]))
    for entry, valid in NUMERIC_ENTRIES.items():
        for value in NUMBERS:
            expect = SUCCEED if value in valid else FAIL
            settings = {}
            if entry == "Refinement/Cycles":
                settings = {"Refinement/Cycles": value}
            cases.append(Case("%s = %s" % (entry, value),
                              scene=scene_with(entry, value), expect=expect,
                              words=[entry] if expect == FAIL else [],
                              settings=settings))
    for constants in ("R=nan", "R=1e400", "=1", "x=1", "R=1, 2"):
        cases.append(Case("Function constants '%s'" % constants,
                          scene=section("Problem",
                                        Function_constants=constants),
                          words=["Problem/Function constants"]))
    cases += [Case(name, scene=scene, words=words)
              for name, scene, words in SCENE_ERRORS]
    cases += [Case(name, scene=scene, expect=SUCCEED, settings=settings)
              for name, scene, settings in VALID_SCENES]
    cases += [
        # deal.II's parser follows includes without a limit: a cycle would
        # recurse until the stack overflows.
        Case("a scene that includes itself", scene="include scene.prm\n",
             words=["scene.prm, line 1", "include cycle"]),
        Case("an include cycle through a second file",
             scene="include other.prm\n",
             files={"other.prm": b"subsection Problem\nend\ninclude scene.prm\n"},
             words=["other.prm, line 3", "include cycle"]),
        Case("a 100 kB value", scene=section("Problem", f1="1" + "+1" * 50000),
             expect=EITHER, words=["Problem/f1"]),
        Case("Windows line ends",
             scene=section("Problem", mu1="2").replace("\n", "\r\n"),
             expect=EITHER, words=["Problem"]),
        Case("byte order mark", scene=b"\xef\xbb\xbf" +
             section("Problem", mu1="2").encode(),
             expect=EITHER, words=["line 1"]),
    ]
    return cases


# (name, scene, words the message must contain)
SCENE_ERRORS = [
    ("Bulk parameter + Coarsen fraction = 1.5",
     section("Refinement", Strategy="adaptive", Bulk_parameter="1",
             Coarsen_fraction="0.5"),
     ["Refinement/Coarsen fraction", "Bulk parameter"]),
    ("Refinement fraction + Coarsen fraction = 1.5",
     section("Refinement", Strategy="adaptive", Marking="fixed number",
             Refinement_fraction="1", Coarsen_fraction="0.5"),
     ["Refinement/Coarsen fraction", "Refinement fraction"]),
    ("Marking = fixed fraction (the former name of fixed number)",
     section("Refinement", Strategy="adaptive", Marking="fixed fraction"),
     ["Refinement/Marking", "'fixed number'", "'bulk'"]),
    ("Max dofs = -1", section("Refinement", Max_dofs="-1"),
     ["Refinement/Max dofs"]),
    ("Max dofs = 2.5", section("Refinement", Max_dofs="2.5"),
     ["Refinement/Max dofs"]),
    ("Max dofs = 1e30", section("Refinement", Max_dofs="1e30"),
     ["Refinement/Max dofs"]),
    ("Max dofs = 2147483648", section("Refinement", Max_dofs="2147483648"),
     ["Refinement/Max dofs"]),
    ("Max dofs below the first mesh", section("Refinement", Max_dofs="10"),
     ["Refinement/Max dofs"]),
    ("mu2 = 1e308", section("Problem", mu2="1e308"), ["Problem/mu2"]),
    ("mu2 = 3e-308", section("Problem", mu2="3e-308"), ["Problem/mu2"]),
    ("mu1 = mu2 = 1e60", section("Problem", mu1="1e60", mu2="1e60"),
     ["Problem/mu1"]),
    ("tension ratio 1e16", section("Problem", mu1="1e16"), ["Problem/mu1"]),
    ("tension ratio 1e-16", section("Problem", mu2="1e16"), ["Problem/mu2"]),
    ("Initial refinement = 20 (10^12 cells)",
     section("Geometry", Initial_refinement="20"),
     ["Geometry/Initial refinement"]),
    ("Initial refinement = 14 on the disk",
     section("Geometry", Domain="disk", Initial_refinement="14"),
     ["Geometry/Initial refinement"]),
    ("unknown subsection", section("Physics", mu1="1"),
     ["Physics", "Geometry"]),
    ("unknown nested subsection",
     "subsection Problem\n  subsection Loads\n  end\nend\n",
     ["Problem/Loads"]),
    ("unknown entry", section("Problem", mu3="1"), ["Problem/mu3", "mu1"]),
    ("entry at top level", "set mu1 = 1\n", ["mu1"]),
    ("entry in the wrong subsection", section("Geometry", mu1="1"),
     ["Geometry/mu1"]),
    ("set without '='", "subsection Problem\n  set mu1\nend\n",
     ["Problem", "line 2"]),
    ("extra 'end'", section("Problem", mu1="1") + "end\n", ["line 4"]),
    ("missing 'end'", "subsection Solver\n  set Tolerance = 1e-8\n",
     ["Solver"]),
    ("garbage line", "subsection Problem\n  mu1 := 2\nend\n",
     ["Problem", "line 2"]),
    ("include of a missing file", "include nothing-here.prm\n",
     ["nothing-here.prm"]),
    # deal.II does not check a value with '{' against its pattern.
    ("Domain = {square|disk}", section("Geometry", Domain="{square|disk}"),
     ["Geometry/Domain", "square|lshape|slit|disk|file"]),
    ("binary scene",
     bytes(random.Random(7).randrange(256) for _ in range(300)), ["line"]),
    ("NUL bytes in a scene",
     b"subsection Problem\n  set mu1 = 1\x00\x002\nend\n", ["Problem/mu1"]),
    ("Function constants 'R=1e308' used squared",
     section("Problem", Function_constants="R=1e308", f1="R^2"),
     ["Problem/f1"]),
]

# (name, scene, settings): valid, if unusual, scenes that must run cleanly.
VALID_SCENES = [
    ("Method = decoupled", section("Solver", Method="decoupled"), {}),
    ("Flux reconstruction and flux estimator",
     section("Output", Flux_reconstruction="true") +
     section("Refinement", Estimator="flux"), {}),
    ("flux estimator without the flux reconstruction output",
     section("Refinement", Estimator="flux"), {}),
    ("Max dofs = 0 (no limit)", section("Refinement", Max_dofs="0"), {}),
    ("Max dofs = 100000", section("Refinement", Max_dofs="100000"), {}),
    ("tension ratio 1e12",
     section("Problem", mu1="1e12", f1="-1", f2="1", g="1"), {}),
    ("tension ratio 1e12, CG and AMG",
     section("Problem", mu2="1e12", f1="-1", f2="1", g="1") +
     section("Solver", Linear_solver="cg-amg"), {}),
    ("tensions 1e-50 and loads 1e50",
     section("Problem", mu1="1e-50", mu2="1e-50", f1="-1e50", f2="1e50",
             g="1"), {}),
    ("tensions 1e50 and loads 1e-50",
     section("Problem", mu1="1e50", mu2="1e50", f1="-1e-50", f2="1e-50",
             g="1e-50"), {}),
    ("Bulk parameter 3e-308, adaptive",
     section("Refinement", Strategy="adaptive", Bulk_parameter="3e-308"),
     {"Refinement/Cycles": "2"}),
    ("a 1 MB comment line", "# " + "x" * 1000000 + "\n", {}),
    ("empty scene (all defaults)", "", {}),
]


# ---------------------------------------------------------------------------
# Expressions: NaN, inf, division by zero, bad boundary data

EXPRESSION_ENTRIES = ["Problem/f1", "Problem/f2", "Problem/g", "Problem/g2",
                      "Exact solution/u1", "Exact solution/u2",
                      "Exact solution/lambda"]
BAD_EXPRESSIONS = ["nan", "1/0", "sqrt(-1)", "log(x)"]


# (entry, expression) beyond the product above.
MORE_EXPRESSIONS = [
    ("Problem/f1", "log(0)"), ("Problem/f1", "inf"), ("Problem/f2", "-1/0"),
    ("Problem/g", "0/0"), ("Exact solution/u1", "1e60"),
    ("Problem/f1", "1e60"), ("Problem/g2", "1e308*10"),
    ("Exact solution/u1", "x^"), ("Exact solution/lambda", "atan2("),
    ("Problem/f2", "y z"),
    # NaN in a strip between the vertices of the mesh.
    ("Problem/f1", "(x > 0.1 && x < 0.2) ? sqrt(-1) : 0"),
    ("Exact solution/u2", "(x > 0.1 && x < 0.2) ? sqrt(-1) : 0"),
    # Exact gradients: two expressions separated by ';', each checked.
    ("Exact solution/u1 gradient", "2*x"),
    ("Exact solution/u1 gradient", "x; y; 0"),
    ("Exact solution/u2 gradient", "x; y^"),
    ("Exact solution/u1 gradient", "0/0; 0"),
    ("Exact solution/u2 gradient", "0; log(x)"),
]

# (what, geometry, problem entries, the entry to name): singular data on a
# line of the mesh (the loads are evaluated at quadrature points, e.g. the
# cell midpoints x = +-1/2 of the square refined once; the boundary data at
# boundary vertices), and boundary data with g < 0 or g - g2 < 0.
REFINED_ONCE = section("Geometry", Initial_refinement="1")
DATA_ON_MESHES = [
    ("f1 = 1/(x-0.5) on a quadrature point", REFINED_ONCE,
     {"f1": "1/(x-0.5)"}, "Problem/f1"),
    ("g = 1/(x-0.5) on a boundary vertex", "", {"g": "1/(x-0.5)"},
     "Problem/g"),
    ("g2 = 1/(y-0.25) on a boundary vertex", "",
     {"g": "1", "g2": "1/(y-0.25)"}, "Problem/g2"),
    ("g < 0 on the square", "", {"g": "x - 0.5"}, "Problem/g"),
    ("g < 0 by 1e-12", "", {"g": "-1e-12"}, "Problem/g"),
    ("g < 0 between coarse vertices only", "",
     {"g": "abs(x-0.3) < 0.2 ? -1 : 1"}, "Problem/g"),
    ("g - g2 < 0 on the square", "", {"g": "1", "g2": "1 + y^2"},
     "Problem/g2"),
    ("g - g2 < 0 by 1e-12", "", {"g": "1", "g2": "1 + 1e-12"},
     "Problem/g2"),
    ("g < 0 on the L-shape", section("Geometry", Domain="lshape"),
     {"g": "-x*y"}, "Problem/g"),
    ("g < 0 on the disk", section("Geometry", Domain="disk"),
     {"g": "0.99 - x^2 - y^2"}, "Problem/g"),
    ("g < 0 on the circle but not on the coarse chords",
     section("Geometry", Domain="disk"),
     {"g": "x^2 + y^2 < 0.99 ? 1 : (abs(x) < 0.3 ? -1 : 1)"}, "Problem/g"),
    ("g - g2 < 0 on a mesh file", mesh_scene("meshes/square-triangles.msh"),
     {"g": "0", "g2": "x"}, "Problem/g2"),
]


def expressions():
    cases = [Case("%s = %s" % (entry, expression),
                  scene=scene_with(entry, expression), words=[entry])
             for entry in EXPRESSION_ENTRIES
             for expression in BAD_EXPRESSIONS]
    cases += [Case("%s = %s" % (entry, expression),
                   scene=scene_with(entry, expression), words=[entry])
              for entry, expression in MORE_EXPRESSIONS]
    cases += [Case(name, scene=geometry + section("Problem", **entries),
                   words=[entry])
              for name, geometry, entries, entry in DATA_ON_MESHES]
    cases += [
        Case("f2 = 1/(x+y) on triangles",
             scene=section("Geometry", Initial_refinement="1",
                           Cell_type="triangle") +
             section("Problem", f2="1/(x+y)"), expect=EITHER,
             words=["Problem/f2"]),
        # Cycle 0 runs; the loads are infinite on a quadrature point of
        # cycle 1: the files of cycle 0 stay, complete.
        Case("f1 NaN only on a later mesh",
             scene=REFINED_ONCE + section("Problem", f1="1/(x-0.25)"),
             settings={"Refinement/Cycles": "2"},
             words=["Problem/f1"], keeps_directory=True, late=True),
    ]
    return cases


# ---------------------------------------------------------------------------
# Output directories that cannot be written

def make_file(path, text="x"):
    with open(path, "w") as out:
        out.write(text)


def output():
    def under_file(d):
        make_file(os.path.join(d, "a-file"))

    def existing_file(d):
        make_file(os.path.join(d, "out"))

    def blocked(name):
        def prepare(d):
            os.makedirs(os.path.join(d, "out", name))
        return prepare

    scene = ""
    vtu = {"Output/Write vtu": "true"}
    return [
        Case("Directory under a regular file", scene=scene,
             settings={"Output/Directory": "{dir}/a-file/out"},
             prepare=under_file, words=["Output/Directory"]),
        Case("Directory is a regular file", scene=scene,
             settings={"Output/Directory": "{dir}/out"},
             prepare=existing_file, words=["Output/Directory"],
             keeps_directory=True),
        Case("Directory in /proc", scene=scene,
             settings={"Output/Directory": "/proc/membranes-hostile/out"},
             words=["Output/Directory"]),
        Case("Directory /proc/self (exists, not writable)", scene=scene,
             settings={"Output/Directory": "/proc/self"},
             words=["Output/Directory"], keeps_directory=True),
        Case("Directory /dev/null", scene=scene,
             settings={"Output/Directory": "/dev/null"},
             words=["Output/Directory"], keeps_directory=True),
        Case("Directory name too long", scene=scene,
             settings={"Output/Directory": "{dir}/" + "d" * 300},
             words=["Output/Directory"]),
        Case("Directory empty", scene=scene,
             settings={"Output/Directory": ""}, words=["Output/Directory"]),
        Case("report.csv is a directory", scene=scene,
             prepare=blocked("report.csv"), words=["Output/Directory"],
             keeps_directory=True, late=True),
        Case("solution.pvd is a directory", scene=scene, settings=vtu,
             prepare=blocked("solution.pvd"), words=["Output/Directory"],
             keeps_directory=True, late=True),
        Case("solution-00.vtu is a directory", scene=scene, settings=vtu,
             prepare=blocked("solution-00.vtu"), words=["Output/Directory"],
             keeps_directory=True, late=True),
        Case("report.csv is a directory, no report", scene=scene,
             settings={"Output/Report": "false", "Output/Write vtu": "true"},
             prepare=blocked("report.csv"), expect=SUCCEED,
             keeps_directory=True),
    ]


# ---------------------------------------------------------------------------
# Command lines

def command_line():
    def directory_scene(d):
        os.mkdir(os.path.join(d, "scene-dir.prm"))

    return [
        Case("no argument", argv=[], words=["scene"]),
        Case("unknown option", argv=["--frobnicate", "{scene}"],
             words=["--frobnicate"]),
        Case("lone dash", argv=["-", "{scene}"], words=["'-'"]),
        Case("--set without argument", argv=["{scene}", "--set"],
             words=["--set"]),
        Case("--set without '/'", argv=["--set", "mu1=1", "{scene}"],
             words=["mu1=1"]),
        Case("--set without '='", argv=["--set", "Problem/mu1", "{scene}"],
             words=["Problem/mu1"]),
        Case("--set '=1'", argv=["--set", "=1", "{scene}"], words=["=1"]),
        Case("--set '/=1'", argv=["--set", "/=1", "{scene}"], words=["/=1"]),
        Case("--set 'Problem/=1'", argv=["--set", "Problem/=1", "{scene}"],
             words=["Problem/"]),
        Case("--set unknown subsection",
             argv=["--set", "Nowhere/mu1=1", "{scene}"],
             words=["Nowhere", "Geometry"]),
        Case("--set unknown entry", argv=["--set", "Problem/mu4=1", "{scene}"],
             words=["Problem/mu4", "mu1"]),
        Case("--set nested unknown subsection",
             argv=["--set", "Problem/Loads/f1=1", "{scene}"],
             words=["Problem/Loads"]),
        Case("--set wrong type",
             argv=["--set", "Refinement/Cycles=many", "{scene}"],
             words=["Refinement/Cycles"]),
        Case("--set 1e400", argv=["--set", "Problem/mu1=1e400", "{scene}"],
             words=["Problem/mu1"]),
        Case("--set value with a newline",
             argv=["--set", "Problem/f1=1\n2", "{scene}"],
             words=["Problem/f1"]),
        Case("two scene files", argv=["{scene}", "{scene}"],
             words=["more than one scene"]),
        Case("missing scene file", argv=["{dir}/no-such-scene.prm"],
             words=["no-such-scene.prm"]),
        Case("scene file is a directory", argv=["{dir}/scene-dir.prm"],
             prepare=directory_scene, words=["scene-dir.prm"]),
        Case("scene file without .prm", argv=["/dev/null"],
             words=["/dev/null"]),
        Case("scene file name too long",
             argv=["{dir}/" + "s" * 300 + ".prm"], words=["sss"]),
        Case("empty scene file name", argv=[""], words=["scene"]),
    ]


FAMILIES = {"truncated_scenes": truncated_scenes, "meshes": meshes,
            "values": lambda source: values(),
            "expressions": lambda source: expressions(),
            "output": lambda source: output(),
            "command_line": lambda source: command_line()}


# ---------------------------------------------------------------------------
# Running and checking one case

def complete_report(path, problems):
    try:
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
    except (OSError, UnicodeDecodeError, csv.Error) as error:
        problems.append("report.csv unreadable: %s" % error)
        return
    if not rows or rows[0][:len(REPORT_COLUMNS)] != REPORT_COLUMNS:
        problems.append("report.csv has no complete header")
        return
    if len(rows) < 2:
        problems.append("report.csv has no row")
    for row in rows[1:]:
        if len(row) != len(rows[0]) or not row[0].isdigit():
            problems.append("report.csv has a partial row: %r" % row[:4])


def check_output_directory(outdir, problems):
    """Nothing partial in outdir: no temporary files, complete report and
    VTU/.pvd files."""
    if not os.path.isdir(outdir):
        return
    for name in sorted(os.listdir(outdir)):
        path = os.path.join(outdir, name)
        if not os.path.isfile(path):
            continue
        if name.endswith(".tmp"):
            problems.append("temporary file %s left" % name)
        elif name == "report.csv":
            complete_report(path, problems)
        elif name.endswith(".vtu") or name.endswith(".pvd"):
            with open(path, "rb") as f:
                text = f.read()
            if not text.rstrip().endswith(b"</VTKFile>"):
                problems.append("%s is not complete" % name)


def run_case(membranes, source, workdir, index, case):
    casedir = os.path.join(workdir, "%03d" % index)
    shutil.rmtree(casedir, ignore_errors=True)
    os.makedirs(casedir)
    os.symlink(os.path.join(source, "parameters", "meshes"),
               os.path.join(casedir, "meshes"))
    for name, content in case.files.items():
        with open(os.path.join(casedir, name), "wb") as out:
            out.write(content)
    if case.prepare:
        case.prepare(casedir)
    scene_file = os.path.join(casedir, "scene.prm")
    if case.scene is not None:
        with open(scene_file, "wb") as out:
            out.write(case.scene if isinstance(case.scene, bytes)
                      else case.scene.encode())

    def fill(text):
        return text.replace("{scene}", scene_file).replace("{dir}", casedir)

    settings = dict({"Output/Directory": os.path.join(casedir, "out")},
                    **case.settings)
    outdir = fill(settings["Output/Directory"])
    if case.argv is not None:
        argv = [fill(arg) for arg in case.argv]
    else:
        argv = []
        for entry, value in settings.items():
            argv += ["--set", "%s=%s" % (entry, fill(value))]
        argv.append(scene_file)

    problems = []
    try:
        result = subprocess.run([membranes] + argv, capture_output=True,
                                timeout=TIMEOUT, cwd=casedir)
    except subprocess.TimeoutExpired:
        return False, "%s: no result after %g s (hang)" % (case.name, TIMEOUT)
    try:
        stderr = result.stderr.decode("utf-8")
    except UnicodeDecodeError:
        stderr = result.stderr.decode("utf-8", "replace")
        problems.append("stderr is not UTF-8 text")
    lines = stderr.rstrip("\n").split("\n") if stderr else []
    if result.returncode < 0:
        problems.append("killed by signal %d" % -result.returncode)
    elif result.returncode == 0:
        if case.expect == FAIL:
            problems.append("exit status 0, an error was expected")
        if stderr:
            problems.append("stderr of a successful run: %r" % stderr[:300])
        for name, entry in (("report.csv", "Output/Report"),
                            ("solution.pvd", "Output/Write vtu")):
            if case.settings.get(entry, "true") == "true" and \
               not os.path.isfile(os.path.join(outdir, name)):
                problems.append("no %s" % name)
    else:
        if case.expect == SUCCEED:
            problems.append("exit status %d, success was expected"
                            % result.returncode)
        if result.returncode != 1:
            problems.append("exit status %d, not 1" % result.returncode)
        if len(lines) != 1 or not lines[0].startswith("membranes: error: "):
            problems.append("stderr is not one 'membranes: error:' line: %r"
                            % stderr[:600])
        else:
            missing = [w for w in case.words if w not in lines[0]]
            if missing:
                problems.append("message does not name %s" % missing)
            if not lines[0].isprintable():
                problems.append("the error line is not printable: %r"
                                % lines[0][:300])
        if not case.late and b"Cycle " in result.stdout:
            problems.append("the error came after the first cycle started")
        if os.path.exists(outdir) and not case.keeps_directory:
            problems.append("output directory %s was created" % outdir)
    check_output_directory(outdir, problems)
    verdict = "; ".join(problems) if problems else (
        lines[0] if lines else "exit status 0")
    return not problems, "%s: %s" % (case.name, verdict)


def main():
    membranes, source, workdir = sys.argv[1:4]
    families = sys.argv[4:] or sorted(FAMILIES)
    cases = [case for family in families for case in FAMILIES[family](source)]
    workdir = os.path.join(workdir, "-".join(families))
    shutil.rmtree(workdir, ignore_errors=True)
    os.makedirs(workdir)
    # Each run waits for the MPI start-up most of its time: four at once
    # keep two cores busy.
    with concurrent.futures.ThreadPoolExecutor(max_workers=4) as pool:
        results = list(pool.map(
            lambda ic: run_case(membranes, source, workdir, *ic),
            enumerate(cases)))
    for ok, text in results:
        print("%s %s" % ("PASS" if ok else "FAIL", text))
    failed = [text for ok, text in results if not ok]
    print("%d cases: %d passed, %d failed" % (len(results),
                                              len(results) - len(failed),
                                              len(failed)))
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
