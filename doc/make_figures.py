#!/usr/bin/env python3
"""The figures of doc/tutorial.md that show meshes and fields.

Usage::

    /usr/bin/python3 doc/make_figures.py [path/to/membranes] [output-dir]

Defaults: build/membranes of this repository and /tmp/membranes-figures.
Draws the picture of the problem from the exact solution of case M, then
runs three small scenes with VTU output and draws from the VTU files the
program writes (deal.II's zlib-compressed base64 format, read here without
VTK):

* ``membranes.png``: the two membranes of case M along the line y = 0, the
  contact zone and the action lambda there (no run of the program);
* ``dual-mesh.png``: case M on triangles, one global refinement, the flux
  reconstruction on: the primal mesh and the sub-triangles (a, m_e, b_K) of
  the dual mesh, coloured by their dual vertex a, as Fig. 1 of the paper;
* ``case-m-fields.png``: case M on Q1, 5 cycles: u1, u2, u1 − u2, λ_h (the
  nodal λ_a) and the active set, with the exact contact circle r = 1/2;
* ``slit-adaptive-mesh.png``: the slit scene, 12 adaptive cycles: the mesh
  refined towards the crack tip, with the slit and the contact disk.

The commands behind each figure are printed. Requires matplotlib.
"""

import base64
import csv
import os
import re
import struct
import subprocess
import sys
import zlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402
from matplotlib.tri import Triangulation  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


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


def run(membranes, scene, directory, settings):
    command = [membranes] + sum((["--set", s] for s in settings), []) + [
        "--set", "Output/Directory=" + directory,
        os.path.join(ROOT, "parameters", scene)]
    shown = command[:-1] + [os.path.relpath(command[-1])]
    print("$ " + " ".join("'%s'" % c if " " in c else c for c in shown))
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)


def save(figure, path):
    figure.savefig(path, dpi=130, bbox_inches="tight")
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


def dual_mesh_figure(membranes, out):
    directory = os.path.join(out, "dual-mesh")
    run(membranes, "case-m-triangle.prm", directory,
        ["Geometry/Initial refinement=1", "Refinement/Cycles=1",
         "Output/Flux reconstruction=true"])
    primal = read_vtu(os.path.join(directory, "solution-00.vtu"))
    dual = read_vtu(os.path.join(directory, "dual-mesh-00.vtu"))
    figure, axes = plt.subplots(figsize=(6, 6))
    # Neighbouring vertices have neighbouring numbers: scatter them over
    # the 20 colours.
    colours = PolyCollection(polygons(dual), array=[
        (int(v) * 2654435761) % 20 for v in dual["dual_vertex"]],
        cmap="tab20",
        edgecolors="white", linewidths=0.3)
    axes.add_collection(colours)
    draw_cells(axes, primal, 1.2,
               "Primal mesh (black) and the sub-triangles (a, m_e, b_K)\n"
               "of the dual cells D_a, one colour per vertex a")
    save(figure, os.path.join(out, "dual-mesh.png"))


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
    fields_figure(membranes, out)
    adaptive_mesh_figure(membranes, out)


if __name__ == "__main__":
    main()
