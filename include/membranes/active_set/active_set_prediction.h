#ifndef membranes_active_set_prediction_h
#define membranes_active_set_prediction_h

#include <array>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <membranes/active_set/active_set.h>
#include <membranes/dual_mesh/discrete_action.h>
#include <membranes/mesh/discrete_problem.h>
#include <membranes/scene/parameters.h>
#include <membranes/scene/problem_data.h>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The next active set, predicted.
   *
   * Where strict complementarity fails at the free boundary (λ and u1 − u2
   * both vanish there, as in parameters/degenerate-free-boundary.prm), the
   * discrete contact zone of a finer mesh reaches several layers of
   * vertices beyond the one interpolated from the coarser mesh: with
   * u1 − u2 ~ dist³, the O(h²) errors of the coarse solution move its edge
   * by O(h^{2/3}), i.e. by O(h^{−1/3}) layers (benchmarks/choices.md, "The
   * prediction of the active set", measures it). The
   * plain update of ActiveSet then overshoots: the first solve penetrates
   * over a band wider than the missing one, all of it is activated, and the
   * surplus is released one layer per iteration, because only its outer
   * rim feels the free vertices beyond (inside the band the load presses
   * the membranes together, so λ_a > 0 there): the number of iterations
   * grows with refinement. So when the test wants changes, ActiveSetSolver
   * applies the test not to the iterate itself but to a prediction from it:
   * n_prediction_sweeps sweeps of projected Jacobi on the obstacle problem
   * for w with s fixed,
   *
   *   W_a ← max(0, W_a − r_a / (μ̄ ‖A_a‖₁ / 2)),   r_a = λ_a d_a,
   *
   * ‖A_a‖₁ = Σ_b |A_ab| the l1 norm of the row of a in the condensed
   * Laplacian (one product with A per sweep). On a row whose entries off
   * the diagonal are ≤ 0 and sum with it to zero (an interior vertex of a
   * non-obtuse mesh whose neighbours are not on ∂ω) ‖A_a‖₁ / 2 = A_aa, and
   * this is plain Jacobi. In general diag(‖A_a‖₁) − A is weakly diagonally
   * dominant, hence positive semidefinite, so the sweeps never increase the
   * energy norm of the error, on any mesh; plain Jacobi has no such
   * guarantee where A has positive entries off the diagonal, and l1-Jacobi
   * (the divisor ‖A_a‖₁) takes half the step of plain Jacobi on the rows
   * that sum to zero (benchmarks/choices.md, "The prediction of the active
   * set", compares the three). Each sweep carries the contact
   * information one layer further: penetrated vertices are clamped and lift
   * their neighbours, active vertices pulled apart are released with the ones
   * behind them. Where the predicted test is within the band of indifference of
   * ActiveSet, the prediction has nothing to say and the plain test on the
   * iterate decides: a vertex that the solves keep penetrating by a few ε is
   * clamped by the sweeps to a contact force within the band, and without
   * the plain test it would stay inactive until the prediction wants no
   * change at all (an extra iteration on the finest meshes of a degenerate
   * free boundary). The prediction only proposes; the solve of the next
   * iteration and the plain test decide, and convergence is judged on the
   * iterate alone. If the prediction wants no change, or once a cycle has
   * been detected on the mesh, ActiveSetSolver uses the plain update, so
   * that the remedy against cycling (ActiveSetHistory) works on the plain
   * test.
   */
  template <int dim>
  class ActiveSetPrediction
  {
  public:
    using VectorType      = TrilinosWrappers::MPI::Vector;
    using BlockVectorType = TrilinosWrappers::MPI::BlockVector;

    ActiveSetPrediction(const Parameters::Solver &parameters,
                        const ProblemData<dim>   &data);

    /**
     * Work on the mesh of @p problem: the lifted loads b of W and the steps
     * 2 / (μ̄ ‖A_a‖₁) of the sweeps, which are the same on every iteration
     * of the mesh.
     */
    void
    reinit(const DiscreteProblem<dim> &problem);

    /**
     * The locally owned vertices whose status the test of @p active_set
     * wants to change on the iterate predicted from @p solution by
     * n_prediction_sweeps sweeps of projected Jacobi; at the vertices where
     * that test is within the band, those of @p plain_changes.
     */
    std::vector<StatusChange>
    changes(const DiscreteProblem<dim>      &problem,
            const ActiveSet<dim>            &active_set,
            const BlockVectorType           &solution,
            const std::vector<StatusChange> &plain_changes);

    /**
     * F_∞ and F^w_∞ (DiscreteAction) of the iterate of the last changes():
     * the force scales that the next linear solve is measured against.
     */
    std::array<double, 2>
    force_scales() const;

  private:
    /**
     * Sweeps of projected Jacobi: more layers than the free boundary moves
     * between two nested meshes, which grows like O(h^{−1/3}) at a
     * degenerate free boundary (benchmarks/choices.md, "The prediction of
     * the active set").
     */
    static constexpr unsigned int n_prediction_sweeps = 40;

    const Parameters::Solver &parameters;
    const ProblemData<dim>   &data;
    /** λ_a of the predicted iterate (not that of the iterate itself). */
    DiscreteAction<dim> predicted_action;
    /**
     * For each locally owned vertex of V_h (in the order of
     * DiscreteProblem::vertices()): b_a = (μ2 L_1 − μ1 L_2)_a / M, the
     * lifted load of W, and 2 / (μ̄ ‖A_a‖₁), the step of its sweep.
     */
    std::vector<double> w_load, sweep_step;
  };
} // namespace membranes

#endif
