#include <deal.II/base/timer.h>
#include <deal.II/dofs/dof_tools.h>
#include <membranes/coupled_system.h>
#include <tuple>

namespace membranes
{
  template <int dim>
  CoupledSystem<dim>::CoupledSystem(const Parameters::Solver  &parameters,
                                    const Discretization<dim> &discretization,
                                    const ProblemData<dim>    &data,
                                    const MPI_Comm             mpi_communicator)
    : ActiveSetSystem<dim>("coupled",
                           parameters,
                           discretization,
                           data,
                           mpi_communicator)
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

    // The contact constraint u1(a) = u2(a) only ever couples DoFs of
    // vertices that share a cell, so the full coupling of all DoFs of a
    // cell (condensed with the hanging node constraints) holds the matrix
    // of every active set. Boundary rows are constrained for good.
    make_constraints(action, IndexSet(dof_handler.n_dofs()));
    this->reinit_linear_system(dof_handler,
                               constraints,
                               locally_owned_dofs,
                               locally_relevant_dofs);
  }



  template <int dim>
  void
  CoupledSystem<dim>::make_constraints(const DiscreteAction<dim> &action,
                                       const IndexSet            &active_set)
  {
    constraints.clear();
    constraints.reinit(locally_relevant_dofs);
    DoFTools::make_hanging_node_constraints(*dof_handler, constraints);

    for (const auto &dofs : action.locally_relevant_vertices())
      if (active_set.is_element(dofs[0]))
        {
          constraints.add_line(dofs[0]);
          constraints.add_entry(dofs[0], dofs[1], 1.0);
        }

    this->add_boundary_values(*dof_handler,
                              this->data.boundary_values(),
                              constraints);
    constraints.close();
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
    this->assemble_system(*dof_handler,
                          constraints,
                          [](const auto &, const CellSystem<dim> &cell_system) {
                            return std::tie(cell_system.matrix,
                                            cell_system.rhs,
                                            cell_system.dof_indices);
                          });
    statistics.assembly_time += timer.wall_time();

    this->solve_linear_system(constraints, solution, tolerance, statistics);
  }



  template class CoupledSystem<2>;
} // namespace membranes
