#include <deal.II/dofs/dof_tools.h>
#include <membranes/coupled_system.h>

namespace membranes
{
  template <int dim>
  CoupledSystem<dim>::CoupledSystem(const Parameters::Solver  &parameters,
                                    const Discretization<dim> &discretization,
                                    const ProblemData<dim>    &data,
                                    TimerOutput               &timer,
                                    const MPI_Comm             mpi_communicator)
    : ActiveSetSystem<dim>("coupled",
                           parameters,
                           discretization,
                           data,
                           timer,
                           mpi_communicator)
  {}



  template <int dim>
  void
  CoupledSystem<dim>::setup(const DoFHandler<dim> &dof_handler,
                            const IndexSet        &locally_owned_dofs,
                            const IndexSet        &locally_relevant_dofs,
                            const DiscreteAction<dim> &)
  {
    this->dof_handler           = &dof_handler;
    this->locally_relevant_dofs = locally_relevant_dofs;

    // The contact constraint u1(a) = u2(a) only ever couples DoFs of
    // vertices that share a cell, so the full coupling of all DoFs of a
    // cell (condensed with the hanging node constraints) holds the matrix
    // of every active set. Boundary rows are constrained for good.
    this->make_mesh_constraints(dof_handler,
                                this->data.boundary_values(),
                                locally_relevant_dofs,
                                mesh_constraints);
    this->reinit_linear_system(dof_handler,
                               mesh_constraints,
                               locally_owned_dofs,
                               locally_relevant_dofs);
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
    {
      TimerOutput::Scope scope(this->timer, "assembly");
      constraints.clear();
      constraints.reinit(locally_relevant_dofs);
      for (const auto &dofs : action.locally_relevant_vertices())
        if (active_set.is_element(dofs[0]))
          {
            constraints.add_line(dofs[0]);
            constraints.add_entry(dofs[0], dofs[1], 1.0);
          }
      constraints.merge(mesh_constraints);
      constraints.close();
      constraints.distribute(solution);

      this->system_matrix = 0;
      this->system_rhs    = 0;
      CellSystem<dim> cell_system(this->discretization, this->data);
      for (const auto &cell : dof_handler->active_cell_iterators())
        if (cell->is_locally_owned())
          {
            cell_system.reinit_operator(cell);
            cell_system.set_loads(action.cell_loads(cell));
            constraints.distribute_local_to_global(cell_system.matrix,
                                                   cell_system.rhs,
                                                   cell_system.dof_indices,
                                                   this->system_matrix,
                                                   this->system_rhs);
          }
      this->system_matrix.compress(VectorOperation::add);
      this->system_rhs.compress(VectorOperation::add);
    }

    this->solve_linear_system(this->system_matrix,
                              this->system_rhs,
                              constraints,
                              solution,
                              tolerance,
                              statistics);
  }



  template class CoupledSystem<2>;
} // namespace membranes
