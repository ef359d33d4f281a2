#ifndef membranes_active_set_system_h
#define membranes_active_set_system_h

#include <deal.II/base/function.h>
#include <deal.II/base/index_set.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/cell_system.h>
#include <membranes/discrete_action.h>
#include <membranes/discretization.h>
#include <membranes/linear_solver.h>
#include <membranes/parameters.h>
#include <membranes/problem_data.h>
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
    double       assembly_time     = 0; ///< Seconds spent assembling.
    double       solve_time = 0; ///< Seconds in linear solves and updates.
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
   * are lines of an AffineConstraints object and the condensed system is
   * symmetric positive definite: this class holds its matrix, right-hand
   * side and LinearSolver, and the steps both ways share. Every method adds
   * the time it spends assembling and solving, and its CG iterations, to
   * the ActiveSetStatistics it is given.
   */
  template <int dim>
  class ActiveSetSystem
  {
  public:
    using VectorType = TrilinosWrappers::MPI::Vector;

    virtual ~ActiveSetSystem() = default;

    /**
     * Matrices, sparsity patterns and constraints for the current mesh of
     * @p dof_handler (the DoFHandler of (u1, u2)), with room for any
     * active set on the vertices of @p action.
     */
    virtual void
    setup(const DoFHandler<dim>     &dof_handler,
          const IndexSet            &locally_owned_dofs,
          const IndexSet            &locally_relevant_dofs,
          const DiscreteAction<dim> &action) = 0;

    /**
     * Before the first iteration on a mesh, from the initial guess
     * @p solution: the work that does not depend on the active set, solved
     * with a residual norm of at most @p tolerance.
     */
    virtual void
    prepare(const VectorType    &solution,
            const double         tolerance,
            ActiveSetStatistics &statistics) = 0;

    /**
     * Solve the linear problem for @p active_set (u1 DoFs of the active
     * locally relevant vertices of @p action, so that every process knows
     * the constraints of the cells it assembles), starting from
     * @p solution, with a residual
     * norm of at most @p tolerance. On return @p solution holds (u1h, u2h),
     * constraints included.
     */
    virtual void
    solve(const DiscreteAction<dim> &action,
          const IndexSet            &active_set,
          VectorType                &solution,
          const double               tolerance,
          ActiveSetStatistics       &statistics) = 0;

    /** The method and its linear solver, e.g. "coupled, direct". */
    std::string
    description() const;

  protected:
    ActiveSetSystem(const std::string         &method,
                    const Parameters::Solver  &parameters,
                    const Discretization<dim> &discretization,
                    const ProblemData<dim>    &data,
                    const MPI_Comm             mpi_communicator);

    /**
     * Add @p boundary_values, interpolated at the boundary vertices of
     * @p dof_handler, on all of ∂ω to @p constraints.
     */
    void
    add_boundary_values(const DoFHandler<dim>     &dof_handler,
                        const Function<dim>       &boundary_values,
                        AffineConstraints<double> &constraints) const;

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
     * Assemble the system, condensed with @p constraints: on every locally
     * owned cell of @p dof_handler (the DoFHandler of (u1, u2)), CellSystem
     * is computed and `local_system(cell, cell_system)` returns the tuple
     * (cell matrix, cell right-hand side, their DoF indices) to add.
     */
    template <typename LocalSystem>
    void
    assemble_system(const DoFHandler<dim>           &dof_handler,
                    const AffineConstraints<double> &constraints,
                    const LocalSystem               &local_system);

    /**
     * Solve the assembled system for @p x (starting from it) to a residual
     * norm of @p tolerance, then set its constrained entries.
     */
    void
    solve_linear_system(const AffineConstraints<double> &constraints,
                        VectorType                      &x,
                        const double                     tolerance,
                        ActiveSetStatistics             &statistics);

    const Discretization<dim> &discretization;
    const ProblemData<dim>    &data;
    const MPI_Comm             mpi_communicator;

    TrilinosWrappers::SparseMatrix system_matrix;
    VectorType                     system_rhs;

  private:
    const std::string method;
    LinearSolver<dim> linear_solver;
  };



  template <int dim>
  template <typename LocalSystem>
  void
  ActiveSetSystem<dim>::assemble_system(
    const DoFHandler<dim>           &dof_handler,
    const AffineConstraints<double> &constraints,
    const LocalSystem               &local_system)
  {
    system_matrix = 0;
    system_rhs    = 0;

    CellSystem<dim> cell_system(discretization, data);
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          cell_system.reinit(cell);
          const auto [matrix, rhs, dof_indices] =
            local_system(cell, cell_system);
          constraints.distribute_local_to_global(
            matrix, rhs, dof_indices, system_matrix, system_rhs);
        }
    system_matrix.compress(VectorOperation::add);
    system_rhs.compress(VectorOperation::add);
  }
} // namespace membranes

#endif
