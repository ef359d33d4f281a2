#include <deal.II/base/timer.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/numerics/vector_tools.h>
#include <map>
#include <membranes/cell_system.h>
#include <membranes/coupled_system.h>

namespace membranes
{
  template <int dim>
  CoupledSystem<dim>::CoupledSystem(const Parameters::Solver  &parameters,
                                    const Discretization<dim> &discretization,
                                    const ProblemData<dim>    &data,
                                    const MPI_Comm             mpi_communicator)
    : discretization(discretization)
    , data(data)
    , mpi_communicator(mpi_communicator)
    , linear_solver(parameters.linear_solver, mpi_communicator)
  {}



  template <int dim>
  void
  CoupledSystem<dim>::setup(const DoFHandler<dim>     &dof_handler,
                            const IndexSet            &locally_owned_dofs,
                            const IndexSet            &locally_relevant_dofs,
                            const DiscreteAction<dim> &action)
  {
    this->dof_handler           = &dof_handler;
    this->locally_relevant_dofs = locally_relevant_dofs;
    linear_solver.reinit(dof_handler);

    // The contact constraint u1(a) = u2(a) only ever couples DoFs of
    // vertices that share a cell, so the full coupling of all DoFs of a
    // cell (condensed with the hanging node constraints) holds the matrix
    // of every active set. Boundary rows are constrained for good.
    make_constraints(action, IndexSet(dof_handler.n_dofs()));
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
  CoupledSystem<dim>::make_constraints(const DiscreteAction<dim> &action,
                                       const IndexSet            &active_set)
  {
    constraints.clear();
    constraints.reinit(locally_relevant_dofs);
    DoFTools::make_hanging_node_constraints(*dof_handler, constraints);

    for (const auto &a : action.vertices())
      if (active_set.is_element(a.dof[0]))
        {
          constraints.add_line(a.dof[0]);
          constraints.add_entry(a.dof[0], a.dof[1], 1.0);
        }

    std::map<types::boundary_id, const Function<dim> *> boundary_functions;
    for (const auto id : dof_handler->get_triangulation().get_boundary_ids())
      boundary_functions[id] = &data.boundary_values();
    VectorTools::interpolate_boundary_values(*discretization.mapping,
                                             *dof_handler,
                                             boundary_functions,
                                             constraints);
    constraints.close();
  }



  template <int dim>
  void
  CoupledSystem<dim>::assemble_system()
  {
    system_matrix = 0;
    system_rhs    = 0;

    CellSystem<dim> cell_system(discretization, data);
    for (const auto &cell : dof_handler->active_cell_iterators())
      if (cell->is_locally_owned())
        {
          cell_system.reinit(cell);
          constraints.distribute_local_to_global(cell_system.matrix,
                                                 cell_system.rhs,
                                                 cell_system.dof_indices,
                                                 system_matrix,
                                                 system_rhs);
        }
    system_matrix.compress(VectorOperation::add);
    system_rhs.compress(VectorOperation::add);
  }



  template <int dim>
  void
  CoupledSystem<dim>::prepare(const VectorType &,
                              const double,
                              ActiveSetStatistics &)
  {}



  template <int dim>
  void
  CoupledSystem<dim>::solve(const DiscreteAction<dim> &action,
                            const IndexSet            &active_set,
                            VectorType                &solution,
                            const double               tolerance,
                            ActiveSetStatistics       &statistics)
  {
    Timer timer;
    make_constraints(action, active_set);
    constraints.distribute(solution);
    assemble_system();
    statistics.assembly_time += timer.wall_time();

    timer.restart();
    statistics.linear_iterations +=
      linear_solver.solve(system_matrix, solution, system_rhs, tolerance);
    constraints.distribute(solution);
    statistics.solve_time += timer.wall_time();
  }



  template <int dim>
  std::string
  CoupledSystem<dim>::description() const
  {
    return "coupled, " + linear_solver.method();
  }



  template class CoupledSystem<2>;
} // namespace membranes
