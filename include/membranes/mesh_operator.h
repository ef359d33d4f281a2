#ifndef membranes_mesh_operator_h
#define membranes_mesh_operator_h

#include <array>
#include <deal.II/base/index_set.h>
#include <deal.II/base/smartpointer.h>
#include <deal.II/base/subscriptor.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/discretization.h>
#include <membranes/problem_data.h>
#include <utility>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * What the discrete problem (3.4) is made of on one mesh, built once per
   * mesh (MembraneProblem::setup_system()) and read, through a const
   * reference, by everything that works on the mesh: DiscreteAction (the
   * postprocessing (4.5)), the linear systems of the active set method
   * (CoupledSystem, DecoupledSystem) and the ActiveSet.
   *
   * It holds
   * - the DoFHandler of (u1, u2), its locally owned and locally relevant
   *   DoFs (the step-40 layout) and its hanging node constraints;
   * - the operator U ↦ (μ_i ∫ ∇u_ih·∇φ)_φ of (4.5), block diagonal in the
   *   membranes, and the loads (∫ f_i φ)_φ, both condensed with the hanging
   *   node constraints (boundary DoFs not eliminated: their values enter
   *   the terms of the interior vertices next to ∂ω);
   * - the cell loads F_1K, F_2K (and the mean and oscillation of each load
   *   on K) in the layout of CellSystem::copy_loads(), so that no system
   *   evaluates the data again on this mesh;
   * - the diagonal Σ_K A_K(j, j) of the Laplacian, not condensed;
   * - the set V_h of the unconstrained interior vertices with, for each
   *   locally owned one, d_a = ∫ φ_a (the lumped mass of (4.17); with
   *   hanging nodes the row sum of the constrained mass matrix), ∫|∇φ_a|²
   *   and the l1 norm of its row of the condensed Laplacian.
   */
  template <int dim>
  class MeshOperator : public Subscriptor
  {
  public:
    using VectorType = TrilinosWrappers::MPI::Vector;

    /** One vertex a of V_h: its two DoFs and the data of its dual cell. */
    struct Vertex
    {
      /** DoF of u1 (index 0) and of u2 (index 1) at a. */
      std::array<types::global_dof_index, 2> dof;
      /** d_a = ∫ φ_a, the measure of D_a on triangles (4.17). */
      double dual_cell_measure;
      /**
       * Σ_K A_K(a, a) = ∫ |∇φ_a|² for the hat function of a without the
       * shares of the hanging vertices it constrains (laplace_diagonal()):
       * the scale of the stiffness matrix at a.
       */
      double stiffness_diagonal;
      /**
       * Σ_b |A_ab|, the l1 norm of the row of a in the Laplacian A
       * condensed with the hanging node constraints (where the hat function
       * of a takes its share of those of the hanging vertices it
       * constrains): half of it is the divisor of the projected Jacobi
       * sweeps of ActiveSet.
       */
      double stiffness_row_l1_norm;
    };

    MeshOperator(const Discretization<dim> &discretization,
                 const ProblemData<dim>    &data);

    /**
     * Assemble the operator, the loads and d_a on the mesh of
     * @p dof_handler, and find V_h. The arguments are kept by reference
     * until the next call: they are the mesh data of the caller.
     */
    void
    reinit(const DoFHandler<dim>           &dof_handler,
           const AffineConstraints<double> &hanging_node_constraints,
           const IndexSet                  &locally_owned_dofs,
           const IndexSet                  &locally_relevant_dofs,
           const MPI_Comm                   mpi_communicator);

    const DoFHandler<dim> &
    get_dof_handler() const;
    const AffineConstraints<double> &
    hanging_node_constraints() const;
    const IndexSet &
    locally_owned_dofs() const;
    const IndexSet &
    locally_relevant_dofs() const;
    MPI_Comm
    get_mpi_communicator() const;

    /** μ_i A on each membrane (condensed with the hanging node constraints). */
    const TrilinosWrappers::SparseMatrix &
    stiffness_matrix() const;

    /**
     * Σ_K A_K(j, j) = ∫ |∇φ_j|² at each locally owned DoF j, summed over
     * its cells without μ_i and without condensation: the diagonal entry
     * that AffineConstraints leaves in the row of a constrained DoF j when
     * it assembles the Laplacian (the systems of the active set method
     * eliminate the rows of constrained DoFs so).
     */
    const VectorType &
    laplace_diagonal() const;

    /** The loads (∫ f_i φ)_φ, condensed likewise. */
    const VectorType &
    load_vector() const;

    /** The loads F_1K, F_2K of the locally owned cell @p cell. */
    const double *
    cell_loads(
      const typename DoFHandler<dim>::active_cell_iterator &cell) const;

    /**
     * The mean f̄_iK and the oscillation ∫_K (f_i − f̄_iK)² of load @p i on
     * the locally owned cell @p cell.
     */
    std::pair<double, double>
    load_mean_and_oscillation(
      const typename DoFHandler<dim>::active_cell_iterator &cell,
      const unsigned int                                    i) const;

    /** The locally owned vertices of V_h, by increasing u1 DoF. */
    const std::vector<Vertex> &
    vertices() const;

    /**
     * The positions of the DoFs (u1, u2) of vertices() in the local storage
     * of a vector of the locally owned DoFs (all such vectors share one
     * layout): reading them there needs no search per entry.
     */
    const std::vector<std::array<int, 2>> &
    local_positions() const;

    /**
     * The DoFs (u1, u2) of the locally relevant vertices of V_h: those of
     * the locally owned and ghost cells.
     */
    const std::vector<std::array<types::global_dof_index, 2>> &
    locally_relevant_vertices() const;

    /**
     * Whether the u1 DoF @p a (locally relevant) belongs to an interior
     * vertex, of V_h or hanging: the vertices whose dual cells make up ω_h.
     */
    bool
    is_interior_vertex(const types::global_dof_index a) const;

  private:
    /**
     * The cell loop: the operator, the loads, d_a, ∫|∇φ_a|² and the cell
     * loads, condensed with the hanging node constraints.
     */
    void
    assemble(VectorType &dual_cell_measure, VectorType &stiffness_diagonal);

    /** V_h and its data, from the vectors that assemble() fills. */
    void
    find_vertices(const VectorType &dual_cell_measure,
                  const VectorType &stiffness_diagonal);

    const Discretization<dim> &discretization;
    const ProblemData<dim>    &data;

    SmartPointer<const DoFHandler<dim>>           dof_handler;
    SmartPointer<const AffineConstraints<double>> constraints;
    const IndexSet                               *owned_dofs;
    const IndexSet                               *relevant_dofs;
    MPI_Comm                                      mpi_communicator;

    TrilinosWrappers::SparseMatrix matrix;
    VectorType                     diagonal;
    VectorType                     loads;
    /**
     * The cell loads as CellSystem::copy_loads() writes them, loads_per_cell
     * = 2 n_v + 4 numbers per cell from active_cell_index() · loads_per_cell
     * on (n_v hat functions per cell).
     */
    std::vector<double> loads_of_cells;
    unsigned int        loads_per_cell;

    std::vector<Vertex>                                 interior_vertices;
    std::vector<std::array<int, 2>>                     positions;
    std::vector<std::array<types::global_dof_index, 2>> relevant_vertices;
    IndexSet                                            interior_vertex_dofs;
  };
} // namespace membranes

#endif
