#ifndef membranes_error_norms_h
#define membranes_error_norms_h

#include <array>
#include <deal.II/base/index_set.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/discrete_action.h>
#include <membranes/discretization.h>
#include <membranes/problem_data.h>

namespace membranes
{
  using namespace dealii;

  /**
   * Errors against a known exact solution:
   * |u_i − u_ih|_{H1(ω)}, ‖u_i − u_ih‖_{L2(ω)} for both membranes, and
   * ‖λ − λ_h‖_{L2(ω_h)}, where λ_h is piecewise constant on the dual cells
   * D_a and ω_h is their union (ω minus a strip along ∂ω).
   *
   * All integrals use the DualCellQuadrature of DiscreteAction, so
   * that each quadrature point knows the dual cell D_a it lies in and λ_h
   * is evaluated exactly; the same rule integrates the displacement errors
   * over the whole cell.
   */
  template <int dim>
  class ErrorNorms
  {
  public:
    using VectorType = TrilinosWrappers::MPI::Vector;

    struct Errors
    {
      std::array<double, 2> u_H1;      ///< H1 seminorm errors of u1, u2.
      std::array<double, 2> u_L2;      ///< L2 errors of u1, u2.
      double                lambda_L2; ///< L2(ω_h) error of λ_h.
    };

    ErrorNorms(const Discretization<dim> &discretization,
               const ProblemData<dim>    &data);

    /** With @p lambda_h the λ_h of @p action (DiscreteAction::lambda_h()). */
    Errors
    compute(const DoFHandler<dim>     &dof_handler,
            const VectorType          &ghosted_solution,
            const DiscreteAction<dim> &action,
            const VectorType          &lambda_h,
            const MPI_Comm             mpi_communicator) const;

  private:
    const Discretization<dim> &discretization;
    const ProblemData<dim>    &data;
  };
} // namespace membranes

#endif
