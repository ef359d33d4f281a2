#ifndef membranes_discretization_h
#define membranes_discretization_h

#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature.h>
#include <deal.II/fe/fe.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/grid/tria.h>
#include <membranes/dual_mesh/dual_cell_quadrature.h>
#include <membranes/scene/parameters.h>
#include <memory>

namespace membranes
{
  using namespace dealii;

  /**
   * The finite element setting of §3 of the paper: one mesh T_h and the
   * same continuous piecewise-linear space for both membranes, P1 on
   * triangles (FE_SimplexP, MappingFE, QGaussSimplex) or Q1 on
   * quadrilaterals (FE_Q, MappingQ1, QGauss).
   *
   * Both membranes live in the same scalar space: one DoFHandler of this
   * element numbers the vertices of the mesh, and the two membranes are two
   * blocks with that one numbering (u1h = solution.block(0), u2h =
   * solution.block(1); no FESystem, unlike step-22). s = μ1 u1 + μ2 u2 and
   * w = u1 − u2 are vector operations on the blocks, and the stiffness
   * matrix of the mesh is one matrix A of the scalar element, μ_i A for
   * membrane i.
   *
   * On a mesh of axis-parallel rectangles (the square, the L-shape and the
   * slit, and every refinement of them) the mapping of each cell is a
   * scaling and a shift, and MappingCartesian computes it far more cheaply
   * than MappingQ1, with the same values up to round-off. This matters
   * because deal.II recomputes the mapping on every cell whenever more
   * than one thread is in use (it then turns off the shortcut of FEValues
   * for a cell that is a translation of the previous one).
   */
  template <int dim>
  class Discretization
  {
  public:
    explicit Discretization(const Parameters::CellType cell_type);

    /**
     * Take MappingCartesian when every cell of the coarse mesh
     * @p triangulation is a rectangle with axis-parallel edges and no
     * curved manifold; keep MappingQ1 (or MappingFE for triangles)
     * otherwise. Called once, on the coarse mesh, before any cycle.
     */
    void
    select_mapping(const Triangulation<dim> &triangulation);

    const Parameters::CellType                cell_type;
    const std::unique_ptr<FiniteElement<dim>> fe;
    std::unique_ptr<Mapping<dim>>             mapping;

    /** Whether select_mapping() found a mesh of axis-parallel rectangles
     * (and took MappingCartesian), on which a Q1 function has
     * ∂²/∂x² = ∂²/∂y² = 0. */
    bool
    rectangles() const;

    /** Quadrature for the stiffness matrix and the loads (exact for P1/Q1
     * stiffness, degree 3 for smooth loads). */
    const Quadrature<dim> cell_quadrature;

    /**
     * The quadrature on the pieces K ∩ D_a of the dual cells in every cell
     * K: the one quadrature of everything that integrates λ_h, which is
     * constant on each piece (the error norms, both estimators, the flux
     * reconstruction). It lives on the reference cell, the same for every
     * mesh of the run.
     */
    const DualCellQuadrature<dim> dual_cell_quadrature;
  };



  /**
   * The triangulation of a run on the processes of @p mpi_communicator:
   *
   * - quadrilaterals: a parallel::distributed::Triangulation (p4est), on
   *   any number of processes; one process is the case N = 1 of the same
   *   class, so serial and parallel runs share every line of the program;
   * - triangles: a parallel::shared::Triangulation (deal.II 9.4's p4est
   *   triangulation has no simplices), on any number of processes: every
   *   process holds the whole mesh, and its active cells are partitioned in
   *   the z-order that p4est uses, again after every refinement. Each
   *   process owns its cells and their DoFs and sees one layer of ghost
   *   cells; the others are artificial to it, as on p4est, so the program
   *   runs the same lines on both (step-40's owned and relevant index sets,
   *   ghosted vectors).
   *
   * Mesh smoothing is off for both, so that a refinement step refines what
   * the marking marked (and the hanging-node rule of at most one hanging
   * node per edge, which every deal.II triangulation keeps).
   */
  template <int dim>
  std::unique_ptr<Triangulation<dim>>
  make_triangulation(const Parameters::CellType cell_type,
                     const MPI_Comm             mpi_communicator);



  /**
   * The coarse mesh of the scene's domain, refined `Initial refinement`
   * times: the square (−1,1)², the L-shape (−1,1)² minus [0,1)², the
   * slit domain (−1,1)² minus [0,1) × {0} (four cells, the vertices on the
   * slit doubled, so that both of its faces are boundary), the unit
   * disk (its circle kept as a SphericalManifold, so refinement follows the
   * curved boundary), or a Gmsh file. Quadrilateral meshes are split into
   * triangles (GridGenerator::convert_hypercube_to_simplex_mesh) when the
   * scene asks for triangles; a triangle mesh with `Cell type =
   * quadrilateral`, a mixed mesh, or a file that cannot be read is an
   * InputError naming the entry.
   */
  template <int dim>
  void
  create_mesh(const Parameters::Geometry &geometry,
              Triangulation<dim>         &triangulation);



  /**
   * Complete the ghost layer of a parallel::shared::Triangulation after
   * it was partitioned (created or refined): a cell is a ghost cell of a
   * process if it touches one of the process's own cells, also through a
   * hanging vertex. deal.II 9.4 makes ghost cells only of the cells that
   * share a vertex of theirs with an owned cell, so a coarse cell that
   * meets an owned fine cell only at the hanging vertex in the middle of
   * its edge would stay artificial, and with it the constraint of that
   * vertex and the cells around it that the flux reconstruction needs;
   * p4est's ghost layer has them, and so has this one. Here a cell touches
   * the vertices of its corners and the hanging vertices in the middle of
   * its refined edges. On other triangulations, or one process, nothing
   * changes.
   */
  template <int dim>
  void
  complete_ghost_layer(Triangulation<dim> &triangulation);
} // namespace membranes

#endif
