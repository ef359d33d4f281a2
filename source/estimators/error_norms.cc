#include <cmath>
#include <deal.II/base/mpi.h>
#include <deal.II/fe/fe_values.h>
#include <membranes/estimators/error_norms.h>
#include <membranes/mesh/cell_loop.h>

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
  ErrorNorms<dim>::compute(const DoFHandler<dim> &dof_handler,
                           const BlockVectorType &ghosted_solution,
                           const DualMesh<dim>   &dual_mesh,
                           const VectorType      &lambda_h,
                           const MPI_Comm         mpi_communicator) const
  {
    // All six norms in one pass over the cells (see the class comment for
    // why not VectorTools::integrate_difference()).
    //
    // What one thread needs on a cell: u_h, λ_h, u, λ and the gradients
    // at the points of the dual-cell quadrature.
    struct Scratch
    {
      Scratch(const Discretization<dim> &discretization,
              const DualMesh<dim>       &dual_mesh,
              const VectorType          &lambda_h)
        : values(discretization,
                 dual_mesh,
                 lambda_h,
                 update_values | update_gradients | update_quadrature_points |
                   update_JxW_values)
      {
        const unsigned int n_q_points = values.fe_values.n_quadrature_points;
        for (unsigned int i = 0; i < 2; ++i)
          {
            uh[i].resize(n_q_points);
            grad_uh[i].resize(n_q_points);
          }
      }
      DualCellValues<dim>                        values;
      std::array<std::vector<double>, 2>         uh;
      std::array<std::vector<Tensor<1, dim>>, 2> grad_uh;
      typename ProblemData<dim>::ExactValues     exact;
    };
    // Squared norms on one cell, and summed over the locally owned cells.
    using Squares = std::array<double, 6>;
    Squares squares{};

    run_on_cells<Squares>(
      dof_handler,
      [&]() {
        return std::make_unique<Scratch>(discretization, dual_mesh, lambda_h);
      },
      [&](const auto &cell, Scratch &scratch, Squares &cell_squares) {
        cell_squares = Squares{};
        if (!cell->is_locally_owned())
          return;
        scratch.values.reinit(cell, ghosted_solution);
        const FEValues<dim> &fe_values = scratch.values.fe_values;
        data.set_gradient_step(1e-4 * cell->diameter());
        const auto &points = fe_values.get_quadrature_points();
        const FEValuesExtractors::Scalar scalar(0);
        for (unsigned int i = 0; i < 2; ++i)
          {
            fe_values[scalar].get_function_values_from_local_dof_values(
              scratch.values.local_dofs[i], scratch.uh[i]);
            fe_values[scalar].get_function_gradients_from_local_dof_values(
              scratch.values.local_dofs[i], scratch.grad_uh[i]);
          }
        data.exact_solution_list(points, scratch.exact);
        const auto &exact = scratch.exact;

        for (const unsigned int q : fe_values.quadrature_point_indices())
          {
            const double JxW = fe_values.JxW(q);
            for (unsigned int i = 0; i < 2; ++i)
              {
                cell_squares[i] +=
                  (exact.grad_u[i][q] - scratch.grad_uh[i][q]).norm_square() *
                  JxW;
                cell_squares[2 + i] +=
                  std::pow(exact.u[i][q] - scratch.uh[i][q], 2) * JxW;
              }
            // λ_h = 0 on the strip ω ∖ ω_h.
            const bool   in_omega_h = scratch.values.in_omega_h[q];
            const double lambda_error =
              exact.lambda[q] - (in_omega_h ? scratch.values.lambda_h[q] : 0.);
            cell_squares[in_omega_h ? 4 : 5] +=
              lambda_error * lambda_error * JxW;
          }
      },
      [&](const Squares &cell_squares) {
        for (unsigned int k = 0; k < squares.size(); ++k)
          squares[k] += cell_squares[k];
      });

    for (double &square : squares)
      square = Utilities::MPI::sum(square, mpi_communicator);
    return {{{std::sqrt(squares[0]), std::sqrt(squares[1])}},
            {{std::sqrt(squares[2]), std::sqrt(squares[3])}},
            std::sqrt(squares[4] + squares[5]),
            std::sqrt(squares[4])};
  }



  template class ErrorNorms<2>;
} // namespace membranes
