#ifndef membranes_active_set_system_h
#define membranes_active_set_system_h

#include <deal.II/base/index_set.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/discrete_action.h>
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
   * λ_2a, the test function (φ_a, φ_a) of Prop. 12). CoupledSystem solves
   * it on the pair (u1h, u2h).
   *
   * Every method adds the time it spends assembling and solving, and its CG
   * iterations, to the ActiveSetStatistics it is given.
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
     * vertices of @p action), starting from @p solution, with a residual
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
    virtual std::string
    description() const = 0;
  };
} // namespace membranes

#endif
