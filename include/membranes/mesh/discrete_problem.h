#ifndef membranes_discrete_problem_h
#define membranes_discrete_problem_h

#include <array>
#include <deal.II/base/function.h>
#include <deal.II/base/index_set.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/dual_mesh/dual_mesh.h>
#include <membranes/mesh/discretization.h>
#include <membranes/scene/problem_data.h>
#include <utility>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The discrete problem (3.4) on one mesh without its contact condition:
   * the Laplacian and the loads of the two membranes on the scalar P1/Q1
   * space, and the vertices V_h that carry λ_a with the measures d_a of
   * their dual cells. It is built once per mesh
   * (MembraneProblem::setup_system()) and passed, as a const reference
   * argument, to everything that works on the mesh: DiscreteAction (the
   * postprocessing (4.5)), the linear systems of the active set method
   * (CoupledSystem, DecoupledSystem), the ActiveSet and the estimators. It
   * holds no reference to the DoFHandler it was built on, nor to the
   * DualMesh it took the interior vertices from; what needs them gets them
   * from their owner, MembraneProblem.
   *
   * Both membranes live on one mesh with the same scalar element, so their
   * Laplacians are one matrix A and the operator of membrane i is μ_i A.
   * One DoFHandler of the scalar element numbers the vertices; membrane i
   * is block i of the vectors of the mesh (Discretization), so a vertex has
   * one DoF, the same in both blocks.
   *
   * It holds
   * - A = (∫ ∇φ_a·∇φ_b), condensed by AffineConstraints with the hanging
   *   node constraints and the boundary values: the rows and columns of
   *   constrained DoFs eliminated, Σ_K A_K(j, j) on their diagonal. It is
   *   the matrix of S in DecoupledSystem, whose solve_s() builds an AMG
   *   hierarchy from it, the matrix CG applies to W through the projection
   *   Π, and the operator of λ_a in DiscreteAction. The other hierarchy
   *   of the decoupled method on a mesh is built from the condensed matrix
   *   of W (μ̄ A with the rows and columns of the active vertices
   *   eliminated; anew only when CG slows down), and CoupledSystem builds
   *   one from its system matrix on every iteration;
   * - the loads F_i = (∫ f_i φ_a), condensed with the hanging node
   *   constraints, and the lifted loads F_i − μ_i A_{·,∂} g_i, condensed
   *   like A with the boundary values g_1 = g, g_2 = g2: the right-hand
   *   sides of membrane i. Their difference is the boundary column part of
   *   μ_i A U_i, so that μ_i (A U_i)_a with the columns of ∂ω is
   *   stiffness_term() without a second matrix;
   * - the mean f̄_iK and the oscillation ∫_K (f_i − f̄_iK)² of each load on
   *   each locally owned cell K, the data terms of the residual estimator,
   *   from the evaluations of the loads of this assembly;
   * - the set V_h of the unconstrained interior vertices with, for each
   *   locally owned one, d_a = ∫ φ_a (the lumped mass of (4.17); with
   *   hanging nodes the row sum of the constrained mass matrix), ∫|∇φ_a|²
   *   and the l1 norm of its row of A.
   */
  template <int dim>
  class DiscreteProblem
  {
  public:
    using VectorType = TrilinosWrappers::MPI::Vector;

    /** One vertex a of V_h: its DoF and the data of its dual cell. */
    struct Vertex
    {
      /** The DoF of a, the same in both blocks (u1h(a), u2h(a)). */
      types::global_dof_index dof;
      /** d_a = ∫ φ_a, the measure of D_a on triangles (4.17). */
      double dual_cell_measure;
      /**
       * Σ_K A_K(a, a) = ∫ |∇φ_a|² for the hat function of a without the
       * shares of the hanging vertices it constrains: the scale of the
       * stiffness matrix at a.
       */
      double stiffness_diagonal;
      /**
       * Σ_b |A_ab|, the l1 norm of the row of a in A (condensed with the
       * hanging node constraints and the boundary values): half of it is
       * the divisor of the projected Jacobi sweeps of ActiveSetPrediction.
       */
      double stiffness_row_l1_norm;
    };

    DiscreteProblem(const Discretization<dim> &discretization,
                    const ProblemData<dim>    &data);

    /**
     * The constraints of both membranes, A, the loads and d_a on the mesh
     * of @p dof_handler, whose locally relevant DoFs (those of the owned
     * and ghost cells) are @p locally_relevant_dofs and whose hanging node
     * constraints are @p hanging_node_constraints, and V_h from the
     * interior vertices of @p dual_mesh.
     */
    void
    reinit(const DoFHandler<dim>           &dof_handler,
           const IndexSet                  &locally_relevant_dofs,
           const AffineConstraints<double> &hanging_node_constraints,
           const DualMesh<dim>             &dual_mesh,
           const MPI_Comm                   mpi_communicator);

    /**
     * The constraints of membrane @p i on every iteration of this mesh:
     * the hanging node constraints and the boundary values g_1 = g,
     * g_2 = g2 interpolated at the boundary DoFs (a hanging vertex on ∂ω
     * keeps its hanging node constraint). Both membranes constrain the
     * same lines with the same weights; only the inhomogeneities differ.
     */
    const AffineConstraints<double> &
    constraints(const unsigned int i) const
    {
      return membrane_constraints[i];
    }

    MPI_Comm
    get_mpi_communicator() const
    {
      return mpi_communicator;
    }
    /**
     * The index sets of the step-40 layout: the locally owned DoFs of the
     * mesh, and those of the owned and ghost cells. Every block of a vector
     * of the mesh has them.
     */
    const IndexSet &
    locally_owned_dofs() const
    {
      return owned_dofs;
    }
    const IndexSet &
    locally_relevant_dofs() const
    {
      return relevant_dofs;
    }

    /** A, condensed with the hanging node constraints and boundary values. */
    const TrilinosWrappers::SparseMatrix &
    laplace_matrix() const
    {
      return matrix;
    }

    /** F_i, condensed with the hanging node constraints. */
    const VectorType &
    loads(const unsigned int i) const
    {
      return load_vectors[i];
    }

    /** F_i − μ_i A_{·,∂} g_i, condensed as A (zero in constrained rows). */
    const VectorType &
    lifted_loads(const unsigned int i) const
    {
      return lifted_load_vectors[i];
    }

    /**
     * The mean f̄_iK and the oscillation ∫_K (f_i − f̄_iK)² of load @p i on
     * the locally owned cell @p cell.
     */
    std::pair<double, double>
    load_mean_and_oscillation(
      const typename DoFHandler<dim>::active_cell_iterator &cell,
      const unsigned int                                    i) const;

    /** The locally owned vertices of V_h, by increasing DoF. */
    const std::vector<Vertex> &
    vertices() const
    {
      return interior_vertices;
    }

    /**
     * W_a = u1h(a) − u2h(a) at the locally owned vertex k of vertices(),
     * read from the local storage of the two blocks of @p solution at the
     * position of the vertex: no search per entry. @p solution holds the
     * locally owned DoFs alone (a ghosted vector stores its ghost entries
     * among the owned ones, at other positions).
     */
    double
    nodal_w(const unsigned int                        k,
            const TrilinosWrappers::MPI::BlockVector &solution) const
    {
      Assert(!solution.has_ghost_elements(),
             ExcMessage("nodal_w() reads a vector of the locally owned "
                        "DoFs by position, not a ghosted vector."));
      const unsigned int p = positions[k];
      return solution.block(0).begin()[p] - solution.block(1).begin()[p];
    }

    /**
     * The positions of the DoFs of vertices() in the local storage of a
     * vector of the locally owned DoFs (every block of a vector of the mesh
     * has that layout): reading them there needs no search per entry. A
     * ghosted vector has another layout; the readers assert that they get
     * none.
     */
    const std::vector<unsigned int> &
    local_positions() const
    {
      return positions;
    }

    /**
     * The DoFs of the locally relevant vertices of V_h: those of the
     * locally owned and ghost cells.
     */
    const std::vector<types::global_dof_index> &
    locally_relevant_vertices() const
    {
      return relevant_vertices;
    }

  private:
    /**
     * constraints(0) and constraints(1) of @p dof_handler with its
     * @p hanging_node_constraints.
     */
    void
    make_constraints(const DoFHandler<dim>           &dof_handler,
                     const AffineConstraints<double> &hanging_node_constraints);

    /**
     * The cell loop: A, the loads, d_a and ∫|∇φ_a|², each condensed by
     * distribute_local_to_global with its constraints, and the
     * load_statistics of each cell.
     */
    void
    assemble(const DoFHandler<dim>           &dof_handler,
             const AffineConstraints<double> &hanging_node_constraints,
             VectorType                      &dual_cell_measure,
             VectorType                      &stiffness_diagonal);

    /** V_h and its data, from the vectors that assemble() fills. */
    void
    find_vertices(const DualMesh<dim>             &dual_mesh,
                  const AffineConstraints<double> &hanging_node_constraints,
                  const VectorType                &dual_cell_measure,
                  const VectorType                &stiffness_diagonal);

    const Discretization<dim> &discretization;
    const ProblemData<dim>    &data;

    MPI_Comm mpi_communicator;
    IndexSet owned_dofs, relevant_dofs;

    std::array<AffineConstraints<double>, 2> membrane_constraints;
    TrilinosWrappers::SparseMatrix           matrix;
    std::array<VectorType, 2>                load_vectors;
    std::array<VectorType, 2>                lifted_load_vectors;
    /**
     * f̄_1K, f̄_2K, then ∫_K (f_1 − f̄_1K)², ∫_K (f_2 − f̄_2K)² of each
     * cell, by active_cell_index().
     */
    std::vector<std::array<double, 4>> load_statistics;

    std::vector<Vertex>                  interior_vertices;
    std::vector<unsigned int>            positions;
    std::vector<types::global_dof_index> relevant_vertices;
  };
} // namespace membranes

#endif
