#include <deal.II/base/timer.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/numerics/vector_tools.h>
#include <map>
#include <membranes/active_set_system.h>

namespace membranes
{
  template <int dim>
  ActiveSetSystem<dim>::ActiveSetSystem(
    const std::string         &method,
    const Parameters::Solver  &parameters,
    const Discretization<dim> &discretization,
    const ProblemData<dim>    &data,
    const MPI_Comm             mpi_communicator)
    : discretization(discretization)
    , data(data)
    , mpi_communicator(mpi_communicator)
    , method(method)
    , linear_solver(parameters.linear_solver, mpi_communicator)
  {}



  template <int dim>
  std::string
  ActiveSetSystem<dim>::description() const
  {
    return method + ", " + linear_solver.method();
  }



  template <int dim>
  void
  ActiveSetSystem<dim>::add_boundary_values(
    const DoFHandler<dim>     &dof_handler,
    const Function<dim>       &boundary_values,
    AffineConstraints<double> &constraints) const
  {
    std::map<types::boundary_id, const Function<dim> *> boundary_functions;
    for (const auto id : dof_handler.get_triangulation().get_boundary_ids())
      boundary_functions[id] = &boundary_values;
    VectorTools::interpolate_boundary_values(*discretization.mapping,
                                             dof_handler,
                                             boundary_functions,
                                             constraints);
  }



  template <int dim>
  void
  ActiveSetSystem<dim>::reinit_linear_system(
    const DoFHandler<dim>           &dof_handler,
    const AffineConstraints<double> &constraints,
    const IndexSet                  &locally_owned_dofs,
    const IndexSet                  &locally_relevant_dofs)
  {
    linear_solver.reinit(dof_handler);
    DynamicSparsityPattern dsp(locally_relevant_dofs);
    DoFTools::make_sparsity_pattern(dof_handler, dsp, constraints, false);
    SparsityTools::distribute_sparsity_pattern(dsp,
                                               locally_owned_dofs,
                                               mpi_communicator,
                                               locally_relevant_dofs);
    system_matrix.reinit(locally_owned_dofs,
                         locally_owned_dofs,
                         dsp,
                         mpi_communicator);
    system_rhs.reinit(locally_owned_dofs, mpi_communicator);
  }



  template <int dim>
  void
  ActiveSetSystem<dim>::solve_linear_system(
    const AffineConstraints<double> &constraints,
    VectorType                      &x,
    const double                     tolerance,
    ActiveSetStatistics             &statistics)
  {
    Timer timer;
    statistics.linear_iterations +=
      linear_solver.solve(system_matrix, x, system_rhs, tolerance);
    constraints.distribute(x);
    statistics.solve_time += timer.wall_time();
  }



  template class ActiveSetSystem<2>;
} // namespace membranes
