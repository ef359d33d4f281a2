#ifndef membranes_kkt_defects_h
#define membranes_kkt_defects_h

#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <membranes/active_set/active_set.h>
#include <membranes/dual_mesh/discrete_action.h>
#include <membranes/mesh/discrete_problem.h>

namespace membranes
{
  using namespace dealii;

  /**
   * The defects of the KKT conditions of (3.4) with the multiplier (4.7) of
   * an iterate, as maxima and minima over the vertices a of V_h (all
   * processes), in the units of the problem: with W_a = u1h(a) − u2h(a),
   * λ_a of DiscreteAction::lambda() and d_a,
   * - Prop. 12 (equilibrium of s): max |λ_1a − λ_2a| d_a;
   * - equilibrium of w: max |λ_a d_a| on the inactive vertices;
   * - primal feasibility (W_a ≥ 0): min W_a;
   * - dual feasibility (λ_a ≥ 0): min λ_a and min λ_a d_a;
   * - complementarity (4.8): max |λ_a d_a W_a|.
   * ActiveSetSolver evaluates them on every iterate, for its stopping test
   * (relative_residual()), and keeps those of the last one in
   * ActiveSetStatistics, from which the report takes the discrete
   * identities of the solution.
   */
  struct KKTDefects
  {
    double sum_equilibrium     = 0;
    double contact_equilibrium = 0;
    double min_w               = 0;
    double min_lambda          = 0;
    double min_contact_force   = 0;
    double complementarity     = 0;

    /**
     * The defects of the iterate @p solution (locally owned DoFs) on the
     * mesh of @p problem, with λ_a in @p action and the active set
     * @p active_set (the equilibrium of w is tested off it).
     */
    template <int dim>
    KKTDefects(const DiscreteProblem<dim>               &problem,
               const DiscreteAction<dim>                &action,
               const ActiveSet<dim>                     &active_set,
               const TrilinosWrappers::MPI::BlockVector &solution);

    KKTDefects() = default;

    /**
     * The relative KKT residual, the largest of the defects of the two
     * problems of DecoupledSystem, each on its own scale: F_∞
     * (@p force_scale) and F^w_∞ (@p contact_force_scale) of DiscreteAction,
     * U_∞ = max|U| (@p displacement_scale):
     * - equilibrium of s / F_∞;
     * - equilibrium of w / F^w_∞;
     * - primal feasibility: max(−W_a)⁺ / U_∞;
     * - dual feasibility: max(−λ_a d_a)⁺ / F^w_∞;
     * - complementarity / (F^w_∞ U_∞).
     * All are maxima over the vertices, so none grows with the size of the
     * mesh, and all are unchanged when the data are scaled or the
     * membranes swap roles.
     */
    double
    relative_residual(const double force_scale,
                      const double contact_force_scale,
                      const double displacement_scale) const;
  };



  /** U_∞ = max|U| of @p solution, both blocks (never zero: it divides). */
  double
  displacement_scale(const TrilinosWrappers::MPI::BlockVector &solution);



} // namespace membranes

#endif
