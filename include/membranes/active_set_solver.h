#ifndef membranes_active_set_solver_h
#define membranes_active_set_solver_h

#include <array>
#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/index_set.h>
#include <deal.II/base/timer.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/active_set_system.h>
#include <membranes/discrete_action.h>
#include <membranes/discretization.h>
#include <membranes/parameters.h>
#include <membranes/problem_data.h>
#include <memory>
#include <optional>
#include <vector>

namespace membranes
{
  using namespace dealii;

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
   * A vertex whose status the active set method wants to change: its u1 DoF
   * and by how much its test is violated, in units of the band of
   * indifference (see ActiveSetSolver), so at least 1.
   */
  struct StatusChange
  {
    types::global_dof_index dof;
    double                  violation;

    /** For Utilities::MPI::all_gather(). */
    template <class Archive>
    void
    serialize(Archive &archive, const unsigned int)
    {
      archive &dof &violation;
    }
  };



  /**
   * The active sets the active set method has visited on one mesh, and the
   * remedy against cycling.
   *
   * The plain update changes the status of every vertex whose test is
   * violated. For an M-matrix (non-obtuse meshes) this converges
   * monotonically, but in general the primal-dual active set method, a
   * semismooth Newton method for the complementarity problem, may cycle:
   * return to an active set it has already visited, and go round for ever.
   * Each update is therefore checked against all active sets visited on
   * the current mesh (the initial one included). When it would return to
   * one of them, the update is restricted to the vertices with the largest
   * violations: on the r-th cycle detected on this mesh to ⌈n / 2^r⌉ of the
   * n vertices that want to change; if that set was visited too, r is
   * raised again. Once the share is down to one vertex, the method
   * continues on this mesh with Murty's least-index rule: change only the
   * wanted vertex of least DoF index. That rule terminates for every linear
   * complementarity problem with a P-matrix (K. G. Murty, Note on a
   * Bard-type scheme for solving the complementarity problem, Opsearch 11,
   * 1974), and ours has one: eliminating the displacements leaves the Schur
   * complement of the symmetric positive definite system on the contact
   * vertices, which is symmetric positive definite. The halving can only happen
   * log2(n) times, so the method terminates on every mesh; a cycle costs
   * iterations, not convergence.
   *
   * Under MPI each process keeps the locally owned part of the sets; the
   * comparisons and the choice of vertices are global.
   */
  class ActiveSetHistory
  {
  public:
    explicit ActiveSetHistory(const MPI_Comm mpi_communicator);

    /** Forget all, and start a new mesh at @p initial_active_set. */
    void
    restart(const IndexSet &initial_active_set);

    /** What one update did. */
    struct Step
    {
      /** The next active set (locally owned part). */
      IndexSet active_set;
      /** How many vertices wanted to change, and how many did. */
      types::global_dof_index wanted, changed;
      /**
       * The number of the visited set (0 for the initial one, k for the
       * set of iteration k + 1) that the plain update would have
       * returned to, if a cycle was detected.
       */
      std::optional<unsigned int> cycle_to;
      /** Whether the update followed Murty's least-index rule. */
      bool least_index_rule;
    };

    /**
     * The active set after @p active_set (the last one visited), changed
     * at the locally owned vertices @p changes or, if that would close a
     * cycle, at the part of them that the remedy allows. The result is
     * recorded as visited.
     */
    Step
    next(const IndexSet &active_set, const std::vector<StatusChange> &changes);

    /** Cycles detected since restart(). */
    unsigned int
    cycles() const;

  private:
    /** The number of the visited set equal to @p set (on all processes). */
    std::optional<unsigned int>
    find(const IndexSet &set) const;

    const MPI_Comm        mpi_communicator;
    std::vector<IndexSet> visited;
    unsigned int          n_cycles;
    bool                  least_index_rule;
  };



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
   * obstacle problem for w = u1 − u2, DecoupledSystem). Each iteration
   * solves the
   * linear problem W_a = 0 on A, Λ_a = 0 off A (ActiveSetSystem): on the
   * coupled pair (CoupledSystem, `Solver/Method = coupled`) or on the sum
   * and the difference of the membranes (DecoupledSystem, `decoupled`).
   * Both give the same iterate; λ_a, the next active set and the KKT
   * residual are computed from it in the same way.
   *
   * <b>Decisions relative to the data.</b> In the units of the data, the
   * test reads λ̂_a − Ŵ_a > 0 with
   *
   *   λ̂_a = λ_a / (c_a U_∞),   Ŵ_a = W_a / U_∞,   U_∞ = max|U|,
   *
   * both unchanged when the loads and g are multiplied by a factor, or μ1
   * and μ2 (with the loads) by a factor. (c_a U_∞ d_a = μ̄ ∫|∇φ_a|² U_∞ is
   * the size of the forces of the obstacle problem for w at a.) After a
   * solve, W_a = 0 on A and λ_a = 0 off A, up to round-off, so the test
   * keeps an active vertex iff λ_a > 0 and activates an inactive one iff
   * W_a < 0; c_a only matters for the initial active set of a mesh. Where
   * both are zero in exact arithmetic (a degenerate vertex: the membranes
   * touch without pressing on each other), the sign of the test is the
   * sign of round-off, a vertex may flip at every iteration, and the plain
   * method cycles. Each sign is therefore read with a band of indifference
   * ε = `Tolerance`:
   * - an active vertex is released iff λ̂_a < −ε,
   * - an inactive vertex is activated iff Ŵ_a < −ε,
   * - every other vertex keeps its status (hysteresis).
   * The band is about that of the KKT residual: a vertex kept in it adds at
   * most about ε to its dual (−λ_a d_a / F^w_∞, F^w_∞ ≥ μ̄ ∫|∇φ_a|² U_∞) or
   * primal (−W_a / U_∞) feasibility part, so either status is an acceptable
   * answer for it. λ_a is DiscreteAction::lambda(), the multiplier of the
   * obstacle problem for w: its rounding and algebraic errors are those of
   * forces of tension μ̄, as the band is, whatever the tension ratio.
   *
   * <b>The next active set, predicted.</b> Where strict complementarity
   * fails at the free boundary (λ and u1 − u2 both vanish there, as in
   * parameters/degenerate-free-boundary.prm), the discrete contact zone of
   * a finer mesh reaches several layers of vertices beyond the one
   * interpolated from the coarser mesh: with u1 − u2 ~ dist³, the O(h²)
   * errors of the coarse solution move its edge by O(h^{2/3}), i.e. by
   * O(h^{−1/3}) layers (measured: the contact radius 0.4774, 0.4853,
   * 0.4904 for R = 1/2 on 33 282, 132 098, 526 338 DoFs, the gap shrinking
   * by 1.53 ≈ 2^{2/3} per refinement). The plain update then overshoots:
   * the first solve penetrates over a band wider than the missing one, all
   * of it is activated, and the surplus is released one layer per
   * iteration, because only its outer rim feels the free vertices beyond
   * (inside the band the load presses the membranes together, so λ_a > 0
   * there), and the count grew with refinement (3 4 3 5 6 6 iterations on
   * cycles 1 to 6 of that scene). So when the test wants changes, the next
   * active set is the test applied not to the iterate itself but to a
   * prediction from it: n_prediction_sweeps sweeps of projected Jacobi on
   * the obstacle problem for w with s fixed,
   *
   *   W_a ← max(0, W_a − r_a / (μ̄ ‖A_a‖₁ / 2)),   r_a = λ_a d_a,
   *
   * ‖A_a‖₁ = Σ_b |A_ab| the l1 norm of the row of a in the condensed
   * Laplacian (one product with the operator of DiscreteAction per sweep).
   * Where A is an M-matrix, ‖A_a‖₁ / 2 = A_aa (its rows sum to zero) and
   * this is plain Jacobi. In general diag(‖A_a‖₁) − A is weakly diagonally
   * dominant, hence positive semidefinite, so the sweeps never increase
   * the energy norm of the error, on any mesh; plain Jacobi diverged on
   * the curved, locally refined cells of the disk, and l1-Jacobi (the
   * divisor ‖A_a‖₁) needed more sweeps (4 iterations on Q1 where this
   * needs 3). Each sweep carries the contact
   * information one layer further: penetrated vertices are clamped and
   * lift their neighbours, active vertices pulled apart are released with
   * the ones behind them. Where the predicted test is within the band of
   * indifference, the prediction has nothing to say and the plain test on
   * the iterate decides: a vertex that the solves keep penetrating by a
   * few ε is clamped by the sweeps to a contact force within the band, and
   * without the plain test it would stay inactive until the prediction
   * wants no change at all (an extra iteration on the finest meshes of a
   * degenerate free boundary). The prediction only proposes; the solve of
   * the next iteration and the plain test decide, and convergence is
   * judged on the iterate alone. If the prediction wants no change, or once a
   * cycle has been detected on the mesh, the plain update is used, so that the
   * remedy against cycling below works on the plain test as before.
   *
   * <b>Convergence.</b> The iteration stops when no vertex wants to change
   * and the relative KKT residual (kkt_residual()) is at most `Tolerance`.
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
   * set is solved again with residuals settled_tightening times smaller,
   * from the same AMG hierarchy; if that does not decrease the residual, or
   * at `Max active set iterations`, solve() throws ActiveSetNotConverged
   * with the residual reached. Cycling is detected and remedied by
   * ActiveSetHistory.
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
   *   prediction below, the correction δ of w that the wanted changes ask
   *   for: δ_a = −W_a on an inactive vertex with W_a < 0, and
   *   δ_a = 2 λ_a⁻ d_a / (μ̄ ‖A_a‖₁) on an active one with λ_a < 0. Moving w by
   *   δ with s fixed moves (u1, u2) by (μ2 δ, −μ1 δ)/(μ1 + μ2), of energy
   *   μ̄ δᵀAδ ≤ μ̄ Σ_a ‖A_a‖₁ δ_a² (diag(‖A_a‖₁) − A is positive
   *   semidefinite), so
   *     η_lin = (μ̄ Σ_a ‖A_a‖₁ δ_a²)^{1/2},
   *   local to the vertices that want to change (an estimate of the next
   *   step, not a bound of the whole linearization error: the next solve
   *   spreads the correction).
   * On the first mesh nothing is expected (η̃ = 0 is passed) and the method
   * stops exactly. With `exact` (the default) nothing of this is evaluated.
   */
  template <int dim>
  class ActiveSetSolver
  {
  public:
    using VectorType = TrilinosWrappers::MPI::Vector;
    using Statistics = ActiveSetStatistics;

    /**
     * The phases of the method are timed in the sections "assembly" and
     * "solve" of @p timer.
     */
    ActiveSetSolver(const Parameters::Solver  &parameters,
                    const Discretization<dim> &discretization,
                    const ProblemData<dim>    &data,
                    const ConditionalOStream  &pcout,
                    TimerOutput               &timer,
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
     * @p action holds λ_a for it; if ActiveSetNotConverged is thrown, the
     * last iterate. @p expected_error is the discretization error η̃
     * expected on this mesh for balanced stopping, 0 if none is known.
     */
    Statistics
    solve(DiscreteAction<dim> &action,
          VectorType          &solution,
          IndexSet            &active_set,
          const double         expected_error = 0);

    /**
     * The active set {a : Λ_a − c_a W_a > 0} of a new mesh, for the previous
     * mesh's solution and λ_h interpolated onto it (nested iteration). A
     * vertex where both |λ̂_a| ≤ ε and |Ŵ_a| ≤ ε is degenerate up to
     * round-off; it starts inactive, as every vertex of the first mesh does.
     */
    IndexSet
    initial_active_set(const DiscreteAction<dim> &action,
                       const VectorType          &ghosted_solution,
                       const VectorType          &ghosted_lambda_h) const;

    /**
     * The relative KKT residual of an iterate, the largest of the defects
     * of the two problems of DecoupledSystem, each on its own scale
     * (F_∞, F^w_∞ of DiscreteAction, U_∞ = max|U|):
     * - equilibrium of s: max |λ_1a − λ_2a| d_a / F_∞ (Prop. 12);
     * - equilibrium of w: max |λ_a d_a| / F^w_∞ on inactive vertices;
     * - primal feasibility: max(−W_a)⁺ / U_∞;
     * - dual feasibility: max(−λ_a d_a)⁺ / F^w_∞;
     * - complementarity: max |λ_a d_a W_a| / (F^w_∞ U_∞).
     * All are maxima over the vertices, so none grows with the size of the
     * mesh, and all are unchanged when the data are scaled or the
     * membranes swap roles.
     */
    double
    kkt_residual(const DiscreteAction<dim> &action,
                 const VectorType          &ghosted_solution,
                 const IndexSet            &active_set) const;

  private:
    /** The scales of an iterate that decisions and residuals refer to. */
    struct Scales
    {
      double force;         ///< F_∞ of DiscreteAction.
      double contact_force; ///< F^w_∞ of DiscreteAction.
      double displacement;  ///< U_∞ = max|U|.
    };

    Scales
    scales(const DiscreteAction<dim> &action,
           const VectorType          &ghosted_solution) const;

    /**
     * Sweeps of projected Jacobi in predicted_changes(): more layers than
     * the free boundary moves between two nested meshes (measured: 3 to 6
     * on the degenerate scene; 10 sweeps left one iteration more on its
     * last two cycles, 40 none).
     */
    static constexpr unsigned int n_prediction_sweeps = 40;

    /**
     * How much smaller the residuals of the linear solves are made when
     * the active set has settled but the KKT test has not been met.
     */
    static constexpr double settled_tightening = 100;

    /**
     * The changes of the active set after the iterate @p solution (locally
     * owned entries) whose plain test wants @p changes: those of
     * predicted_changes(), unless a cycle has been detected on this mesh or
     * the prediction wants none; then @p changes.
     */
    std::vector<StatusChange>
    next_changes(DiscreteAction<dim>             &action,
                 const VectorType                &solution,
                 const IndexSet                  &active_set,
                 const std::vector<StatusChange> &changes) const;

    /**
     * The locally owned vertices whose status in @p active_set the test
     * Λ_a − c_a W_a > 0 (with the band of indifference) wants to change on
     * the iterate predicted from @p solution by n_prediction_sweeps sweeps
     * of projected Jacobi (see the class documentation); at the vertices
     * where that test is within the band, those of @p plain_changes, the
     * changes the plain test wants on @p solution itself. Leaves in
     * @p action the λ_a of the prediction.
     */
    std::vector<StatusChange>
    predicted_changes(DiscreteAction<dim>             &action,
                      const VectorType                &solution,
                      const IndexSet                  &active_set,
                      const std::vector<StatusChange> &plain_changes) const;

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
     * The locally owned vertices of @p action whose status in
     * @p active_set the test wants to change, outside the band of
     * indifference (see the class documentation).
     */
    std::vector<StatusChange>
    wanted_changes(const DiscreteAction<dim> &action,
                   const VectorType          &ghosted_solution,
                   const IndexSet            &active_set) const;

    /**
     * The squared residual of the equilibrium part of the KKT conditions at
     * the k-th vertex of @p action, weighted: with r_ia = λ_ia d_a,
     * @p weights[0] r_1a² + @p weights[1] r_2a² on an inactive vertex,
     * @p weights[2] (r_1a − r_2a)² on an active one.
     */
    double
    equilibrium_square(const DiscreteAction<dim>   &action,
                       const unsigned int           k,
                       const IndexSet              &active_set,
                       const std::array<double, 3> &weights) const;

    /**
     * η_lin of an iterate with λ_a in @p action (see the class
     * documentation), over all processes.
     */
    double
    linearization_estimate(const DiscreteAction<dim> &action,
                           const VectorType          &ghosted_solution,
                           const IndexSet            &active_set) const;

    /** η_alg of an iterate with λ_a in @p action, over all processes. */
    double
    algebraic_estimate(const DiscreteAction<dim> &action,
                       const IndexSet            &active_set) const;

    const Parameters::Solver &parameters;
    const ProblemData<dim>   &data;
    const ConditionalOStream &pcout;
    TimerOutput              &timer;
    const MPI_Comm            mpi_communicator;

    SmartPointer<const DoFHandler<dim>> dof_handler;
    IndexSet                            locally_owned_dofs;
    IndexSet                            locally_relevant_dofs;

    /** The linear problem of one iteration, coupled or decoupled. */
    std::unique_ptr<ActiveSetSystem<dim>> system;

    /** The active sets visited on the current mesh. */
    ActiveSetHistory history;

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
