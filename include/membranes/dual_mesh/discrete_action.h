#ifndef membranes_discrete_action_h
#define membranes_discrete_action_h

#include <array>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/mesh/discrete_problem.h>
#include <membranes/scene/problem_data.h>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The discrete action λ_h by the local postprocessing (4.5) of the paper.
   *
   * For every interior vertex a (the set V_h; with hanging nodes, every
   * unconstrained interior vertex), with φ_a its hat function and
   * d_a = ∫ φ_a = meas(D_a) (the lumped mass; with hanging nodes the row
   * sum of the constrained mass matrix),
   *
   *   λ_a d_a = μ1 ∫ ∇u1h·∇φ_a − ∫ f1 φ_a          (membrane 1)
   *           = −(μ2 ∫ ∇u2h·∇φ_a − ∫ f2 φ_a)        (membrane 2).
   *
   * Both right-hand sides are computed; Prop. 12 says that they agree for
   * the solution of the discrete variational inequality (3.4), and
   * λ_a ≥ 0 and λ_a (u1h − u2h)(a) = 0 (4.8).
   *
   * <h3>λ_h</h3>
   * λ_h is the function equal to λ_a on the dual cell D_a (a ∈ V_h); on the
   * pieces of a hanging vertex, the constraint-weighted mean of the λ_a of
   * its parents; zero on the pieces of boundary vertices, the strip ω \ ω_h.
   * lambda_h() returns its nodal values as one vector on the DoFs of the
   * mesh, which the driver keeps and hands to the active set of the next
   * mesh, the errors, both estimators, the flux reconstruction and the
   * output; they read it on the pieces of the dual cells through the
   * DualMesh, or as its nodal interpolant λ̃_h = Σ_a λ_a φ_a.
   *
   * The same nodal quantities are the multipliers of the active set solver:
   * λ_a d_a is the residual of membrane 1's equation at a.
   *
   * V_h, d_a, the operator and the loads are those of the DiscreteProblem of
   * the mesh, assembled once per mesh and passed to the functions that need
   * them; this class only applies them to a solution and keeps what it
   * computed: λ_a of both formulas for the locally owned vertices of V_h,
   * in the order of DiscreteProblem::vertices(), and the force scales.
   */
  template <int dim>
  class DiscreteAction
  {
  public:
    using VectorType      = TrilinosWrappers::MPI::Vector;
    using BlockVectorType = TrilinosWrappers::MPI::BlockVector;

    /** One vertex a of V_h: its DoF and the data of its dual cell. */
    using Vertex = typename DiscreteProblem<dim>::Vertex;

    explicit DiscreteAction(const ProblemData<dim> &data);

    /** Size the work vectors for the mesh of @p problem. */
    void
    reinit(const DiscreteProblem<dim> &problem);

    /**
     * Compute λ_a by (4.5) from both membranes for @p solution (the blocks
     * u1h, u2h, locally owned entries, hanging nodes and boundary values
     * set) with the operator and loads of @p problem: one product of the
     * operator of the mesh with each block, as step-41 obtains its contact
     * forces from the residual of the assembled system.
     */
    void
    compute(const DiscreteProblem<dim> &problem,
            const BlockVectorType      &solution);

    /**
     * λ_h of the last compute(): a ghosted vector on the DoFs of the mesh of
     * @p problem, λ_a at every vertex a of V_h, at a hanging vertex the mean
     * given by @p hanging_node_constraints, zero on ∂ω.
     */
    VectorType
    lambda_h(const DiscreteProblem<dim>      &problem,
             const AffineConstraints<double> &hanging_node_constraints) const;

    /**
     * λ_a from membrane i (0 or 1) for the k-th vertex of
     * DiscreteProblem::vertices().
     */
    double
    lambda_from_membrane(const unsigned int i, const unsigned int k) const;

    /**
     * μ_i ∫ ∇u_ih·∇φ_a, the stiffness term of (4.5) of membrane @p i (0 or
     * 1), for the k-th vertex of the vertices() of @p problem.
     */
    double
    stiffness_term(const DiscreteProblem<dim> &problem,
                   const unsigned int          i,
                   const unsigned int          k) const;

    /** ∫ f_i φ_a, the load term of (4.5), likewise (the assembly's). */
    double
    load_term(const DiscreteProblem<dim> &problem,
              const unsigned int          i,
              const unsigned int          k) const;

    /**
     * λ_a from the two formulas of (4.5), which agree by Prop. 12, weighted
     * as (μ2 λ_1a + μ1 λ_2a) / (μ1 + μ2): times d_a it is the residual
     * μ̄ (A W)_a − G_a of the obstacle problem for w = u1 − u2
     * (DecoupledSystem), G = (μ2 F1 − μ1 F2)/(μ1 + μ2), the multiplier of
     * the active set method. Its rounding and algebraic errors are those
     * of forces of tension μ̄ = μ1μ2/(μ1 + μ2); the plain mean of the two
     * formulas would carry those of the stiffer membrane, max(μ1, μ2)/μ̄
     * times larger (1e8 times for a tension ratio of 1e8). For μ1 = μ2 it
     * is the mean.
     */
    double
    lambda(const unsigned int k) const;

    /**
     * The size of the forces at the interior vertices: the max over a and
     * i of the terms that (4.5) balances, |μ_i ∫ ∇u_ih·∇φ_a|, |∫ f_i φ_a|
     * and the diagonal part μ_i ∫|∇φ_a|² |u_ih(a)| of the first (whose
     * rounding error bounds how well the balance can be computed). What
     * the difference (λ_1a − λ_2a) d_a of Prop. 12, the residual of the
     * problem for s = μ1 u1 + μ2 u2, is measured against; global over all
     * processes. It scales like the data.
     */
    double
    force_scale() const;

    /**
     * The same for the forces of the obstacle problem for w = u1 − u2 that
     * lambda() d_a balances: the max over a of |μ̄ (A W)_a|, |G_a|
     * and μ̄ ∫|∇φ_a|² max_i |u_ih(a)|. What λ_a of the active set method
     * is measured against. It is unchanged when the two membranes swap
     * roles, and for tension ratios far from 1 it is the scale of the
     * softer membrane, not of the stiffer one.
     */
    double
    contact_force_scale() const;

  private:
    const ProblemData<dim> &data;

    /** The stiffness terms μ_i ∫ ∇u_ih·∇φ of the last solution. */
    std::array<VectorType, 2> stiffness_terms;

    /** λ_a from formula i of (4.5), by vertex, of the last compute(). */
    std::vector<std::array<double, 2>> membrane_lambdas;

    double max_force;
    double max_contact_force;
  };
} // namespace membranes

#endif
