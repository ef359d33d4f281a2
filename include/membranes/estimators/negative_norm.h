#ifndef membranes_negative_norm_h
#define membranes_negative_norm_h

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <functional>
#include <membranes/dual_mesh/dual_cell_quadrature.h>
#include <membranes/dual_mesh/dual_mesh.h>
#include <membranes/estimators/riesz_operator.h>
#include <membranes/mesh/discretization.h>
#include <membranes/scene/problem_data.h>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The norm of H^{-1}(ω), the dual of H¹₀(ω) with the full H¹(ω) norm, as
   * the paper defines it in (4.20):
   *
   *   ‖ρ‖_{H^{-1}(ω)} = sup_{v ∈ H¹₀(ω)} ∫_ω ρ v / ‖v‖_{H¹(ω)},
   *
   * the norm in which Theorem 21 bounds the error of the action,
   * ‖λ − λ_h‖_{H^{-1}(ω)} ≤ c h (4.34). The supremum is attained at the
   * Riesz representative z ∈ H¹₀(ω) of ρ,
   *
   *   ∫ ∇z·∇v + ∫ z v = ∫ ρ v   for all v ∈ H¹₀(ω),
   *
   * and equals ‖z‖_{H¹(ω)} = (∫ ρ z)^{1/2}. The class computes z_h, the
   * Galerkin approximation of z by continuous elements of degree @p degree
   * (Q_p on quadrilaterals, P_p on triangles) on the mesh of the solution,
   * and returns ‖z_h‖_{H¹(ω)} = (F·Z)^{1/2}, with F_j = ∫ ρ φ_j and Z the
   * nodal values of z_h. Galerkin orthogonality in the H¹ inner product
   * gives ‖z‖² = ‖z_h‖² + ‖z − z_h‖²: the computed norm is a lower bound,
   * with relative error ‖z − z_h‖²_{H¹} / (2 ‖z‖²_{H¹}).
   *
   * The right-hand side is integrated on the pieces K ∩ D_a of the dual
   * cells (DualCellQuadrature), on which λ_h is constant: the three-point
   * rule on each piece, and on the cells where ρ jumps by more than a
   * threshold (an exact λ that jumps across a curve inside the pieces) the
   * same rule on each of the 4^k parts of every piece.
   *
   * The system (A + M) Z = F of degree p has twice the unknowns of the
   * solution and is solved without its matrix: RieszOperator applies A + M
   * cell by cell, and RieszMultigrid preconditions CG by one p-multigrid
   * V-cycle down to the space of degree 1 on the same mesh, the space of
   * the solution, on which algebraic multigrid of the Laplacian that the
   * method assembled anyway solves. The error phase of a cycle thus holds
   * vectors of degree p and an AMG hierarchy of degree 1, and assembles no
   * matrix.
   */
  template <int dim>
  class NegativeNorm
  {
  public:
    using CellIterator = typename Triangulation<dim>::active_cell_iterator;

    /**
     * ρ on one cell: @p values[q] = ρ(@p points[q]) at the points of
     * @p rule mapped to @p cell (its vertex_of_point() gives the piece
     * K ∩ D_a of each point).
     */
    using Density = std::function<void(const CellIterator            &cell,
                                       const DualCellQuadrature<dim> &rule,
                                       const std::vector<Point<dim>> &points,
                                       std::vector<double>           &values)>;

    /**
     * The representative z_h of degree @p degree, on the cells and with the
     * mapping of @p discretization; ∫ ρ φ_j with 4^k parts of every piece
     * (k = @p jump_subdivisions) where ρ jumps.
     */
    NegativeNorm(const Discretization<dim> &discretization,
                 const unsigned int         degree            = 2,
                 const unsigned int         jump_subdivisions = 4);

    /**
     * ‖ρ‖_{H^{-1}(ω)} by ‖z_h‖_{H¹(ω)}, on the mesh of
     * @p linear_dof_handler, the space of degree 1 (P1/Q1) on it: the
     * coarse level of the multigrid, on which the AMG of @p linear_matrix
     * solves. That matrix need only be spectrally equivalent to A + M on
     * the space of degree 1 with zero boundary values: the Laplacian of
     * the mesh, condensed with its hanging node and boundary constraints
     * (DiscreteProblem::laplace_matrix()), is (A ≤ A + M ≤ (1 + C_P) A by
     * Poincaré's inequality). The cells on which the values of ρ at the
     * points of the three-point rule differ by more than @p jump take the
     * composite rule.
     */
    double
    norm(const DoFHandler<dim>                &linear_dof_handler,
         const TrilinosWrappers::SparseMatrix &linear_matrix,
         const Density                        &rho,
         const double                          jump) const;

    /**
     * ‖λ − λ_h‖_{H^{-1}(ω)} with the exact λ of @p data and λ_h of
     * @p lambda_h (DiscreteAction::lambda_h(), ghosted) on the dual cells of
     * @p dual_mesh, and λ_h = 0 on the strip ω ∖ ω_h, as in the L²(ω)
     * error (ErrorNorms). The composite rule takes the cells where λ − λ_h
     * varies by more than a tenth of max |λ_h|: where λ jumps, not where it
     * is smooth, on which it varies by O(h). @p dof_handler is the scalar
     * P1/Q1 space of the solution and @p laplace_matrix its Laplacian A
     * (DiscreteProblem::laplace_matrix()): the coarse level of norm().
     */
    double
    lambda_error(const DoFHandler<dim>                &dof_handler,
                 const TrilinosWrappers::SparseMatrix &laplace_matrix,
                 const DualMesh<dim>                  &dual_mesh,
                 const TrilinosWrappers::MPI::Vector  &lambda_h,
                 const ProblemData<dim>               &data) const;

  private:
    using VectorType = typename RieszOperator<dim>::VectorType;

    /**
     * F_j = ∫ ρ φ_j on the representative's space of @p dof_handler,
     * condensed with @p constraints, into @p rhs.
     */
    void
    assemble_density(const DoFHandler<dim>           &dof_handler,
                     const AffineConstraints<double> &constraints,
                     const Density                   &rho,
                     const double                     jump,
                     VectorType                      &rhs) const;

    const Discretization<dim>                &discretization;
    const std::unique_ptr<FiniteElement<dim>> fe;
    const Quadrature<dim>                     cell_quadrature;
    const DualCellQuadrature<dim>             density_quadrature;
    const DualCellQuadrature<dim>             jump_quadrature;
  };
} // namespace membranes

#endif
