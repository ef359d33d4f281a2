#ifndef membranes_discrete_action_h
#define membranes_discrete_action_h

#include <array>
#include <deal.II/base/index_set.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/dual_mesh/dual_cell_quadrature.h>
#include <membranes/mesh/discrete_problem.h>
#include <membranes/mesh/discretization.h>
#include <membranes/scene/problem_data.h>
#include <utility>
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
   * output; they read it through lambda_h_values() on the pieces of the
   * DualCellQuadrature, or its nodal interpolant through
   * nodal_lambda_values().
   *
   * The same nodal quantities are the multipliers of the active set solver:
   * λ_a d_a is the residual of membrane 1's equation at a.
   *
   * V_h, d_a, the operator and the loads are those of the DiscreteProblem of
   * the mesh, assembled once per mesh; this class only applies them to a
   * solution. Everything is stored for the locally owned vertices of V_h
   * only, in the order of their DoF index; the DoFs of the locally
   * relevant vertices (those of the ghost cells too) are known for the
   * constraints and for λ_h on ghost cells.
   */
  template <int dim>
  class DiscreteAction
  {
  public:
    using VectorType      = TrilinosWrappers::MPI::Vector;
    using BlockVectorType = TrilinosWrappers::MPI::BlockVector;

    /** One vertex a of V_h: its DoF and the data of its dual cell. */
    using Vertex = typename DiscreteProblem<dim>::Vertex;

    DiscreteAction(const Discretization<dim> &discretization,
                   const ProblemData<dim>    &data);

    /**
     * Work on the mesh of @p discrete_problem, which holds V_h, d_a, the
     * operator and the loads of (4.5); it must live as long as this object
     * is used on that mesh.
     */
    void
    reinit(const DiscreteProblem<dim> &discrete_problem);

    /**
     * Compute λ_a by (4.5) from both membranes for @p solution (the blocks
     * u1h, u2h, locally owned entries, hanging nodes and boundary values
     * set): one product of the operator of this mesh with each block, as
     * step-41 obtains its contact forces from the residual of the assembled
     * system.
     */
    void
    compute(const BlockVectorType &solution);

    /** DiscreteProblem::load_mean_and_oscillation() of the mesh. */
    std::pair<double, double>
    load_mean_and_oscillation(
      const typename DoFHandler<dim>::active_cell_iterator &cell,
      const unsigned int                                    i) const;

    /** The locally owned vertices of V_h. */
    const std::vector<Vertex> &
    vertices() const;

    /**
     * λ_h of the last compute(): a ghosted vector on the DoFs of the mesh,
     * λ_a at every vertex a of V_h, at a hanging vertex the mean given by
     * @p hanging_node_constraints, zero on ∂ω.
     */
    VectorType
    lambda_h(const AffineConstraints<double> &hanging_node_constraints) const;

    /** The quadrature on the pieces K ∩ D_a of every cell. */
    const DualCellQuadrature<dim> &
    dual_quadrature() const;

    /**
     * λ_h (@p lambda_h, as lambda_h() returns it) on the pieces K ∩ D_a of
     * vertex @p v of @p cell.
     */
    double
    lambda_h_value(const typename DoFHandler<dim>::active_cell_iterator &cell,
                   const unsigned int                                    v,
                   const VectorType &lambda_h) const;

    /**
     * λ_h on the pieces of the vertex whose DoF is @p a (locally
     * relevant); zero if a is on ∂ω.
     */
    double
    lambda_h_at_vertex(const types::global_dof_index a,
                       const VectorType             &lambda_h) const;

    /**
     * λ_h at the points of dual_quadrature() on @p cell; with @p in_omega_h,
     * also whether each point lies in ω_h (not in the strip along ∂ω).
     */
    void
    lambda_h_values(const typename DoFHandler<dim>::active_cell_iterator &cell,
                    const VectorType    &lambda_h,
                    std::vector<double> &values,
                    std::vector<bool>   *in_omega_h = nullptr) const;

    /**
     * The P1/Q1 function λ̃_h = Σ_a λ_a φ_a with the nodal values λ_a of
     * @p lambda_h (zero on ∂ω; at a hanging vertex the constraint-weighted
     * mean), at the points of @p fe_values, reinit'ed on a cell.
     */
    void
    nodal_lambda_values(const FEValues<dim> &fe_values,
                        const VectorType    &lambda_h,
                        std::vector<double> &values) const;

    /** λ_a from membrane i (0 or 1) for the k-th vertex of vertices(). */
    double
    lambda_from_membrane(const unsigned int i, const unsigned int k) const;

    /**
     * μ_i ∫ ∇u_ih·∇φ_a, the stiffness term of (4.5) of membrane @p i (0 or
     * 1), for the k-th vertex of vertices().
     */
    double
    stiffness_term(const unsigned int i, const unsigned int k) const;

    /** ∫ f_i φ_a, the load term of (4.5), likewise (the assembly's). */
    double
    load_term(const unsigned int i, const unsigned int k) const;

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
    const Discretization<dim>    &discretization;
    const ProblemData<dim>       &data;
    const DualCellQuadrature<dim> dual_cell_quadrature;
    /** The mesh data of (4.5). */
    const DiscreteProblem<dim> *problem;

    /** The products A U_i of the last solution (locally owned DoFs). */
    std::array<VectorType, 2> stiffness_products;

    /** λ_a from formula i of (4.5), by vertex, of the last compute(). */
    std::vector<std::array<double, 2>> membrane_lambdas;

    double max_force;
    double max_contact_force;
  };



  /**
   * What a loop over cells reads on a cell at the points of the dual-cell
   * quadrature: FEValues with @p update_flags, the nodal values of each
   * membrane (read into one buffer each: the functions of FEValues that take
   * the global vector allocate an aligned vector on every call, which on a
   * million cells fragments the heap), and λ_h with the points that lie in
   * ω_h. The error norms and the estimators hold one per thread.
   */
  template <int dim>
  struct DualCellValues
  {
    DualCellValues(const Discretization<dim>           &discretization,
                   const DiscreteAction<dim>           &action,
                   const TrilinosWrappers::MPI::Vector &lambda_h,
                   const UpdateFlags                    update_flags)
      : fe_values(*discretization.mapping,
                  *discretization.fe,
                  action.dual_quadrature().quadrature(),
                  update_flags)
      , action(action)
      , nodal_lambda_h(lambda_h)
    {
      for (auto &values : local_dofs)
        values.resize(discretization.fe->n_dofs_per_cell());
    }

    /**
     * Reinit on @p cell, with the nodal values of the two blocks of
     * @p solution there.
     */
    void
    reinit(const typename DoFHandler<dim>::active_cell_iterator &cell,
           const TrilinosWrappers::MPI::BlockVector             &solution)
    {
      fe_values.reinit(cell);
      for (unsigned int i = 0; i < 2; ++i)
        cell->get_dof_values(solution.block(i),
                             local_dofs[i].begin(),
                             local_dofs[i].end());
      action.lambda_h_values(cell, nodal_lambda_h, lambda_h, &in_omega_h);
    }

    FEValues<dim> fe_values;
    /** The nodal values of u_ih on the cell, i = 0, 1. */
    std::array<std::vector<double>, 2>   local_dofs;
    std::vector<double>                  lambda_h;
    std::vector<bool>                    in_omega_h;
    const DiscreteAction<dim>           &action;
    const TrilinosWrappers::MPI::Vector &nodal_lambda_h;
  };
} // namespace membranes

#endif
