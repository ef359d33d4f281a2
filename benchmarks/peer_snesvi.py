#!/usr/bin/python3
"""The scene of parameters/degenerate-free-boundary.prm solved by FEniCSx and
PETSc's SNES VI solver, as a peer of membranes; and the table comparing both.

Solve (FEniCSx 0.5: python3-dolfinx of Debian 12, whose interpreter is
/usr/bin/python3; one process):

    /usr/bin/python3 benchmarks/peer_snesvi.py [--scene degenerate]
        [--levels 7] [--mu1 1] [--mu2 1] [--output peer.csv] [PETSc options]

The scenes are hard-coded here, except for the tensions. --scene
shifted-circle is parameters/shifted-circle.prm (long expressions: cos,
powers, conditionals; see shifted_circle()); --scene ellipse is
tests/scenes/ellipse-contact.prm (contact inside an ellipse off the centre,
u2 = sin(pi x) sin(pi y), a cubic gap, lambda vanishing quadratically at the
free boundary; see ellipse()); the default, degenerate, is
parameters/degenerate-free-boundary.prm: on omega = (-1,1)^2,
with r^2 = x^2 + y^2, t = r^2 - R^2, R = 1/2, L = 16, q = (1-x^2)(1-y^2),

    u2 = q,   u1 = q + max(t, 0)^3,   lambda = L max(-t, 0)^2,
    f1 = -mu1 Laplace(u1) - lambda,   f2 = -mu2 Laplace(u2) + lambda,
    u1 = g = t^3 and u2 = g2 = 0 on the boundary.

Discrete problem: P1 elements for the pair (u1, w), w = u1 - u2 (a
two-component P1 space: 2 DoFs per vertex, as membranes' (u1, u2)),
minimizing

    sum_i mu_i/2 |grad u_i|^2 - f_i u_i   over u2 = u1 - w,

with u1 = g, w = g - g2 on the boundary and w >= 0 at every vertex, that is
membranes' nodal constraint u1(a) >= u2(a). The energy is quadratic, so its
gradient is F(x) = A x - b with a constant matrix A (assembled once per level,
boundary rows replaced by identity rows) and b the loads with the boundary
values lifted. PETSc's reduced-space active set Newton method
(SNES vinewtonrsls) solves this variational inequality, with the bounds of
SNESVISetVariableBounds: 0 <= w, -PETSC_INFINITY <= u1, both below
PETSC_INFINITY. Each Newton step is an LU factorization by MUMPS of the
matrix reduced to the inactive set (KSP preonly, PC lu). Tolerances:
-snes_rtol 1e-10 and -snes_atol 1e-12 |b|_2 (it scales with the data); the
other settings are PETSc's defaults (line search bt, -snes_stol 1e-8, at
most 50 iterations). PETSc options on the command line override these
(e.g. -snes_linesearch_type basic, -snes_monitor, -snes_view).

Meshes: dolfinx.mesh.create_rectangle on [-1,1]^2 with n x n squares, each cut
into two triangles along its "right" diagonal (from lower left to upper
right), n = 2^(k+3) on level k. These are the vertex grids, and so the DoF
counts 2 (n+1)^2, of membranes' cycles k on this scene, but not all its
triangles: membranes splits the square into an inner diamond |x| + |y| <= 1
and four corner triangles (eight triangles through the centre and the edge
midpoints) and refines them regularly, so its diagonals are parallel to the
sides of the diamond. The two triangulations coincide where x y < 0 and are
mirror images where x y > 0. The errors depend on the triangulation (most in
the corners, where u1 - u2 = t^3 is largest), so the two solvers' errors
differ here by factors up to about 1.7; each triangulation has one discrete
solution, which SNES VI and membranes both find.

Nested iteration: level k+1 starts from the level-k solution evaluated at the
fine vertices (each fine mesh refines the coarse one, so this is exactly the
coarse P1 function), with the boundary values of the fine level, projected
onto w >= 0. Level 0 starts from zero with the boundary values.

Written to the CSV file, per level: DoFs, SNES (Newton) iterations, active
vertices (where w_h = 0: SNES leaves the active ones on the bound), wall
time of the level (mesh, spaces, forms, data, transfer of the previous
solution, assembly, solve and error norms) and its cumulative sum, the errors
||u_i - u_ih||_H1 (the full norm) and ||u_i - u_ih||_L2 against the exact
solution, by quadrature of degree 8 (loads: degree 5).

Table (standard library only):

    python3 benchmarks/peer_snesvi.py --table peer.csv report.csv \\
        peer.time membranes.time

reads the peer's CSV, membranes' report.csv of the same scene and the two
whole-process measurements, each a line "wall_s user_s sys_s max_rss_kib"
(as written by /usr/bin/time -f "%e %U %S %M"), and prints a markdown table
per level and the whole-process comparison.
"""
import argparse
import csv
import math
import sys
import time

R = 0.5
L = 16.0


def degenerate(x, mu1, mu2):
    """parameters/degenerate-free-boundary.prm: u1, u2, f1, f2 in UFL, and
    the boundary values (g, g - g2) at points p as numpy arrays."""
    import ufl
    r2 = x[0] ** 2 + x[1] ** 2
    t = r2 - R ** 2
    outside = ufl.gt(t, 0)
    q = (1 - x[0] ** 2) * (1 - x[1] ** 2)
    lam = ufl.conditional(outside, 0, L * t ** 2)
    laplace_q = 2 * r2 - 4
    laplace_t3 = ufl.conditional(outside, 12 * t ** 2 + 24 * t * r2, 0)
    f1 = -mu1 * (laplace_q + laplace_t3) - lam
    f2 = -mu2 * laplace_q + lam

    def boundary(np, p):
        g = (p[0] ** 2 + p[1] ** 2 - R ** 2) ** 3
        return [g, g]
    return q + ufl.conditional(outside, t ** 3, 0), q, f1, f2, boundary


def shifted_circle(x, mu1, mu2):
    """parameters/shifted-circle.prm (tests/scenes/shifted-circle-loads.prm):
    contact inside the circle of radius 1/2 about (0.2, 0.1), a cubic gap
    outside it, lambda = 8 (R^2 - rho^2) inside."""
    import ufl
    cx, cy, lam_scale = 0.2, 0.1, 8.0
    rho2 = (x[0] - cx) ** 2 + (x[1] - cy) ** 2
    s = rho2 - R ** 2
    outside = ufl.gt(s, 0)
    u2 = ufl.cos(ufl.pi * x[0] / 2) * ufl.cos(ufl.pi * x[1] / 2)
    lam = ufl.conditional(outside, 0, -lam_scale * s)
    laplace_gap = ufl.conditional(outside, 12 * s ** 2 + 24 * s * rho2, 0)
    f1 = mu1 * ufl.pi ** 2 / 2 * u2 - mu1 * laplace_gap - lam
    f2 = mu2 * ufl.pi ** 2 / 2 * u2 + lam

    def boundary(np, p):
        gap = np.maximum((p[0] - cx) ** 2 + (p[1] - cy) ** 2 - R ** 2, 0) ** 3
        return [np.cos(np.pi * p[0] / 2) * np.cos(np.pi * p[1] / 2) + gap, gap]
    return u2 + ufl.conditional(outside, s ** 3, 0), u2, f1, f2, boundary


def ellipse(x, mu1, mu2):
    """tests/scenes/ellipse-contact.prm: contact inside the ellipse t < 0,
    t = ((x-cx)/a)^2 + ((y-cy)/b)^2 - 1, u2 = sin(pi x) sin(pi y), a cubic
    gap G max(t, 0)^3 outside it, lambda = L max(-t, 0)^2 inside."""
    import ufl
    cx, cy, a, b, gap_scale, lam_scale = 0.2, -0.1, 0.55, 0.35, 0.002, 10.0
    X, Y = x[0] - cx, x[1] - cy
    t = (X / a) ** 2 + (Y / b) ** 2 - 1
    outside = ufl.gt(t, 0)
    u2 = ufl.sin(ufl.pi * x[0]) * ufl.sin(ufl.pi * x[1])
    lam = ufl.conditional(outside, 0, lam_scale * t ** 2)
    laplace_gap = ufl.conditional(
        outside, gap_scale * (6 * t ** 2 * (1 / a ** 2 + 1 / b ** 2)
                              + 24 * t * (X ** 2 / a ** 4 + Y ** 2 / b ** 4)),
        0)
    f1 = 2 * mu1 * ufl.pi ** 2 * u2 - mu1 * laplace_gap - lam
    f2 = 2 * mu2 * ufl.pi ** 2 * u2 + lam

    def boundary(np, p):
        gap = gap_scale * np.maximum(
            ((p[0] - cx) / a) ** 2 + ((p[1] - cy) / b) ** 2 - 1, 0) ** 3
        return [gap, gap]
    u1 = u2 + ufl.conditional(outside, gap_scale * t ** 3, 0)
    return u1, u2, f1, f2, boundary


SCENES = {"degenerate": degenerate, "shifted-circle": shifted_circle,
          "ellipse": ellipse}
CSV_COLUMNS = ["level", "dofs", "snes_iterations", "active_vertices",
               "wall_time_s", "cumulative_wall_time_s", "err_u1_H1",
               "err_u2_H1", "err_u1_L2", "err_u2_L2"]


def interpolate_coarse(coarse, V):
    """The coarse P1 function evaluated at the dofs (vertices) of
    the finer space V: exactly the coarse function, as the fine mesh
    refines the coarse one."""
    import numpy as np
    from dolfinx import fem, geometry

    coarse_mesh = coarse.function_space.mesh
    tree = geometry.BoundingBoxTree(coarse_mesh, coarse_mesh.topology.dim)

    def values(x):
        points = np.ascontiguousarray(x.T)
        cells = geometry.compute_colliding_cells(
            coarse_mesh, geometry.compute_collisions(tree, points), points)
        return coarse.eval(points, cells.array[cells.offsets[:-1]]).T

    u = fem.Function(V)
    u.interpolate(values)
    return u


def discrete_problem(comm, level, scene, mu1, mu2):
    """The mesh of the level (n = 2^(level+3)), the two-component P1 space V
    of (u1, w), the exact solution, and the gradient of the energy in
    (u1, w), u2 = u1 - w: F(x) = A x - b with A and b assembled, the
    boundary values (u1 = g, w = g - g2) lifted. Returns V, A, b, the
    boundary conditions and the exact u1, u2 (UFL)."""
    import numpy as np
    import ufl
    from dolfinx import fem, mesh
    from dolfinx.fem import petsc as fem_petsc

    n = 2 ** (level + 3)
    domain = mesh.create_rectangle(
        comm, [np.array([-1.0, -1.0]), np.array([1.0, 1.0])], [n, n],
        mesh.CellType.triangle, diagonal=mesh.DiagonalType.right)
    V = fem.VectorFunctionSpace(domain, ("Lagrange", 1), dim=2)

    # Exact solution and data.
    x = ufl.SpatialCoordinate(domain)
    u1_exact, u2_exact, f1, f2, boundary = SCENES[scene](x, mu1, mu2)

    # The gradient of the energy in (u1, w), u2 = u1 - w, is
    # F(x) = A x - b with these forms.
    du, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    du1, du2 = du[0], du[0] - du[1]
    v1, v2 = v[0], v[0] - v[1]
    a = fem.form((mu1 * ufl.inner(ufl.grad(du1), ufl.grad(v1))
                  + mu2 * ufl.inner(ufl.grad(du2), ufl.grad(v2))) * ufl.dx)
    load = fem.form((f1 * v1 + f2 * v2)
                    * ufl.dx(metadata={"quadrature_degree": 5}))

    # u1 = g, w = g - g2 on the boundary.
    boundary_values = fem.Function(V)
    boundary_values.interpolate(lambda p: np.array(boundary(np, p)))
    domain.topology.create_connectivity(1, 2)
    boundary_dofs = fem.locate_dofs_topological(
        V, 1, mesh.exterior_facet_indices(domain.topology))
    bcs = [fem.dirichletbc(boundary_values, boundary_dofs)]

    A = fem_petsc.assemble_matrix(a, bcs)
    A.assemble()
    b = fem_petsc.assemble_vector(load)
    fem_petsc.apply_lifting(b, [a], [bcs])
    fem_petsc.set_bc(b, bcs)
    return V, A, b, bcs, u1_exact, u2_exact


def initial_guess(V, bcs, previous):
    """The previous level's solution (or zero on level 0) with
    the boundary values of this level, w projected onto w >= 0."""
    import numpy as np
    from dolfinx import fem
    from dolfinx.fem import petsc as fem_petsc

    u = fem.Function(V)
    if previous is not None:
        u.x.array[:] = interpolate_coarse(previous, V).x.array
    fem_petsc.set_bc(u.vector, bcs)
    u.x.array[1::2] = np.maximum(u.x.array[1::2], 0.0)
    return u


def solve_variational_inequality(comm, level, A, b, u):
    """A x = b on the inactive set, w >= 0, by SNES vinewtonrsls with MUMPS
    LU from the initial guess u, which holds the solution afterwards.
    Returns the SNES (Newton) iterations; exits if SNES did not converge."""
    from petsc4py import PETSc

    lower = u.vector.duplicate()
    lower.array[0::2] = -PETSc.INFINITY
    lower.array[1::2] = 0.0
    upper = u.vector.duplicate()
    upper.set(PETSc.INFINITY)

    def residual(snes, x, r):
        A.mult(x, r)
        r.axpy(-1.0, b)

    def jacobian(snes, x, J, P):
        """Nothing to do: the Jacobian is A, assembled above."""

    snes = PETSc.SNES().create(comm)
    snes.setType("vinewtonrsls")
    snes.setFunction(residual, b.duplicate())
    snes.setJacobian(jacobian, A)
    snes.setVariableBounds(lower, upper)
    snes.setTolerances(rtol=1e-10, atol=1e-12 * b.norm())
    ksp = snes.getKSP()
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    snes.setFromOptions()
    snes.solve(None, u.vector)
    if snes.getConvergedReason() <= 0:
        sys.exit(f"peer_snesvi.py: error: SNES did not converge on level "
                 f"{level} (reason {snes.getConvergedReason()})")
    iterations = snes.getIterationNumber()
    snes.destroy()
    return iterations


def error_norms(u, u1_exact, u2_exact):
    """||u_i - u_ih||_H1 (the full norms, as membranes reports them (3.5))
    and ||u_i - u_ih||_L2, by quadrature of degree 8."""
    import ufl
    from dolfinx import fem

    dx_error = ufl.dx(metadata={"quadrature_degree": 8})

    def norm(square):
        return math.sqrt(fem.assemble_scalar(fem.form(square * dx_error)))

    e1 = u[0] - u1_exact
    e2 = u[0] - u[1] - u2_exact
    return [norm(ufl.inner(ufl.grad(e1), ufl.grad(e1)) + e1 * e1),
            norm(ufl.inner(ufl.grad(e2), ufl.grad(e2)) + e2 * e2),
            norm(e1 * e1), norm(e2 * e2)]


def solve(scene, levels, mu1, mu2, output, petsc_options):
    """Solve on levels 0 .. levels-1, print progress, write the CSV file."""
    # Imported here, so that the table mode needs the standard library only.
    import numpy as np
    from mpi4py import MPI
    from petsc4py import PETSc

    PETSc.Options().insertString(" ".join(petsc_options))
    comm = MPI.COMM_SELF

    rows = []
    cumulative = 0.0
    previous = None
    for level in range(levels):
        start = time.perf_counter()
        V, A, b, bcs, u1_exact, u2_exact = discrete_problem(
            comm, level, scene, mu1, mu2)
        u = initial_guess(V, bcs, previous)
        iterations = solve_variational_inequality(comm, level, A, b, u)
        active = np.count_nonzero(u.x.array[1::2] == 0.0)
        errors = error_norms(u, u1_exact, u2_exact)
        previous = u

        seconds = time.perf_counter() - start
        cumulative += seconds
        dofs = 2 * V.dofmap.index_map.size_global
        rows.append([level, dofs, iterations, active, f"{seconds:.3f}",
                     f"{cumulative:.3f}"] + [f"{e:.6e}" for e in errors])
        print(f"level {level}: {dofs} DoFs, {iterations} SNES iterations, "
              f"{active} active vertices, {seconds:.2f} s; errors H1 "
              f"{errors[0]:.3e} {errors[1]:.3e}, L2 {errors[2]:.3e} "
              f"{errors[3]:.3e}", flush=True)

    with open(output, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(CSV_COLUMNS)
        writer.writerows(rows)


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def read_time(path):
    """wall_s, cpu_s (user + system), peak resident set in MiB."""
    wall, user, system, rss_kib = open(path).read().split()
    return float(wall), float(user) + float(system), int(rss_kib) / 1024


def order(rows, column):
    """Observed order in h between the last two rows (h halves per level)."""
    if len(rows) < 2:
        return float("nan")
    return math.log2(float(rows[-2][column]) / float(rows[-1][column]))


def table(peer_csv, report_csv, peer_time, membranes_time):
    """Print the comparison in markdown."""
    peer = read_csv(peer_csv)
    membranes = read_csv(report_csv)
    # The error columns both compute (membranes: those its scene's
    # Exact solution/Norms names).
    names = {"err_u1_H1": "H1 u1", "err_u2_H1": "H1 u2", "err_u1_L2": "L2 u1",
             "err_u2_L2": "L2 u2"}
    errors = [e for e in names if membranes and e in membranes[0]]
    print("| level | DoFs | its M | its P | s M | s P | s P/M | "
          + "".join(f"{names[e]} M | {names[e]} P | " for e in errors))
    print("|--:|--:|--:|--:|--:|--:|--:|" + "--:|--:|" * len(errors))
    mismatch = []
    for level, (m, p) in enumerate(zip(membranes, peer)):
        if m["dofs"] != p["dofs"]:
            mismatch.append(f"level {level}: membranes {m['dofs']} DoFs, "
                            f"peer {p['dofs']}")
        # The peer's level time holds its error norms: membranes' too
        # (time_errors_s, not part of its wall_time_s).
        m_time = float(m["wall_time_s"]) + float(m.get("time_errors_s") or 0)
        ratio = float(p["wall_time_s"]) / m_time
        cells = [str(level), m["dofs"], m["active_set_iterations"],
                 p["snes_iterations"], f"{m_time:.2f}",
                 f"{float(p['wall_time_s']):.2f}", f"{ratio:.1f}"]
        for e in errors:
            cells += [f"{float(m[e]):.3e}", f"{float(p[e]):.3e}"]
        print("| " + " | ".join(cells) + " |")
    print()
    print("M = membranes, P = the peer (FEniCSx, SNES vinewtonrsls, MUMPS "
          "LU); its: active set / Newton iterations; s: wall time of the "
          "level.")
    print("Observed orders in h between the last two levels, "
          + ", ".join(names[e] for e in errors) + ": membranes "
          + ", ".join(f"{order(membranes, e):.2f}" for e in errors)
          + "; peer " + ", ".join(f"{order(peer, e):.2f}" for e in errors)
          + ".")
    p_wall, p_cpu, p_rss = read_time(peer_time)
    m_wall, m_cpu, m_rss = read_time(membranes_time)
    print(f"Whole process: membranes {m_wall:.1f} s wall ({m_cpu:.1f} s CPU, "
          f"{m_rss:.0f} MiB peak), peer {p_wall:.1f} s wall ({p_cpu:.1f} s "
          f"CPU, {p_rss:.0f} MiB peak); wall time ratio peer/membranes "
          f"{p_wall / m_wall:.2f}.")
    if len(peer) != len(membranes):
        mismatch.append(f"membranes {len(membranes)} cycles, peer "
                        f"{len(peer)} levels")
    for line in mismatch:
        print(f"MISMATCH {line}")
    if mismatch:
        sys.exit(1)


def main():
    parser = argparse.ArgumentParser(
        description="The degenerate free boundary scene by FEniCSx and "
        "PETSc SNES VI (vinewtonrsls), or the comparison table with "
        "membranes. Unknown options are passed to PETSc.")
    parser.add_argument("--scene", choices=sorted(SCENES),
                        default="degenerate",
                        help="the scene (degenerate: degenerate-free-"
                        "boundary.prm; shifted-circle: shifted-circle.prm; "
                        "ellipse: tests/scenes/ellipse-contact.prm)")
    parser.add_argument("--levels", type=int, default=7,
                        help="number of levels (n = 8, 16, ... intervals)")
    parser.add_argument("--mu1", type=float, default=1.0)
    parser.add_argument("--mu2", type=float, default=1.0)
    parser.add_argument("--output", default="peer.csv",
                        help="CSV file of the per-level results")
    parser.add_argument("--table", nargs=4,
                        metavar=("PEER_CSV", "REPORT_CSV", "PEER_TIME",
                                 "MEMBRANES_TIME"),
                        help="print the comparison table instead of solving")
    args, petsc_options = parser.parse_known_args()
    if args.table:
        table(*args.table)
    else:
        solve(args.scene, args.levels, args.mu1, args.mu2, args.output,
              petsc_options)


if __name__ == "__main__":
    main()
