#ifndef membranes_error_estimator_h
#define membranes_error_estimator_h

#include <deal.II/base/index_set.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/trilinos_vector.h>
#include <deal.II/lac/vector.h>
#include <membranes/discretization.h>
#include <membranes/dual_mesh.h>
#include <membranes/problem_data.h>

namespace membranes
{
  using namespace dealii;

  /**
   * A residual a posteriori error indicator for the contact problem (SPEC
   * §2.3), per cell K,
   *
   *   η_K² = Σ_i μ_i⁻¹ [ h_K² ‖f_ih + s_i λ_h + μ_i Δu_ih‖²_K
   *                     + ½ Σ_{e ⊂ ∂K \ ∂ω} h_e ‖[μ_i ∂_n u_ih]‖²_e
   *                     + (h_K/π)² ‖f_i − f_ih‖²_K ]
   *          + 2 (λ_h, u1h − u2h)⁺_K,
   *
   * with s_1 = +1, s_2 = −1 (the signs of λ in (1.1)), f_ih the mean of f_i
   * on K (4.14), λ_h piecewise constant on the dual cells (integrated over
   * the pieces K ∩ D_a with the DualCellQuadrature; zero in the strip
   * ω \ ω_h along the boundary), [·] the jump across interior edges (on
   * edges with a hanging node, across each of the two small edges).
   *
   * The bracket is the classical residual estimator of the Poisson problem
   * −μ_i Δu_i = f_i − s_i λ for each membrane, with λ replaced by the
   * discrete action λ_h of (4.5); weighting membrane i by μ_i⁻¹ makes each
   * bracket estimate μ_i |u_i − u_ih|²_{H1} with constants independent of
   * μ_i, so that η estimates the energy error
   *   |||e||| = (Σ_i μ_i |u_i − u_ih|²_{H1})^{1/2}
   * uniformly in μ1/μ2. The last term measures the complementarity defect
   * of the discrete pair (λ_h, u1h − u2h), which (4.8) makes vanish at the
   * vertices but not in between; it is the contact term of the estimators
   * of Part 2 of the paper and of Dabaghi, Martin and Vohralík for this
   * problem, there with equilibrated fluxes instead of residuals.
   * The result drives adaptive refinement; η/|||e||| is reported as the
   * effectivity index when the exact solution is known.
   *
   * The edge jumps are computed with FEInterfaceValues on quadrilaterals
   * (Q1: the normal derivative varies along an edge); on triangles (P1,
   * constant gradients) directly from the cell gradients, because deal.II
   * 9.4's FEInterfaceValues and KellyErrorEstimator fail on triangle meshes
   * with hanging nodes.
   */
  template <int dim>
  class ErrorEstimator
  {
  public:
    using VectorType = TrilinosWrappers::MPI::Vector;

    ErrorEstimator(const Discretization<dim> &discretization,
                   const ProblemData<dim>    &data);

    /**
     * Fill @p indicators (indexed by active_cell_index(), zero on cells
     * not locally owned) with η_K² and return η = (Σ_K η_K²)^{1/2} over
     * all processes. @p lambda_h holds λ_h in the u1 slot of the vertices
     * of @p dual_mesh_vertices (ghosted, like the solution).
     */
    double
    estimate(const DoFHandler<dim> &dof_handler,
             const VectorType      &ghosted_solution,
             const VectorType      &lambda_h,
             const IndexSet        &dual_mesh_vertices,
             Vector<double>        &indicators,
             const MPI_Comm         mpi_communicator) const;

  private:
    /** Element residuals, oscillation and the contact term. */
    void
    add_cell_terms(const DoFHandler<dim> &dof_handler,
                   const VectorType      &ghosted_solution,
                   const VectorType      &lambda_h,
                   const IndexSet        &dual_mesh_vertices,
                   Vector<double>        &indicators) const;

    /** ½ h_e μ_i⁻¹ ‖[μ_i ∂_n u_ih]‖²_e on both cells of every interior edge. */
    void
    add_jump_terms(const DoFHandler<dim> &dof_handler,
                   const VectorType      &ghosted_solution,
                   Vector<double>        &indicators) const;

    const Discretization<dim>    &discretization;
    const ProblemData<dim>       &data;
    const DualCellQuadrature<dim> dual_quadrature;
  };
} // namespace membranes

#endif
