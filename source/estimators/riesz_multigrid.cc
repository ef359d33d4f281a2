#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <membranes/estimators/riesz_multigrid.h>
#include <vector>

namespace membranes
{
  namespace
  {
    /**
     * An upper estimate of the largest eigenvalue of D⁻¹(A + M), @p riesz
     * with @p inverse_diagonal D⁻¹ and @p constraints: the largest Ritz
     * value of ten CG iterations, which approaches it from below, times 1.2
     * (as deal.II's PreconditionChebyshev), from a vector @p scratch that
     * holds all frequencies.
     */
    template <int dim>
    double
    largest_eigenvalue(
      const RieszOperator<dim> &riesz,
      const DiagonalMatrix<typename RieszOperator<dim>::VectorType>
                                              &inverse_diagonal,
      const AffineConstraints<double>         &constraints,
      typename RieszOperator<dim>::VectorType &scratch)
    {
      const IndexSet               &owned = scratch.locally_owned_elements();
      const types::global_dof_index first =
        owned.is_empty() ? 0 : owned.nth_index_in_set(0);
      for (unsigned int i = 0; i < scratch.locally_owned_size(); ++i)
        scratch.local_element(i) = (first + i) % 11;
      scratch.add(-scratch.mean_value());
      constraints.set_zero(scratch);

      double                 largest = 0;
      IterationNumberControl control(10, 1e-10, false, false);
      SolverCG<typename RieszOperator<dim>::VectorType> cg(control);
      cg.connect_eigenvalues_slot(
        [&largest](const std::vector<double> &eigenvalues) {
          if (!eigenvalues.empty())
            largest = eigenvalues.back();
        });
      typename RieszOperator<dim>::VectorType solution;
      riesz.initialize_dof_vector(solution);
      cg.solve(riesz, solution, scratch, inverse_diagonal);
      return 1.2 * largest;
    }
  } // namespace



  template <int dim>
  RieszMultigrid<dim>::RieszMultigrid(
    const RieszOperator<dim>                &riesz,
    const DoFHandler<dim>                   &dof_handler,
    const AffineConstraints<double>         &constraints,
    const DoFHandler<dim>                   &linear_dof_handler,
    const AffineConstraints<double>         &linear_constraints,
    const TrilinosWrappers::PreconditionAMG &linear_preconditioner)
    : riesz(riesz)
    , linear_preconditioner(linear_preconditioner)
    , embedding(dof_handler,
                constraints,
                riesz.get_partitioner(),
                linear_dof_handler,
                linear_constraints)
  {
    // The eigenvalue estimate here rather than in the first application:
    // its CG iteration then takes its vectors before, not besides, those of
    // the CG iteration this preconditions.
    riesz.compute_inverse_diagonal(inverse_diagonal.get_vector());
    riesz.initialize_dof_vector(residual);
    damping =
      1. / (0.55 *
            largest_eigenvalue(riesz, inverse_diagonal, constraints, residual));

    embedding.initialize_linear_vector(linear_residual);
    embedding.initialize_linear_vector(linear_correction);
  }



  template <int dim>
  void
  RieszMultigrid<dim>::vmult(VectorType &dst, const VectorType &src) const
  {
    inverse_diagonal.vmult(dst, src);
    dst *= damping;
    riesz.vmult(residual, dst);
    residual.sadd(-1., 1., src);
    linear_residual = 0.;
    embedding.restrict_and_add(linear_residual, residual);
    linear_preconditioner.vmult(linear_correction, linear_residual);
    embedding.prolongate(residual, linear_correction);
    dst += residual;
    riesz.vmult(residual, dst);
    residual.sadd(-damping, damping, src);
    inverse_diagonal.vmult_add(dst, residual);
  }



  template class RieszMultigrid<2>;
} // namespace membranes
