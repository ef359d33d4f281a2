#ifndef membranes_riesz_multigrid_h
#define membranes_riesz_multigrid_h

#include <deal.II/base/subscriptor.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/diagonal_matrix.h>
#include <deal.II/lac/precondition.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
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
   *   x = S b,   x += P (A_1)^{-1}_{AMG} Pᵀ (b − (A + M) x),   x = S-step,
   *
   * with S Chebyshev smoothing of degree 1 on the diagonal D of A + M (a
   * damped Jacobi step, its damping set by the largest eigenvalue of
   * D⁻¹(A + M), which ten CG iterations estimate), P the embedding of V_1
   * into V_p (the nodal interpolation of a function of V_1 at the nodes of
   * V_p, exact because V_1 ⊂ V_p), and one V-cycle of algebraic multigrid
   * on the matrix A_1 of A + M on V_1. Pre- and post-smoothing are the same
   * polynomial and Pᵀ is the transpose of P, so the preconditioner is
   * symmetric and CG applies.
   *
   * Only A_1 and P are assembled: A_1 has the rows of a scalar field of the
   * solution, P at most four (P1: three) entries a row of V_p where no
   * hanging node constrains V_1. deal.II 9.4 has the transfer between the
   * two spaces too (MGTwoLevelTransfer), but it takes longer to set up than
   * this whole solve.
   */
  template <int dim>
  class RieszMultigrid : public Subscriptor
  {
  public:
    using VectorType = typename RieszOperator<dim>::VectorType;

    /**
     * The preconditioner of @p riesz on @p dof_handler with @p constraints,
     * with the coarse space of @p linear_dof_handler (degree 1, on the
     * same mesh) with @p linear_constraints, integrated by
     * @p linear_quadrature on the cells mapped by @p mapping.
     */
    RieszMultigrid(const RieszOperator<dim>        &riesz,
                   const DoFHandler<dim>           &dof_handler,
                   const AffineConstraints<double> &constraints,
                   const DoFHandler<dim>           &linear_dof_handler,
                   const AffineConstraints<double> &linear_constraints,
                   const Mapping<dim>              &mapping,
                   const Quadrature<dim>           &linear_quadrature);

    /** @p dst = one V-cycle applied to @p src. */
    void
    vmult(VectorType &dst, const VectorType &src) const;

  private:
    using Smoother = PreconditionChebyshev<RieszOperator<dim>,
                                           VectorType,
                                           DiagonalMatrix<VectorType>>;

    const RieszOperator<dim>         &riesz;
    Smoother                          smoother;
    TrilinosWrappers::SparseMatrix    prolongation;
    TrilinosWrappers::SparseMatrix    linear_matrix;
    TrilinosWrappers::PreconditionAMG amg;
    mutable VectorType                residual;
    mutable VectorType                linear_residual, linear_correction;
  };
} // namespace membranes

#endif
