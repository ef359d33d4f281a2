#include <deal.II/matrix_free/tools.h>
#include <membranes/estimators/riesz_operator.h>

namespace membranes
{
  template <int dim>
  RieszOperator<dim>::RieszOperator(
    const Mapping<dim>              &mapping,
    const DoFHandler<dim>           &dof_handler,
    const AffineConstraints<double> &constraints,
    const Quadrature<dim>           &quadrature)
  {
    // One thread per process: the sums of the cell loop are then formed in
    // the same order on every run.
    typename MatrixFree<dim, double>::AdditionalData data;
    data.tasks_parallel_scheme = MatrixFree<dim, double>::AdditionalData::none;
    data.mapping_update_flags =
      update_values | update_gradients | update_JxW_values;
    matrix_free.reinit(mapping, dof_handler, constraints, quadrature, data);
  }



  template <int dim>
  void
  RieszOperator<dim>::initialize_dof_vector(VectorType &vector) const
  {
    matrix_free.initialize_dof_vector(vector);
  }



  template <int dim>
  const std::shared_ptr<const Utilities::MPI::Partitioner> &
  RieszOperator<dim>::get_partitioner() const
  {
    return matrix_free.get_vector_partitioner();
  }



  template <int dim>
  void
  RieszOperator<dim>::integrate_cell(Integrator &integrator) const
  {
    integrator.evaluate(EvaluationFlags::values | EvaluationFlags::gradients);
    for (const unsigned int q : integrator.quadrature_point_indices())
      {
        integrator.submit_gradient(integrator.get_gradient(q), q);
        integrator.submit_value(integrator.get_value(q), q);
      }
    integrator.integrate(EvaluationFlags::values | EvaluationFlags::gradients);
  }



  template <int dim>
  void
  RieszOperator<dim>::apply_cells(
    const MatrixFree<dim, double>               &matrix_free,
    VectorType                                  &dst,
    const VectorType                            &src,
    const std::pair<unsigned int, unsigned int> &range) const
  {
    Integrator integrator(matrix_free, range);
    for (unsigned int batch = range.first; batch < range.second; ++batch)
      {
        integrator.reinit(batch);
        integrator.read_dof_values(src);
        integrate_cell(integrator);
        integrator.distribute_local_to_global(dst);
      }
  }



  template <int dim>
  void
  RieszOperator<dim>::vmult(VectorType &dst, const VectorType &src) const
  {
    matrix_free.cell_loop(&RieszOperator::apply_cells, this, dst, src, true);
  }



  template <int dim>
  void
  RieszOperator<dim>::Tvmult(VectorType &dst, const VectorType &src) const
  {
    vmult(dst, src);
  }



  template <int dim>
  void
  RieszOperator<dim>::compute_inverse_diagonal(
    VectorType &inverse_diagonal) const
  {
    matrix_free.initialize_dof_vector(inverse_diagonal);
    MatrixFreeTools::compute_diagonal(matrix_free,
                                      inverse_diagonal,
                                      &RieszOperator::integrate_cell,
                                      this);
    for (double &entry : inverse_diagonal)
      entry = (entry > 0. ? 1. / entry : 1.);
  }



  template class RieszOperator<2>;
} // namespace membranes
