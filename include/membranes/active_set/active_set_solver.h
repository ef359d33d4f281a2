#ifndef membranes_active_set_solver_h
#define membranes_active_set_solver_h

#include <array>
#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/timer.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <membranes/active_set/active_set.h>
#include <membranes/active_set/active_set_prediction.h>
#include <membranes/active_set/kkt_defects.h>
#include <membranes/dual_mesh/discrete_action.h>
#include <membranes/mesh/discrete_problem.h>
#include <membranes/mesh/discretization.h>
#include <membranes/scene/parameters.h>
#include <membranes/scene/problem_data.h>
#include <memory>
#include <optional>

namespace membranes
{
  using namespace dealii;

  /** What one solve of the active set method did. */
  struct ActiveSetStatistics
  {
    unsigned int iterations        = 0; ///< Active set iterations.
    unsigned int linear_iterations = 0; ///< CG iterations, summed.
    double       kkt_residual      = 0; ///< Relative KKT residual at the end.
    KKTDefects   kkt_defects;           ///< The KKT defects at the end.
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



  template <int dim>
  class ActiveSetSystem;



  /**
   * The active set method stopped without a converged iterate: at
   * `Solver/Max active set iterations`, or when the active set no longer
   * changes but the relative KKT residual stays above `Solver/Tolerance`.
   * The message says which and the residual reached; the solution and the
   * active set passed to ActiveSetSolver::solve() hold the last iterate.
   * The decision is made on global quantities: every process throws it.
   */
  class ActiveSetNotConverged : public Parameters::CollectiveError
  {
  public:
    using Parameters::CollectiveError::CollectiveError;
  };



  /**
   * The primal-dual active set method (a semismooth Newton method) for the
   * discrete variational inequality (3.4), as in deal.II's step-41 but for
   * the pair (u1, u2).
   *
   * The loop of solve() is that of step-41: solve the linear problem of the
   * active set A (ActiveSetSystem: W_a = u1h(a) − u2h(a) = 0 on A, λ_a = 0
   * off A; on the coupled pair, CoupledSystem, `Solver/Method = coupled`,
   * or on the sum and the difference of the membranes, DecoupledSystem,
   * `decoupled`; both give the same iterate), compute λ_a by (4.5)
   * (DiscreteAction), test the KKT conditions, and move to the next active
   * set (ActiveSet, which holds the test Λ_a − c_a W_a > 0, its band of
   * indifference and the remedy against cycling), by the changes that the
   * test wants on a predicted iterate (ActiveSetPrediction) unless a cycle
   * has been detected on the mesh or the prediction wants none.
   *
   * <b>Convergence.</b> The iteration stops when no vertex wants to change
   * and the relative KKT residual (KKTDefects::relative_residual()) is at
   * most `Tolerance`.
   * The linear solves are tied to that test (LinearTolerances): the problem
   * for s and the obstacle problem for w each stop at the residual norm
   * `Tolerance` times their own force scale, F_∞ and F^w_∞ of
   * DiscreteAction, and a bound on the Euclidean norm bounds every nodal
   * residual. An iterate on the right active set therefore meets the
   * equilibrium, dual feasibility and complementarity parts of the test by
   * construction, on meshes of any size and for any tension ratio (a bound
   * relative to the Euclidean norm of all forces lets single residuals grow
   * like the square root of the number of vertices, and one relative to the
   * stiffer membrane leaves the obstacle problem of a tension ratio 1e8
   * unresolved by eight orders). If the active set has settled but the test
   * is not met (round-off, or vertices kept in the band), the same active
   * set is solved again with residuals settled_tightening times smaller
   * (by the decoupled method from the same AMG hierarchy); if that does not
   * decrease the residual, or at `Max active set iterations`, solve() throws
   * ActiveSetNotConverged with the residual reached.
   *
   * <b>Balanced stopping</b> (`Solver/Stopping = balanced`). On a mesh whose
   * discretization error η̃ in the energy norm |||v|||² = Σ_i μ_i |v_i|²_{H1}
   * is expected, the method stops as the adaptive inexact semismooth Newton
   * method of Dabaghi, Martin and Vohralík (SIAM J. Sci. Comput. 42, 2020):
   * once the linearization and algebraic errors of the iterate are below
   * the fraction γ = `Balance fraction` of η̃,
   *
   *   η_lin + η_alg ≤ γ η̃,
   *
   * or once the active set has settled; and each linear solve stops once
   * its algebraic error is below γ η̃ / 2. Iterations beyond that improve
   * the discrete solution by less than the mesh can resolve. Both measures
   * are in the units of the energy norm (of the estimator):
   * - η_alg bounds the energy norm of the error left by the linear
   *   solver, sup ρ(v) / |||v||| for the residual ρ of the equilibrium
   *   part of the KKT conditions (ρ_ia = λ_ia d_a of membrane i on inactive
   *   vertices, ρ_a = (λ_1a − λ_2a) d_a of both on active ones). With the
   *   lumped mass d_a, |ρ(v)| ≤ (Σ ρ²/(m d))^{1/2} (Σ_i μ_i Σ_a d_a
   * v_ia²)^{1/2} (m = μ_i, or μ1 + μ2 on active vertices), the lumped L² norm
   * is at most c_M times the L² norm (c_M = 2 on triangles, 3 on
   *   quadrilaterals: the eigenvalues of the element mass matrices), and
   *   ‖v‖ ≤ C_F |v|_{H1} (Friedrichs; C_F = 1/(π (1/a² + 1/b²)^{1/2}), the
   *   constant of the bounding box a × b of the mesh, which contains ω), so
   *     η_alg = c_M C_F (Σ_a Σ_i ρ_ia² / (m_ia d_a))^{1/2}.
   *   The same bound with d_a ≥ d_min and m ≥ μ̄ turns γ η̃ / 2 into the
   *   Euclidean residual norm at which CG stops,
   *   γ η̃ (μ̄ d_min)^{1/2} / (2 c_M C_F) (never below the tolerance of exact
   *   stopping), for the coupled system and for S and W of the decoupled
   *   one (their errors add up as |||e|||² = |e_S|²/(μ1 + μ2) + μ̄ |e_W|²).
   *   The bound is sharp for smooth residuals and pessimistic, by up to
   *   1/h, for oscillating ones: the CG tolerance errs on the safe side.
   * - η_lin measures how far the active set is from the right one: the
   *   energy norm of one sweep of the projected Jacobi relaxation of the
   *   prediction of ActiveSet, the correction δ of w that the wanted changes
   * ask for: δ_a = −W_a on an inactive vertex with W_a < 0, and δ_a = 2 λ_a⁻
   * d_a / (μ̄ ‖A_a‖₁) on an active one with λ_a < 0. Moving w by δ with s fixed
   * moves (u1, u2) by (μ2 δ, −μ1 δ)/(μ1 + μ2), of energy μ̄ δᵀAδ ≤ μ̄ Σ_a ‖A_a‖₁
   * δ_a² (diag(‖A_a‖₁) − A is positive semidefinite), so η_lin = (μ̄ Σ_a ‖A_a‖₁
   * δ_a²)^{1/2}, local to the vertices that want to change (an estimate of the
   * next step, not a bound of the whole linearization error: the next solve
   *   spreads the correction).
   * On the first mesh nothing is expected (η̃ = 0 is passed) and the method
   * stops exactly. With `exact` (the default) nothing of this is evaluated.
   */
  template <int dim>
  class ActiveSetSolver
  {
  public:
    using VectorType = TrilinosWrappers::MPI::BlockVector;
    using Statistics = ActiveSetStatistics;

    /**
     * The phases of the method are timed in the sections "assembly" and
     * "solve" of @p timer.
     */
    ActiveSetSolver(const Parameters::Solver &parameters,
                    const ProblemData<dim>   &data,
                    const ConditionalOStream &pcout,
                    TimerOutput              &timer,
                    const MPI_Comm            mpi_communicator);

    ~ActiveSetSolver();

    /** The linear systems for the mesh of @p discrete_problem and
     * @p dof_handler. */
    void
    setup(const DiscreteProblem<dim> &discrete_problem,
          const DoFHandler<dim>      &dof_handler);

    /**
     * Run the active set method on the mesh of @p problem (that of the last
     * setup()) from the initial guess @p solution (locally owned entries)
     * and the initial @p active_set. On return both hold the converged
     * iterate, and @p action holds λ_a for it; if ActiveSetNotConverged is
     * thrown, the last iterate. @p expected_error is the discretization
     * error η̃ expected on this mesh for balanced stopping, 0 if none is
     * known.
     */
    Statistics
    solve(const DiscreteProblem<dim> &problem,
          DiscreteAction<dim>        &action,
          VectorType                 &solution,
          ActiveSet<dim>             &active_set,
          const double                expected_error = 0);

  private:
    /** Where the method stands in its stopping test on one mesh. */
    struct StoppingState
    {
      /** Balanced stopping, and γ η̃. */
      bool   balanced;
      double balance;
      /** By how much the residuals of the linear solves are made smaller. */
      double tightening;
      /**
       * The residual of the last iteration in which the active set did not
       * change: it has to decrease while the linear solves refine it.
       */
      double settled_residual;
      /**
       * F_∞ and F^w_∞ (DiscreteAction) of the iterate the active set was
       * last chosen on, the predicted one if update() made one.
       */
      std::array<double, 2> force_scales;
    };

    /**
     * How much smaller the residuals of the linear solves are made when
     * the active set has settled but the KKT test has not been met.
     */
    static constexpr double settled_tightening = 100;

    /** The stopping test of a mesh whose expected error is @p expected_error.
     */
    StoppingState
    start(const double expected_error) const;

    /**
     * λ_a of the iterate @p solution on the mesh of @p problem into
     * @p action, and its force scales into @p stopping.
     */
    void
    compute_action(const DiscreteProblem<dim> &problem,
                   DiscreteAction<dim>        &action,
                   const VectorType           &solution,
                   StoppingState              &stopping) const;

    /**
     * Move @p active_set on after the iterate @p solution of iteration
     * @p iteration, whose test wants @p changes: by the changes of the
     * prediction (ActiveSetPrediction) while no cycle has been detected on
     * this mesh and the prediction wants some, else by @p changes
     * (ActiveSet::update()); say so if a cycle was remedied, and take the
     * force scales of the predicted iterate into @p stopping.
     */
    void
    update(const DiscreteProblem<dim>      &problem,
           ActiveSet<dim>                  &active_set,
           const VectorType                &solution,
           const std::vector<StatusChange> &changes,
           const unsigned int               iteration,
           StoppingState                   &stopping);

    /**
     * The residual norms at which the linear solves stop: those that the
     * KKT test allows, on the force scales of @p stopping (a bound on the
     * Euclidean norm bounds every nodal residual, so an iterate on the
     * right active set meets the equilibrium, dual feasibility and
     * complementarity parts of the test by construction), made smaller by
     * its tightening; with balanced stopping at least those of an
     * algebraic error of γ η̃ / 2 in the energy norm.
     */
    LinearTolerances
    linear_tolerances(const StoppingState &stopping) const;

    /**
     * The KKT residual of the iterate @p solution with λ_a in @p action and,
     * with balanced stopping, η_lin and η_alg, into @p statistics.
     */
    void
    evaluate(const DiscreteProblem<dim> &problem,
             const DiscreteAction<dim>  &action,
             const VectorType           &solution,
             const ActiveSet<dim>       &active_set,
             const StoppingState        &stopping,
             Statistics                 &statistics) const;

    /**
     * Whether the method stops after the iteration of @p statistics, whose
     * test wants @p n_changes changes; throws ActiveSetNotConverged if it
     * stops without convergence. Tightens the linear solves of @p stopping
     * when the active set has settled without meeting the test.
     */
    bool
    stops(const Statistics             &statistics,
          const types::global_dof_index n_changes,
          StoppingState                &stopping) const;

    /** The line of the terminal for one iteration. */
    void
    print_iteration(const Statistics             &statistics,
                    const ActiveSet<dim>         &active_set,
                    const types::global_dof_index n_changes,
                    const unsigned int            linear_iterations,
                    const StoppingState          &stopping) const;

    /**
     * The squared residual of the equilibrium part of the KKT conditions at
     * the k-th vertex a of V_h (DiscreteProblem::vertices()), weighted:
     * with r_ia = λ_ia d_a from @p action, @p weights[0] r_1a² +
     * @p weights[1] r_2a² on an inactive vertex, @p weights[2]
     * (r_1a − r_2a)² on an active one.
     */
    double
    equilibrium_square(const DiscreteProblem<dim>  &problem,
                       const DiscreteAction<dim>   &action,
                       const unsigned int           k,
                       const ActiveSet<dim>        &active_set,
                       const std::array<double, 3> &weights) const;

    /**
     * η_lin of an iterate with λ_a in @p action (see the class
     * documentation), over all processes.
     */
    double
    linearization_estimate(const DiscreteProblem<dim> &problem,
                           const DiscreteAction<dim>  &action,
                           const VectorType           &solution,
                           const ActiveSet<dim>       &active_set) const;

    /** η_alg of an iterate with λ_a in @p action, over all processes. */
    double
    algebraic_estimate(const DiscreteProblem<dim> &problem,
                       const DiscreteAction<dim>  &action,
                       const ActiveSet<dim>       &active_set) const;

    const Parameters::Solver &parameters;
    const ProblemData<dim>   &data;
    const ConditionalOStream &pcout;
    TimerOutput              &timer;
    const MPI_Comm            mpi_communicator;

    /** The next active set, predicted from an iterate. */
    ActiveSetPrediction<dim> prediction;

    /** The linear problem of one iteration, coupled or decoupled. */
    std::unique_ptr<ActiveSetSystem<dim>> system;

    /**
     * c_M C_F of balanced stopping: the Friedrichs constant of the bounding
     * box of the mesh times that of the lumped mass (class documentation).
     */
    double dual_norm_constant;
    /** d_min, the smallest d_a of the mesh (over all processes). */
    double min_dual_cell_measure;
  };
} // namespace membranes

#endif
