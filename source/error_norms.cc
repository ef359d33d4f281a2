#include <cmath>
#include <deal.II/base/mpi.h>
#include <deal.II/fe/fe_values.h>
#include <membranes/error_norms.h>

namespace membranes
{
  template <int dim>
  ErrorNorms<dim>::ErrorNorms(const Discretization<dim> &discretization,
                              const ProblemData<dim>    &data)
    : discretization(discretization)
    , data(data)
  {}



  template <int dim>
  typename ErrorNorms<dim>::Errors
  ErrorNorms<dim>::compute(const DoFHandler<dim>     &dof_handler,
                           const VectorType          &ghosted_solution,
                           const DiscreteAction<dim> &action,
                           const MPI_Comm             mpi_communicator) const
  {
    const FiniteElement<dim> &fe = *discretization.fe;
    FEValues<dim>             fe_values(*discretization.mapping,
                            fe,
                            action.dual_quadrature().quadrature(),
                            update_values | update_gradients |
                              update_quadrature_points | update_JxW_values);
    const unsigned int        n_q_points = fe_values.n_quadrature_points;
    std::array<std::vector<double>, 2>         uh, u;
    std::array<std::vector<Tensor<1, dim>>, 2> grad_uh, grad_u;
    std::vector<double>                        lambda(n_q_points), lambda_h;
    std::vector<bool>                          in_omega_h;
    std::vector<double>                        local_dofs(fe.n_dofs_per_cell());
    for (unsigned int i = 0; i < 2; ++i)
      {
        uh[i].resize(n_q_points);
        u[i].resize(n_q_points);
        grad_uh[i].resize(n_q_points);
        grad_u[i].resize(n_q_points);
      }

    // Squared norms, summed over the locally owned cells.
    std::array<double, 5> squares{};
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          cell->get_dof_values(ghosted_solution,
                               local_dofs.begin(),
                               local_dofs.end());
          action.lambda_h_values(cell, lambda_h, &in_omega_h);
          data.set_gradient_step(1e-4 * cell->diameter());
          const auto &points = fe_values.get_quadrature_points();
          for (unsigned int i = 0; i < 2; ++i)
            {
              const FEValuesExtractors::Scalar membrane(i);
              fe_values[membrane].get_function_values_from_local_dof_values(
                local_dofs, uh[i]);
              fe_values[membrane].get_function_gradients_from_local_dof_values(
                local_dofs, grad_uh[i]);
              data.exact_displacement(i).value_list(points, u[i]);
              data.exact_displacement(i).gradient_list(points, grad_u[i]);
            }
          data.exact_lambda().value_list(points, lambda);

          for (unsigned int q = 0; q < n_q_points; ++q)
            {
              const double JxW = fe_values.JxW(q);
              for (unsigned int i = 0; i < 2; ++i)
                {
                  squares[i] +=
                    (grad_u[i][q] - grad_uh[i][q]).norm_square() * JxW;
                  squares[2 + i] += std::pow(u[i][q] - uh[i][q], 2) * JxW;
                }
              if (in_omega_h[q])
                squares[4] += std::pow(lambda[q] - lambda_h[q], 2) * JxW;
            }
        }

    for (double &square : squares)
      square = std::sqrt(Utilities::MPI::sum(square, mpi_communicator));
    return {{{squares[0], squares[1]}}, {{squares[2], squares[3]}}, squares[4]};
  }



  template class ErrorNorms<2>;
} // namespace membranes
