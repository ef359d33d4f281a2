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
    TimerOutput               &timer,
    const MPI_Comm             mpi_communicator)
    : discretization(discretization)
    , data(data)
    , timer(timer)
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
  ActiveSetSystem<dim>::clear()
  {
    system_matrix.clear();
    system_rhs.clear();
    linear_solver.clear();
  }



  template <int dim>
  void
  ActiveSetSystem<dim>::make_mesh_constraints(
    const DoFHandler<dim>           &dof_handler,
    const AffineConstraints<double> &hanging_node_constraints,
    const Function<dim>             &boundary_values,
    AffineConstraints<double>       &constraints) const
  {
    constraints.clear();
    constraints.reinit(hanging_node_constraints.get_local_lines());
    std::map<types::boundary_id, const Function<dim> *> boundary_functions;
    for (const auto id : dof_handler.get_triangulation().get_boundary_ids())
      boundary_functions[id] = &boundary_values;
    VectorTools::interpolate_boundary_values(*discretization.mapping,
                                             dof_handler,
                                             boundary_functions,
                                             constraints);
    // A hanging vertex on ∂ω keeps its hanging node constraint, its value
    // that of the boundary values of its parents.
    constraints.merge(hanging_node_constraints,
                      AffineConstraints<double>::right_object_wins);
    constraints.close();
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
    const TrilinosWrappers::SparseMatrix &matrix,
    const VectorType                     &rhs,
    const AffineConstraints<double>      &constraints,
    VectorType                           &x,
    const double                          tolerance,
    ActiveSetStatistics                  &statistics,
    const TrilinosWrappers::SparseMatrix *mesh_matrix,
    const VectorType                     *scaling)
  {
    TimerOutput::Scope scope(timer, "solve");
    if (scaling)
      {
        VectorType inverse(*scaling);
        for (auto &entry : inverse)
          entry = 1 / entry;
        x.scale(inverse);
      }
    statistics.linear_iterations +=
      linear_solver.solve(matrix, x, rhs, tolerance, mesh_matrix);
    if (scaling)
      x.scale(*scaling);
    constraints.distribute(x);
  }



  template <int dim>
  bool
  ActiveSetSystem<dim>::has_mesh_preconditioner() const
  {
    return linear_solver.has_mesh_preconditioner();
  }



  template class ActiveSetSystem<2>;
} // namespace membranes
