#ifndef membranes_active_set_system_h
#define membranes_active_set_system_h

#include <deal.II/base/function.h>
#include <deal.II/base/index_set.h>
#include <deal.II/base/timer.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/cell_system.h>
#include <membranes/discretization.h>
#include <membranes/linear_solver.h>
#include <membranes/mesh_operator.h>
#include <membranes/parameters.h>
#include <membranes/problem_data.h>
#include <optional>
#include <string>

namespace membranes
{
  using namespace dealii;

  /** What one solve of the active set method did. */
  struct ActiveSetStatistics
  {
    unsigned int iterations        = 0; ///< Active set iterations.
    unsigned int linear_iterations = 0; ///< CG iterations, summed.
    double       kkt_residual      = 0; ///< Relative KKT residual at the end.
    /**
     * With balanced stopping: the estimates η_lin and η_alg of
     * ActiveSetSolver at the end, in the energy norm.
     */
    std::optional<double> linearization_estimate, algebraic_estimate;
  };



  /**
   * The residual norms at which the linear solves of one iteration stop.
   *
   * The linear problem of an iteration splits exactly (DecoupledSystem)
   * into the problem for s = μ1 u1 + μ2 u2, whose residual at a vertex is
   * r_S,a = (λ_1a − λ_2a) d_a (Prop. 12), and the obstacle problem for
   * w = u1 − u2, whose residual at an inactive vertex is r_W,a = λ_a d_a
   * (DiscreteAction::lambda()). The two are of different sizes,
   * forces of tension μ1 + μ2 and μ̄ = μ1μ2/(μ1 + μ2), eight orders apart
   * for a tension ratio of 1e8; each gets its own bound on the Euclidean
   * norm of its residual, which also bounds each nodal residual.
   */
  struct LinearTolerances
  {
    double sum;     ///< Bound of ‖r_S‖₂.
    double contact; ///< Bound of ‖r_W‖₂ (inactive vertices).
  };



  /**
   * The linear problem of one iteration of the primal-dual active set
   * method (ActiveSetSolver) for an active set A ⊂ V_h: find (u1h, u2h)
   * with u1h = g_h, u2h = g2_h on ∂ω, the hanging node constraints,
   *
   *   W_a = u1h(a) − u2h(a) = 0  on A,     λ_a = 0  on V_h \ A,
   *
   * and on A the sum of the equations of the two membranes at a (λ_1a =
   * λ_2a, the test function (φ_a, φ_a) of Prop. 12). Two ways to solve it
   * give the same iterate: CoupledSystem on the pair (u1h, u2h), and, for
   * constant tensions, DecoupledSystem on s = μ1 u1h + μ2 u2h and
   * w = u1h − u2h.
   *
   * Either way the constraints (hanging nodes, boundary values, contact)
   * are those of an AffineConstraints object and the condensed system is
   * symmetric positive definite. What does not depend on the active set
   * (the hanging node and boundary constraints, the loads, and for the
   * decoupled system the whole operator) is built once per mesh, in setup()
   * or on the first solve() of a mesh; solve() otherwise only does what the
   * active set changes. This
   * class holds the matrix and right-hand side of the iteration and the
   * LinearSolver, and the steps both ways share. Every method times its
   * assembly and its linear solves in the sections "assembly" and "solve"
   * of the TimerOutput it is given, and adds its CG iterations to the
   * ActiveSetStatistics it is given.
   */
  template <int dim>
  class ActiveSetSystem
  {
  public:
    using VectorType = TrilinosWrappers::MPI::Vector;

    virtual ~ActiveSetSystem() = default;

    /**
     * Matrices, sparsity patterns and the constraints that do not depend on
     * the active set, for the mesh of @p mesh_operator, with room for any
     * active set on its vertices.
     */
    virtual void
    setup(const MeshOperator<dim> &mesh_operator) = 0;

    /**
     * Solve the linear problem for @p active_set (u1 DoFs of the active
     * locally relevant vertices, ActiveSet::locally_relevant(), so that
     * every process knows the constraints of the cells it assembles),
     * starting from @p solution, to the residual norms @p tolerances. On
     * return @p solution holds (u1h, u2h), constraints included.
     */
    virtual void
    solve(const IndexSet         &active_set,
          VectorType             &solution,
          const LinearTolerances &tolerances,
          ActiveSetStatistics    &statistics) = 0;

    /**
     * Free the matrices, vectors and the AMG hierarchy of this mesh once the
     * active set method has finished on it, so that the postprocessing, the
     * estimators and the refinement run without them; setup() makes them
     * anew for the next mesh.
     */
    virtual void
    clear();

    /** The method and its linear solver, e.g. "coupled, direct". */
    std::string
    description() const;

  protected:
    ActiveSetSystem(const std::string         &method,
                    const Parameters::Solver  &parameters,
                    const Discretization<dim> &discretization,
                    const ProblemData<dim>    &data,
                    TimerOutput               &timer,
                    const MPI_Comm             mpi_communicator);

    /**
     * @p hanging_node_constraints (closed) of @p dof_handler and
     * @p boundary_values, interpolated at its boundary vertices on all of
     * ∂ω, into @p constraints (closed): what is constrained on every
     * iteration of a mesh.
     */
    void
    make_mesh_constraints(
      const DoFHandler<dim>           &dof_handler,
      const AffineConstraints<double> &hanging_node_constraints,
      const Function<dim>             &boundary_values,
      AffineConstraints<double>       &constraints) const;

    /**
     * Choose the linear solver for @p dof_handler, and size the matrix and
     * right-hand side with the sparsity pattern condensed with
     * @p constraints (constrained rows and columns left out): room for any
     * further constraint that only removes couplings.
     */
    void
    reinit_linear_system(const DoFHandler<dim>           &dof_handler,
                         const AffineConstraints<double> &constraints,
                         const IndexSet                  &locally_owned_dofs,
                         const IndexSet &locally_relevant_dofs);

    /**
     * Solve `matrix x = rhs` for @p x (starting from it) to a residual norm
     * of @p tolerance, then set its constrained entries. The AMG hierarchy
     * is built from @p mesh_matrix if given (a matrix unchanged on this
     * mesh, kept across solves: LinearSolver), from @p matrix for this
     * solve alone otherwise.
     *
     * With @p scaling, the diagonal D of a symmetric scaling (locally
     * owned entries), @p matrix and @p rhs are D K D and D b of a system
     * K x = b: the solve is for y = D⁻¹x, so that the residual norm is that
     * of D(b − K x); @p x is given and returned unscaled.
     */
    void
    solve_linear_system(
      const TrilinosWrappers::SparseMatrix &matrix,
      const VectorType                     &rhs,
      const AffineConstraints<double>      &constraints,
      VectorType                           &x,
      const double                          tolerance,
      ActiveSetStatistics                  &statistics,
      const TrilinosWrappers::SparseMatrix *mesh_matrix = nullptr,
      const VectorType                     *scaling     = nullptr);

    /**
     * Whether the AMG hierarchy of a mesh matrix given to an earlier
     * solve_linear_system() on this mesh is kept for the next one.
     */
    bool
    has_mesh_preconditioner() const;

    const Discretization<dim> &discretization;
    const ProblemData<dim>    &data;
    TimerOutput               &timer;
    const MPI_Comm             mpi_communicator;

    /** The mesh, its index sets, constraints, operator and loads. */
    SmartPointer<const MeshOperator<dim>> mesh;

    TrilinosWrappers::SparseMatrix system_matrix;
    VectorType                     system_rhs;

  private:
    const std::string method;
    LinearSolver<dim> linear_solver;
  };
} // namespace membranes

#endif
