#!/usr/bin/env python3
"""The figures of doc/tutorial.md that show meshes and fields.

Usage::

    /usr/bin/python3 doc/make_figures.py [path/to/membranes] [output-dir]

Defaults: build/membranes of this repository and /tmp/membranes-figures.
Draws the picture of the problem from the exact solution of case M, then
runs small scenes with VTU output and draws from the VTU files the
program writes (deal.II's zlib-compressed base64 format, read here without
VTK):

* ``membranes.png``: the two membranes of case M along the line y = 0, the
  contact zone and the action lambda there (no run of the program);
* ``dual-mesh.png``: case M on P1 (one global refinement) and on Q1 (two),
  the flux reconstruction on: the primal mesh, the outlines of the dual
  cells D_a about the interior vertices a, whose union is omega_h, one D_a
  filled, and the strip omega minus omega_h where lambda_h = 0, as Fig. 1
  of the paper;
* ``active-set-iterations.png``: case M on one P1 mesh (five global
  refinements), from u_h = 0: the active set of each active set iteration,
  the vertices the next iteration releases, the vertices the first solve
  penetrates, and the exact contact circle r = 1/2; iteration k is the
  run stopped by 'Solver/Max active set iterations = k';
* ``case-m-fields.png``: case M on Q1, 5 cycles: u1, u2, u1 − u2, λ_h (the
  nodal λ_a) and the active set, with the exact contact circle r = 1/2;
* ``slit-adaptive-mesh.png``: the slit scene, 12 adaptive cycles: the mesh
  refined towards the crack tip, with the slit and the contact disk.

The commands behind each figure are printed. Requires matplotlib.
"""

import base64
import csv
import math
import os
import re
import struct
import subprocess
import sys
import zlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import (LineCollection,  # noqa: E402
                                    PolyCollection)
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from matplotlib.tri import Triangulation  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STRIP = "#f2c894"
ONE_CELL = "#bcd6ee"
ACTIVE = "#3a78b5"
RELEASED = "#f0a030"
PENETRATED = "#e8888a"


def decode(text, dtype):
    """The values of one binary DataArray of a compressed deal.II VTU file:
    a base64 header (block count, block size, last block size, compressed
    block sizes, all uint32), then the base64 of the zlib-compressed blocks.
    """
    text = text.strip()
    first = base64.b64decode(text[:24])
    blocks = struct.unpack("<I", first[:4])[0]
    header_length = 4 * ((4 * (3 + blocks) + 2) // 3)
    header = struct.unpack("<%dI" % (3 + blocks),
                           base64.b64decode(text[:header_length]))
    data = base64.b64decode(text[header_length:])
    raw, start = b"", 0
    for size in header[3:]:
        raw += zlib.decompress(data[start:start + size])
        start += size
    return list(struct.unpack("<%d%s" % (len(raw) // struct.calcsize(dtype),
                                         dtype), raw))


def read_vtu(path):
    """{name: values} of a deal.II VTU file; 'points' as (x, y) pairs and
    'cells' as lists of point indices."""
    with open(path) as stream:
        text = stream.read()
    codes = {"Float32": "f", "Float64": "d", "Int32": "i", "UInt8": "B",
             "Int64": "q"}
    arrays = {}
    pattern = re.compile(r'<DataArray type="(\w+)"([^>]*)>(.*?)</DataArray>',
                         re.S)
    for kind, attributes, body in pattern.findall(text):
        name = re.search(r'Name="([^"]+)"', attributes)
        arrays[name.group(1) if name else "points"] = decode(body, codes[kind])
    xyz = arrays.pop("points")
    arrays["points"] = list(zip(xyz[0::3], xyz[1::3]))
    offsets, connectivity = arrays.pop("offsets"), arrays.pop("connectivity")
    arrays["cells"] = [connectivity[a:b]
                       for a, b in zip([0] + offsets[:-1], offsets)]
    return arrays


def polygons(vtu):
    """The cells as polygons (VTK orders their corners around the cell)."""
    return [[vtu["points"][i] for i in cell] for cell in vtu["cells"]]


def triangles(vtu):
    """Each cell split into triangles, for plotting point data."""
    result = []
    for cell in vtu["cells"]:
        result += [[cell[0], cell[k], cell[k + 1]]
                   for k in range(1, len(cell) - 1)]
    return result


def draw_cells(axes, vtu, linewidth, title):
    """The cell edges of @p vtu in black, on equal axes fitted to them."""
    axes.add_collection(PolyCollection(polygons(vtu), facecolors="none",
                                       edgecolors="black",
                                       linewidths=linewidth))
    axes.set_aspect("equal")
    axes.autoscale_view()
    axes.set_title(title)


def run(membranes, scene, directory, settings, may_fail=False):
    """Runs @p scene with output to @p directory; whether it succeeded (a
    failure stops the script unless @p may_fail)."""
    command = [membranes] + sum((["--set", s] for s in settings), []) + [
        "--set", "Output/Directory=" + directory,
        os.path.join(ROOT, "parameters", scene)]
    shown = command[:-1] + [os.path.relpath(command[-1])]
    print("$ " + " ".join("'%s'" % c if " " in c else c for c in shown))
    return subprocess.run(command, check=not may_fail,
                          stdout=subprocess.DEVNULL,
                          stderr=subprocess.DEVNULL if may_fail else None
                          ).returncode == 0


def save(figure, path, dpi=130):
    figure.savefig(path, dpi=dpi, bbox_inches="tight")
    plt.close(figure)
    print("wrote " + path)


def problem_figure(out):
    """Case M (mu1 = 1, mu2 = 2, R = 1/2) along y = 0: u1 and u2, which
    touch for |x| < R, where the action lambda = 8 R^2 mu1 mu2/(mu1 + mu2)
    pushes membrane 1 up and membrane 2 down."""
    mu1, mu2, radius = 1.0, 2.0, 0.5
    share = mu1 / (mu1 + mu2)
    action = 8 * radius**2 * mu1 * mu2 / (mu1 + mu2)
    xs = [-1 + 2 * k / 400 for k in range(401)]
    base = [-(1 - x * x) for x in xs]
    bump = [(x * x - radius**2)**2 for x in xs]
    inside = [abs(x) < radius for x in xs]
    u1 = [b + (share if i else 1) * q for b, q, i in zip(base, bump, inside)]
    u2 = [b + (share * q if i else 0) for b, q, i in zip(base, bump, inside)]
    figure, axes = plt.subplots(figsize=(8, 3.6))
    axes.plot(xs, u1, color="tab:blue", linewidth=2,
              label="membrane 1, $u_1$ ($u_1=g$ on the boundary)")
    axes.plot(xs, u2, color="tab:orange", linewidth=2, linestyle="--",
              label="membrane 2, $u_2$ ($u_2=0$ on the boundary)")
    axes.axvspan(-radius, radius, color="0.9", zorder=0,
                 label=r"contact: $u_1=u_2$, $\lambda=%g>0$" % round(action, 3))
    for x in (-0.4, -0.2, 0, 0.2, 0.4):
        y = -(1 - x * x) + share * (x * x - radius**2)**2
        axes.annotate("", xy=(x, y + 0.12), xytext=(x, y),
                      arrowprops={"arrowstyle": "->", "color": "tab:red"})
    axes.text(0, -0.72, r"$\lambda$ pushes membrane 1 up", ha="center",
              color="tab:red")
    axes.set_xlabel("$x$ (on the line $y=0$)")
    axes.set_title(r"Case M: $\mu_1=1$, $\mu_2=2$; the gap $u_1-u_2\geq0$ "
                   "closes on the disk $r<1/2$")
    axes.legend(loc="upper center", fontsize=8, ncol=1)
    axes.set_ylim(-1.15, 0.75)
    save(figure, os.path.join(out, "membranes.png"))


def on_boundary(point):
    """Whether @p point lies on the boundary of the square (-1, 1)^2."""
    return max(abs(point[0]), abs(point[1])) > 1 - 1e-6


def rounded(point):
    """@p point as a key that identifies it across cells and files."""
    return (round(point[0], 6), round(point[1], 6))


def sub_triangles(primal, dual):
    """The sub-triangles (a, m_e, b_K) of the dual mesh, each as (corners,
    number of a, position of a); a is the corner that is a vertex of the
    primal mesh."""
    vertices = {rounded(p) for p in primal["points"]}
    result = []
    for cell in dual["cells"]:
        corners = [dual["points"][i] for i in cell]
        vertex = next(p for p in corners if rounded(p) in vertices)
        result.append((corners, int(dual["dual_vertex"][cell[0]]), vertex))
    return result


def dual_cell_outlines(pieces):
    """The edges between sub-triangles of different dual vertices a, at
    least one of them interior: the outlines of the D_a, which include the
    boundary of omega_h."""
    sides = {}
    for corners, number, vertex in pieces:
        for k in range(3):
            edge = (corners[k], corners[(k + 1) % 3])
            sides.setdefault(frozenset(map(rounded, edge)), []).append(
                (number, on_boundary(vertex), edge))
    return [neighbours[0][2] for neighbours in sides.values()
            if len(neighbours) == 2
            and neighbours[0][0] != neighbours[1][0]
            and not (neighbours[0][1] and neighbours[1][1])]


def dual_mesh_panel(axes, primal, dual, title):
    """The primal mesh (thin grey), the outlines of the dual cells D_a
    (thick), the dual vertices a (dots), the strip omega minus omega_h
    (shaded) and, filled, the cell D_a of the vertex nearest to
    (-1/2, 1/2)."""
    pieces = sub_triangles(primal, dual)
    inner = {v for _, _, v in pieces if not on_boundary(v)}
    shown = min(inner, key=lambda v: (v[0] + 0.5)**2 + (v[1] - 0.5)**2)
    axes.add_collection(PolyCollection(
        [c for c, _, v in pieces if on_boundary(v)], facecolors=STRIP,
        edgecolors=STRIP, linewidths=0.5))
    axes.add_collection(PolyCollection(
        [c for c, _, v in pieces if v == shown], facecolors=ONE_CELL,
        edgecolors=ONE_CELL, linewidths=0.5))
    axes.add_collection(PolyCollection(polygons(primal), facecolors="none",
                                       edgecolors="0.6", linewidths=0.7))
    axes.add_collection(LineCollection(dual_cell_outlines(pieces),
                                       colors="black", linewidths=2.2))
    axes.plot(*zip(*inner), "o", color="black", markersize=5)
    axes.annotate("$a$", shown, xytext=(4, 3), textcoords="offset points",
                  fontsize=13)
    axes.annotate("$D_a$", shown, xytext=(-3, -5), textcoords="offset points",
                  ha="right", va="top", fontsize=13)
    axes.set_aspect("equal")
    axes.autoscale_view()
    axes.set_axis_off()
    axes.set_title(title, fontsize=13)


def dual_mesh_figure(membranes, out):
    figure, axes = plt.subplots(1, 2, figsize=(10, 5.6))
    for axis, scene, refinement, cells in (
            (axes[0], "case-m-triangle.prm", 1, "P1: %d triangles"),
            (axes[1], "case-m-quadrilateral.prm", 2, "Q1: %d quadrilaterals")):
        directory = os.path.join(out, "dual-mesh", scene[:-4])
        run(membranes, scene, directory,
            ["Geometry/Initial refinement=%d" % refinement,
             "Refinement/Cycles=1", "Output/Flux reconstruction=true"])
        primal = read_vtu(os.path.join(directory, "solution-00.vtu"))
        dual = read_vtu(os.path.join(directory, "dual-mesh-00.vtu"))
        dual_mesh_panel(axis, primal, dual, cells % len(primal["cells"]))
    legend = [
        Line2D([], [], color="0.6", linewidth=0.7, label="primal mesh"),
        Line2D([], [], color="black", linewidth=2.2,
               label=r"dual cells $D_a$"),
        Line2D([], [], color="black", marker="o", linestyle="none",
               markersize=5, label=r"dual vertices $a$ (interior)"),
        Patch(color=ONE_CELL, label=r"one cell $D_a$"),
        Patch(color=STRIP, label=r"strip $\omega\backslash\omega_h$, "
              r"where $\lambda_h=0$")]
    figure.legend(handles=legend, loc="lower center", ncol=3, fontsize=12,
                  frameon=False)
    figure.suptitle(r"The dual mesh of case M on $\omega=(-1,1)^2$: "
                    r"$\omega_h$ is the union of the $D_a$", fontsize=14)
    figure.subplots_adjust(bottom=0.16, top=0.86, wspace=0.08)
    save(figure, os.path.join(out, "dual-mesh.png"), dpi=110)


def active_set_iterates(membranes, out, scene, settings):
    """The iterates of the active set method on one mesh: the run with
    'Max active set iterations = k' stops after iteration k and writes its
    iterate (u_h, lambda_h, the active set of the iteration) to
    unconverged/; the first run that converges gives the last one."""
    iterates = []
    while True:
        limit = len(iterates) + 1
        directory = os.path.join(out, "active-set", "iterations-%d" % limit)
        converged = run(membranes, scene, directory, settings + [
            "Solver/Max active set iterations=%d" % limit], may_fail=True)
        iterates.append(read_vtu(os.path.join(
            directory, "" if converged else "unconverged", "solution-00.vtu")))
        if converged:
            return iterates


def vertex_values(vtu, name):
    """{vertex: value} of the point field @p name (a VTU file repeats each
    vertex once per cell)."""
    return dict(zip(map(rounded, vtu["points"]), vtu[name]))


def squares(vertices, side):
    """A square of @p side about each of @p vertices."""
    half = side / 2
    return [[(x - half, y - half), (x + half, y - half), (x + half, y + half),
             (x - half, y + half)] for x, y in vertices]


def active_set_panel(axes, iterate, following, iteration):
    """The active vertices of @p iterate (those left out of the active set
    of @p following in orange), the inactive vertices where the gap w came
    out negative (red), each as a square of the mesh size of the uniform
    mesh of (-1, 1)^2; the exact contact circle dashed."""
    status = vertex_values(iterate, "active_set")
    active = {v for v, a in status.items() if a > 0.5}
    stays = {v for v, a in vertex_values(following, "active_set").items()
             if a > 0.5}
    gap = vertex_values(iterate, "w")
    scale = max(abs(w) for w in gap.values())
    penetrated = {v for v, w in gap.items() if w < -1e-10 * scale} - active
    side = 2 / (math.isqrt(len(status)) - 1)
    for vertices, colour in ((active & stays, ACTIVE),
                             (active - stays, RELEASED),
                             (penetrated, PENETRATED)):
        axes.add_collection(PolyCollection(squares(vertices, side),
                                           facecolors=colour,
                                           edgecolors=colour, linewidths=0.2))
    axes.add_patch(plt.Circle((0, 0), 0.5, fill=False, color="black",
                              linestyle="--", linewidth=1.2))
    axes.set_xlim(-1, 1)
    axes.set_ylim(-1, 1)
    axes.set_aspect("equal")
    axes.set_xticks([])
    axes.set_yticks([])
    axes.set_title("iteration %d:\n%d active vertices"
                   % (iteration, len(active)), fontsize=12)


def active_set_figure(membranes, out):
    iterates = active_set_iterates(
        membranes, out, "case-m-triangle.prm",
        ["Geometry/Initial refinement=5", "Refinement/Cycles=1"])
    figure, axes = plt.subplots(1, len(iterates),
                                figsize=(2.4 * len(iterates), 3.3))
    following = iterates[1:] + iterates[-1:]
    for k, axis in enumerate(axes):
        active_set_panel(axis, iterates[k], following[k], k + 1)
    legend = [
        Patch(color=ACTIVE, label="active vertex"),
        Patch(color=RELEASED, label="active, released by the next iteration"),
        Patch(color=PENETRATED, label="inactive, gap $w_a<0$"),
        Line2D([], [], color="black", linestyle="--",
               label="exact contact circle $r=1/2$")]
    figure.legend(handles=legend, loc="lower center", ncol=2, fontsize=11,
                  frameon=False)
    cells = len(iterates[0]["cells"])
    figure.suptitle("The active set iterations of case M on one P1 mesh "
                    "(%d triangles, %d vertices),\nfrom $u_h=0$ to "
                    "convergence at iteration %d"
                    % (cells, len(vertex_values(iterates[0], "w")),
                       len(iterates)),
                    fontsize=13)
    figure.subplots_adjust(bottom=0.2, top=0.72, wspace=0.06)
    save(figure, os.path.join(out, "active-set-iterations.png"), dpi=110)


def fields_figure(membranes, out):
    directory = os.path.join(out, "case-m")
    run(membranes, "case-m-quadrilateral.prm", directory,
        ["Refinement/Cycles=5"])
    vtu = read_vtu(os.path.join(directory, "solution-04.vtu"))
    x, y = zip(*vtu["points"])
    mesh = Triangulation(x, y, triangles(vtu))
    figure, axes = plt.subplots(1, 4, figsize=(21, 4.8))
    for axis, name, title in ((axes[0], "u1", "$u_{1h}$"),
                              (axes[1], "u2", "$u_{2h}$"),
                              (axes[2], "w", "$u_{1h}-u_{2h}$"),
                              (axes[3], "lambda_h", r"$\lambda_a$ and the active set")):
        plot = axis.tripcolor(mesh, vtu[name], shading="gouraud",
                              cmap="viridis")
        figure.colorbar(plot, ax=axis, shrink=0.85)
        axis.set_aspect("equal")
        axis.set_title(title)
    active = [p for p, a in zip(vtu["points"], vtu["active_set"]) if a > 0.5]
    if active:
        axes[3].plot(*zip(*active), ".", color="white", markersize=1.5)
    for axis in axes:
        circle = plt.Circle((0, 0), 0.5, fill=False, color="red",
                            linestyle="--", linewidth=1)
        axis.add_patch(circle)
    with open(os.path.join(directory, "report.csv")) as report:
        dofs = list(csv.DictReader(report))[-1]["dofs"]
    figure.suptitle("Case M, Q1, %s DoFs; the exact contact circle r = 1/2 "
                    "dashed" % dofs)
    save(figure, os.path.join(out, "case-m-fields.png"))


def adaptive_mesh_figure(membranes, out):
    directory = os.path.join(out, "slit")
    run(membranes, "slit.prm", directory, ["Refinement/Cycles=12"])
    vtu = read_vtu(os.path.join(directory, "solution-11.vtu"))
    figure, axes = plt.subplots(figsize=(6.5, 6.5))
    draw_cells(axes, vtu, 0.2,
               "slit.prm after 11 adaptive refinements: the slit (red)\n"
               "and the contact disk (dashed)")
    axes.plot([0, 1], [0, 0], color="red", linewidth=1.5)
    axes.add_patch(plt.Circle((-0.5, -0.5), 0.25, fill=False, color="blue",
                              linestyle="--", linewidth=1))
    save(figure, os.path.join(out, "slit-adaptive-mesh.png"))


def main():
    membranes = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        ROOT, "build", "membranes")
    out = sys.argv[2] if len(sys.argv) > 2 else "/tmp/membranes-figures"
    os.makedirs(out, exist_ok=True)
    problem_figure(out)
    dual_mesh_figure(membranes, out)
    active_set_figure(membranes, out)
    fields_figure(membranes, out)
    adaptive_mesh_figure(membranes, out)


if __name__ == "__main__":
    main()
