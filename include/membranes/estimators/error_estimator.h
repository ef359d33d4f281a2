#ifndef membranes_error_estimator_h
#define membranes_error_estimator_h

#include <array>
#include <cmath>
#include <deal.II/base/tensor.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/trilinos_vector.h>
#include <deal.II/lac/vector.h>
#include <membranes/dual_mesh/dual_mesh.h>
#include <membranes/mesh/discrete_problem.h>
#include <membranes/mesh/discretization.h>
#include <membranes/output/report.h>
#include <membranes/scene/problem_data.h>

namespace membranes
{
  using namespace dealii;

  template <int dim>
  class FluxEquilibration;

  /**
   * The two a posteriori estimators of the contact problem, selected by
   * `Refinement/Estimator`: both return η and the indicators η_K² that drive
   * adaptive refinement, and η / |||e||| is reported as the effectivity
   * index when the exact solution is known.
   *
   * <h3>The residual estimator</h3>
   * Per cell K,
   *
   *   η_K² = Σ_i μ_i⁻¹ [ h_K² ‖f_ih + s_i λ_h + μ_i Δu_ih‖²_K
   *                     + ½ Σ_{e ⊂ ∂K \ ∂ω} h_e ‖[μ_i ∂_n u_ih]‖²_e
   *                     + (h_K/π)² ‖f_i − f_ih‖²_K ]
   *          + 2 (λ_h, u1h − u2h)⁺_K,
   *
   * with s_1 = +1, s_2 = −1 (−μ_i Δu_i = f_i + s_i λ by (1.1)), f_ih the mean
   * of f_i on K (4.14), λ_h piecewise constant on the dual cells (integrated
   * over the pieces K ∩ D_a with the dual-cell quadrature; zero in
   * the strip ω \ ω_h along the boundary), [·] the jump across interior edges
   * (on edges with a hanging node, across each of the two small edges).
   *
   * The bracket is the classical residual estimator of the Poisson problem
   * −μ_i Δu_i = f_i + s_i λ for each membrane, with λ replaced by the
   * discrete action λ_h of (4.5); weighting membrane i by μ_i⁻¹ makes each
   * bracket estimate μ_i |u_i − u_ih|²_{H1} with constants independent of
   * μ_i, so that η estimates the energy error
   *   |||e||| = (Σ_i μ_i |u_i − u_ih|²_{H1})^{1/2}
   * uniformly in μ1/μ2. The last term measures the complementarity defect
   * of the discrete pair (λ_h, u1h − u2h), which (4.8) makes vanish at the
   * vertices but not in between; it is the contact term of the estimators
   * of Part 2 of the paper and of Dabaghi, Martin and Vohralík for this
   * problem, there with equilibrated fluxes instead of residuals.
   *
   * The edge jumps are computed with FEInterfaceValues on quadrilaterals
   * (Q1: the normal derivative varies along an edge); on triangles (P1,
   * constant gradients) directly from the cell gradients, because deal.II
   * 9.4's FEInterfaceValues and KellyErrorEstimator fail on triangle meshes
   * with hanging nodes.
   *
   * <h3>The flux estimator</h3>
   * Built on the equilibrated fluxes σ_ih of FluxEquilibration, on the
   * sub-mesh S_h of §4.2 (in the spirit of Part 2 of the paper and of
   * Dabaghi, Martin and Vohralík for this problem).
   *
   * Let e_i = u_i − u_ih, |||e|||² = Σ_i μ_i |e_i|²_{H1}, s_1 = +1,
   * s_2 = −1, and σ_i ∈ H(div, ω) any flux. From −μ_i Δu_i = f_i + s_i λ,
   *
   *   Σ_i μ_i ‖∇e_i‖² = Σ_i [(f_i + s_i λ_h − div σ_i, e_i)
   *                          − (μ_i ∇u_ih + σ_i, ∇e_i)]
   *                     + (λ − λ_h, e_1 − e_2).
   *
   * With w = u1 − u2 ≥ 0, λ ≥ 0, λ w = 0, λ_h ≥ 0 and w_h = u1h − u2h ≥ 0
   * (nodal values ≥ 0 give a nonnegative P1/Q1 function), the last term is
   * (λ, −w_h) − (λ_h, w − w_h) ≤ (λ_h, w_h). The flux term is at most
   * ‖μ_i^{1/2} ∇u_ih + μ_i^{-1/2} σ_i‖ · μ_i^{1/2}‖∇e_i‖. With
   * A² = Σ_i (η_F,i + η_R,i)² and B = (λ_h, w_h), |||e|||² ≤ A |||e||| + B,
   * hence
   *
   *   |||e||| ≤ η = (Σ_i (η_F,i + η_R,i)² + 2 B)^{1/2},
   *   η_F,i = ‖μ_i^{1/2} ∇u_ih + μ_i^{-1/2} σ_ih‖,
   *   η_R,i = (Σ_K (h_K/π)² μ_i^{-1} ‖f_i + s_i λ_h − div σ_ih‖²_K)^{1/2},
   *
   * provided the residual r_i = f_i + s_i λ_h − div σ_ih has mean value
   * zero where the Poincaré inequality is applied.
   *
   * The flux t_ih of (4.13) has this property only on whole dual cells
   * (Lemma 17, up to data oscillation): div t_ih varies from one
   * sub-triangle of D_a to the next by O(|∇²u|), which would make η_R as
   * large as η_F. The estimator therefore uses the equilibrated flux σ_ih
   * of FluxEquilibration, the sum of patch contributions on the supports
   * of the hat functions: div σ_ih = Π_0 (f_i + s_i λ̃_h) on every
   * sub-triangle of S_h, with λ̃_h = Σ_a λ_a φ_a the P1/Q1 function of the
   * nodal λ_a. The argument above holds with λ̃_h in place of λ_h (it only
   * uses λ_h ≥ 0), so the residual and contact terms use λ̃_h; r_i is then
   * f_i + s_i λ̃_h minus its means on the sub-triangles, of the order of
   * h ∇(f_i + s_i λ̃_h), and η_R is of higher order. The 1/π of convex
   * cells with the cell diameter h_K is used as the constant (the means
   * of r_i vanish on every sub-triangle, hence on every cell); η is an
   * upper bound up to this choice of constant and the interpolation of
   * the boundary data g (e_i does not vanish on ∂ω where g ≠ I_h g).
   *
   * For marking, per cell K,
   *
   *   η_K² = Σ_i μ_i^{-1} (‖μ_i ∇u_ih + σ_ih‖_K
   *                        + (h_K/π) ‖f_i + s_i λ̃_h − div σ_ih‖_K)²
   *          + 2 (λ̃_h, u1h − u2h)⁺_K,
   *
   * whose sum is at most η² (Minkowski).
   */
  template <int dim>
  class ErrorEstimator
  {
  public:
    using VectorType      = TrilinosWrappers::MPI::Vector;
    using BlockVectorType = TrilinosWrappers::MPI::BlockVector;

    ErrorEstimator(const Discretization<dim> &discretization,
                   const ProblemData<dim>    &data);

    /**
     * The residual estimator: fill @p indicators (indexed by
     * active_cell_index(), zero on cells not locally owned) with its η_K²
     * and return η over all processes, with @p ghosted_solution the blocks
     * u1h, u2h (ghosted), the loads of @p problem, and @p lambda_h
     * (DiscreteAction::lambda_h()) read on the dual cells of @p dual_mesh.
     */
    double
    residual_estimate(const DoFHandler<dim>      &dof_handler,
                      const BlockVectorType      &ghosted_solution,
                      const DiscreteProblem<dim> &problem,
                      const DualMesh<dim>        &dual_mesh,
                      const VectorType           &lambda_h,
                      Vector<double>             &indicators,
                      const MPI_Comm              mpi_communicator) const;

    /**
     * The flux estimator: the same with the equilibrated fluxes of
     * @p flux_equilibration and the nodal λ_a of @p lambda_h; η and its
     * parts, over all processes, in the FluxRecord (its defects empty).
     */
    FluxRecord
    flux_estimate(const DoFHandler<dim>        &dof_handler,
                  const BlockVectorType        &ghosted_solution,
                  const DualMesh<dim>          &dual_mesh,
                  const VectorType             &lambda_h,
                  const FluxEquilibration<dim> &flux_equilibration,
                  Vector<double>               &indicators,
                  const MPI_Comm                mpi_communicator) const;

  private:
    using CellIterator = typename DoFHandler<dim>::active_cell_iterator;

    /** The values of one cell for both estimators (defined in the .cc). */
    struct CellScratch;

    /** Element residuals, oscillation and the contact term. */
    void
    add_cell_terms(const DoFHandler<dim>      &dof_handler,
                   const BlockVectorType      &ghosted_solution,
                   const DiscreteProblem<dim> &problem,
                   const DualMesh<dim>        &dual_mesh,
                   const VectorType           &lambda_h,
                   Vector<double>             &indicators) const;

    /**
     * (Σ_i μ_i Σ_{e ⊂ ∂ω_h} h_e^{-1} ‖g_i − u_ih‖²_e)^{1/2}, g_1 = g,
     * g_2 = g2: the size of the energy of a lifting of the boundary data
     * error into the cells along ∂ω (constant 1), which the argument for η
     * assumes to vanish. Not part of η.
     */
    double
    boundary_data_part(const DoFHandler<dim> &dof_handler,
                       const BlockVectorType &ghosted_solution,
                       const MPI_Comm         mpi_communicator) const;

    /** ½ h_e μ_i⁻¹ ‖[μ_i ∂_n u_ih]‖²_e on both cells of every interior edge. */
    void
    add_jump_terms(const DoFHandler<dim> &dof_handler,
                   const BlockVectorType &ghosted_solution,
                   Vector<double>        &indicators) const;

    /** The traces on an edge between quadrilaterals (defined in the .cc). */
    struct JumpScratch;

    /**
     * On triangles: the constant gradients ∇u_1h, ∇u_2h of P1 on every
     * cell that is not artificial, indexed by active_cell_index().
     */
    std::vector<std::array<Tensor<1, dim>, 2>>
    p1_gradients(const DoFHandler<dim> &dof_handler,
                 const BlockVectorType &ghosted_solution) const;

    /**
     * ∫_e |[μ_i ∂_n u_ih]|² (i = 1, 2) on the edge @p f of @p cell between
     * triangles, from the cell gradients of p1_gradients().
     */
    std::array<double, 2>
    p1_jump_integrals(
      const CellIterator                               &cell,
      const unsigned int                                f,
      const std::vector<std::array<Tensor<1, dim>, 2>> &cell_gradients) const;

    /**
     * The same between quadrilaterals, by FEInterfaceValues (the normal
     * derivative of Q1 varies along the edge).
     */
    std::array<double, 2>
    q1_jump_integrals(const CellIterator    &cell,
                      const unsigned int     f,
                      const BlockVectorType &ghosted_solution,
                      JumpScratch           &scratch) const;

    /**
     * The terms of the flux estimator, on one cell K or summed over cells:
     * η_F,i² = μ_i⁻¹ ‖μ_i ∇u_ih + σ_ih‖², η_R,i² = (h_K/π)² μ_i⁻¹
     * ‖f_i + s_i λ̃_h − div σ_ih‖² and (λ̃_h, u1h − u2h)⁺.
     */
    struct FluxTerms
    {
      std::array<double, 2> flux{}, residual{};
      double                contact = 0;

      FluxTerms &
      operator+=(const FluxTerms &other)
      {
        for (unsigned int i = 0; i < 2; ++i)
          {
            flux[i] += other.flux[i];
            residual[i] += other.residual[i];
          }
        contact += other.contact;
        return *this;
      }

      /** Σ_i (η_F,i + η_R,i)² + 2 (λ̃_h, u1h − u2h)⁺. */
      double
      eta_squared() const
      {
        double eta2 = 0;
        for (unsigned int i = 0; i < 2; ++i)
          eta2 += std::pow(std::sqrt(flux[i]) + std::sqrt(residual[i]), 2);
        return eta2 + 2 * contact;
      }
    };

    const Discretization<dim> &discretization;
    const ProblemData<dim>    &data;
  };
} // namespace membranes

#endif
