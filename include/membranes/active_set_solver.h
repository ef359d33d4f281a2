#ifndef membranes_active_set_solver_h
#define membranes_active_set_solver_h

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/index_set.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/active_set_system.h>
#include <membranes/discrete_action.h>
#include <membranes/discretization.h>
#include <membranes/parameters.h>
#include <membranes/problem_data.h>
#include <memory>

namespace membranes
{
  using namespace dealii;

  /**
   * The primal-dual active set method (a semismooth Newton method) for the
   * discrete variational inequality (3.4), as in deal.II's step-41 but for
   * the pair (u1, u2).
   *
   * With W_a = u1h(a) − u2h(a) and the nodal multiplier Λ_a = λ_a of (4.5),
   * the active set is
   *
   *   A = { a ∈ V_h : Λ_a − c_a W_a > 0 },   c_a = μ̄ ∫|∇φ_a|² / ∫φ_a,
   *
   * where c_a has the units of Λ/W (μ̄ = μ1μ2/(μ1+μ2) is the tension of the
   * obstacle problem for w = u1 − u2, SPEC §1), so the test does not depend
   * on how the data are scaled. Each iteration solves the linear problem
   * W_a = 0 on A, Λ_a = 0 off A (ActiveSetSystem): on the coupled pair
   * (CoupledSystem, `Solver/Method = coupled`) or on the sum and the
   * difference of the membranes (DecoupledSystem, `decoupled`). Both give
   * the same iterate; λ_a, the next active set and the KKT residual are
   * computed from it in the same way.
   *
   * The iteration stops when the active set repeats and the relative KKT
   * residual (see kkt_residual()) is at most `Tolerance`. If that does not
   * happen within `Max active set iterations`, solve() throws.
   */
  template <int dim>
  class ActiveSetSolver
  {
  public:
    using VectorType = TrilinosWrappers::MPI::Vector;
    using Statistics = ActiveSetStatistics;

    ActiveSetSolver(const Parameters::Solver  &parameters,
                    const Discretization<dim> &discretization,
                    const ProblemData<dim>    &data,
                    const ConditionalOStream  &pcout,
                    const MPI_Comm             mpi_communicator);

    /** The linear systems for the current mesh (ActiveSetSystem::setup()). */
    void
    setup(const DoFHandler<dim>     &dof_handler,
          const IndexSet            &locally_owned_dofs,
          const IndexSet            &locally_relevant_dofs,
          const DiscreteAction<dim> &action);

    /**
     * Run the active set method from the initial guess @p solution (locally
     * owned entries) and the initial active set @p active_set (u1 DoFs of
     * active vertices). On return both hold the converged iterate, and
     * @p action holds λ_a for it.
     */
    Statistics
    solve(DiscreteAction<dim> &action,
          VectorType          &solution,
          IndexSet            &active_set);

    /**
     * The active set {a : Λ_a − c_a W_a > 0} of a new mesh, for the previous
     * mesh's solution and λ_h interpolated onto it (nested iteration):
     * vertices between two active ones stay active, the others are decided
     * by the same test as in the iteration.
     */
    IndexSet
    initial_active_set(const DiscreteAction<dim> &action,
                       const VectorType          &ghosted_solution,
                       const VectorType          &ghosted_lambda_h) const;

    /**
     * The relative KKT residual of an iterate, the largest of
     * - equilibrium: ‖r‖₂ / F₂ with r_a = λ_a d_a from both membranes on
     *   inactive vertices and the difference of the two on active ones;
     * - primal feasibility: max(−W_a)⁺ / max|U|;
     * - dual feasibility: max(−λ_a d_a)⁺ / F_∞;
     * - complementarity: max |λ_a d_a W_a| / (F_∞ max|U|);
     * with F₂, F_∞ the force scales of DiscreteAction.
     */
    double
    kkt_residual(const DiscreteAction<dim> &action,
                 const VectorType          &ghosted_solution,
                 const IndexSet            &active_set) const;

  private:
    /**
     * @p active_set (owned vertices) extended to the locally relevant
     * vertices of @p action by a ghost exchange: the owner of each vertex
     * decides, every process that shares a cell with it learns the
     * decision.
     */
    IndexSet
    locally_relevant_active_set(const DiscreteAction<dim> &action,
                                const IndexSet            &active_set) const;

    /**
     * {a : Λ_a − c_a W_a > 0} for the iterate @p ghosted_solution, with
     * Λ_a = @p lambda(k) for the k-th vertex of @p action.
     */
    template <typename LambdaOfVertex>
    IndexSet
    active_set_for(const DiscreteAction<dim> &action,
                   const VectorType          &ghosted_solution,
                   const LambdaOfVertex      &lambda) const;

    const Parameters::Solver &parameters;
    const ProblemData<dim>   &data;
    const ConditionalOStream &pcout;
    const MPI_Comm            mpi_communicator;

    SmartPointer<const DoFHandler<dim>> dof_handler;
    IndexSet                            locally_owned_dofs;
    IndexSet                            locally_relevant_dofs;

    /** The linear problem of one iteration, coupled or decoupled. */
    std::unique_ptr<ActiveSetSystem<dim>> system;
  };
} // namespace membranes

#endif
