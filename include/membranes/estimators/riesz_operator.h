#ifndef membranes_riesz_operator_h
#define membranes_riesz_operator_h

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/la_parallel_vector.h>
#include <deal.II/matrix_free/fe_evaluation.h>
#include <deal.II/matrix_free/matrix_free.h>

namespace membranes
{
  using namespace dealii;

  /**
   * The H¹(ω) inner product of a finite element space V ⊂ H¹₀(ω),
   *
   *   (A + M)_{ij} = ∫_ω ∇φ_i·∇φ_j + φ_i φ_j,
   *
   * the matrix of the Riesz representative of NegativeNorm, as an operator
   * that is never assembled: its action is integrated cell by cell with
   * deal.II's MatrixFree and FEEvaluation (step-37, step-75), on
   * quadrilaterals and triangles alike (the degree is a run-time value).
   * The constraints (zero on ∂ω, hanging nodes) are resolved in the cell
   * loop, so the operator acts on the unconstrained DoFs, as the condensed
   * matrix would.
   *
   * It serves the p-multigrid of NegativeNorm (RieszMultigrid) as the
   * operator of the representative's space: vmult(), and the diagonal of
   * the Jacobi smoother.
   */
  template <int dim>
  class RieszOperator
  {
  public:
    using VectorType = LinearAlgebra::distributed::Vector<double>;

    /**
     * The operator on the space of @p dof_handler with @p constraints,
     * integrated by @p quadrature on the cells mapped by @p mapping.
     */
    RieszOperator(const Mapping<dim>              &mapping,
                  const DoFHandler<dim>           &dof_handler,
                  const AffineConstraints<double> &constraints,
                  const Quadrature<dim>           &quadrature);

    /** @p vector with the layout (owned and ghost DoFs) of the cell loop. */
    void
    initialize_dof_vector(VectorType &vector) const;

    /** That layout. */
    const std::shared_ptr<const Utilities::MPI::Partitioner> &
    get_partitioner() const;

    /** @p dst = (A + M) @p src. */
    void
    vmult(VectorType &dst, const VectorType &src) const;

    /** The same as vmult(): the operator is symmetric. */
    void
    Tvmult(VectorType &dst, const VectorType &src) const;

    /**
     * The inverse of the diagonal of A + M into @p inverse_diagonal, one on
     * the constrained DoFs (on which the operator is zero).
     */
    void
    compute_inverse_diagonal(VectorType &inverse_diagonal) const;

  private:
    using Integrator = FEEvaluation<dim, -1, 0, 1, double>;

    /** ∫_K ∇v·∇φ_i + v φ_i on the batch of cells of @p integrator. */
    void
    integrate_cell(Integrator &integrator) const;

    /** The cell loop of vmult() on the batches of cells in @p range. */
    void
    apply_cells(const MatrixFree<dim, double>               &matrix_free,
                VectorType                                  &dst,
                const VectorType                            &src,
                const std::pair<unsigned int, unsigned int> &range) const;

    MatrixFree<dim, double> matrix_free;
  };
} // namespace membranes

#endif
