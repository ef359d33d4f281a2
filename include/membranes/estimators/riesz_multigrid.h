#ifndef membranes_riesz_multigrid_h
#define membranes_riesz_multigrid_h

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/diagonal_matrix.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <membranes/estimators/linear_embedding.h>
#include <membranes/estimators/riesz_operator.h>

namespace membranes
{
  using namespace dealii;

  /**
   * A two-level p-multigrid preconditioner for the H¹ inner product A + M
   * (RieszOperator) on a space V_p of degree p ≥ 2, whose coarse level is
   * the space V_1 ⊂ V_p of degree 1 on the same mesh (the pattern of
   * deal.II's step-75 with a single p-step). One application is the
   * V-cycle
   *
   *   x = ω D⁻¹ b,   x += P (A_1)^{-1}_{AMG} Pᵀ (b − (A + M) x),
   *   x += ω D⁻¹ (b − (A + M) x),
   *
   * with damped Jacobi smoothing on the diagonal D of A + M, P the
   * embedding of V_1 into V_p (LinearEmbedding) and one V-cycle of
   * algebraic multigrid on a matrix A_1 of V_1 spectrally equivalent to
   * A + M there (NegativeNorm::norm() takes the Laplacian of the mesh).
   * Pre- and post-smoothing are the same and Pᵀ is the transpose of P, so
   * the preconditioner is symmetric and CG applies.
   *
   * The damping ω = 1 / (0.55 λ̂) is that of deal.II's PreconditionChebyshev
   * of degree 1 on [λ̂/10, λ̂], for an estimate λ̂ of the largest eigenvalue
   * of D⁻¹(A + M). Chebyshev smoothing of degree 2 to 4 saves at most one
   * CG iteration of the six to eight at 526 338 DoFs, each at the price of
   * two more products with A + M per V-cycle.
   */
  template <int dim>
  class RieszMultigrid
  {
  public:
    using VectorType = typename RieszOperator<dim>::VectorType;

    /**
     * The preconditioner of @p riesz on @p dof_handler with @p constraints,
     * with the coarse space of @p linear_dof_handler (degree 1, on the
     * same mesh) with @p linear_constraints, on which
     * @p linear_preconditioner is the AMG of A_1.
     */
    RieszMultigrid(
      const RieszOperator<dim>                &riesz,
      const DoFHandler<dim>                   &dof_handler,
      const AffineConstraints<double>         &constraints,
      const DoFHandler<dim>                   &linear_dof_handler,
      const AffineConstraints<double>         &linear_constraints,
      const TrilinosWrappers::PreconditionAMG &linear_preconditioner);

    /** @p dst = one V-cycle applied to @p src. */
    void
    vmult(VectorType &dst, const VectorType &src) const;

  private:
    const RieszOperator<dim>                &riesz;
    const TrilinosWrappers::PreconditionAMG &linear_preconditioner;
    DiagonalMatrix<VectorType>               inverse_diagonal;
    double                                   damping;
    const LinearEmbedding<dim>               embedding;
    mutable VectorType                       residual;
    mutable VectorType                       linear_residual, linear_correction;
  };
} // namespace membranes

#endif
