#include <cmath>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparsity_tools.h>
#include <membranes/cell_system.h>
#include <membranes/coupled_system.h>

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
  CoupledSystem<dim>::setup(
    const DiscreteProblem<dim>      &problem,
    const DoFHandler<dim>           &dof_handler,
    const AffineConstraints<double> &hanging_node_constraints,
    const DoFHandler<dim> &)
  {
    this->problem                 = &problem;
    this->dof_handler             = &dof_handler;
    const IndexSet &owned_dofs    = problem.locally_owned_dofs();
    const IndexSet &relevant_dofs = problem.locally_relevant_dofs();
    make_mesh_constraints(*this->discretization.mapping,
                          dof_handler,
                          hanging_node_constraints,
                          this->data.boundary_values(),
                          mesh_constraints);
    this->linear_solver.reinit(dof_handler);

    // The contact constraint u1(a) = u2(a) only ever couples DoFs of
    // vertices that share a cell, so the full coupling of all DoFs of a
    // cell (condensed with the constraints of the mesh) holds the matrix
    // of every active set, as step-41's pattern holds that of every active
    // set of its obstacle problem.
    DynamicSparsityPattern dsp(relevant_dofs);
    DoFTools::make_sparsity_pattern(dof_handler, dsp, mesh_constraints, false);
    SparsityTools::distribute_sparsity_pattern(dsp,
                                               owned_dofs,
                                               this->mpi_communicator,
                                               relevant_dofs);
    system_matrix.reinit(owned_dofs, owned_dofs, dsp, this->mpi_communicator);
    system_rhs.reinit(owned_dofs, this->mpi_communicator);

    // The tension μ_i of the membrane of each locally owned DoF: the DoFs
    // of (u1, u2) alternate.
    tension.reinit(owned_dofs, this->mpi_communicator);
    for (unsigned int p = 0; p < tension.locally_owned_size(); ++p)
      tension.begin()[p] = this->data.mu[p % 2];
  }



  template <int dim>
  void
  CoupledSystem<dim>::assemble_system()
  {
    CellSystem<dim> cell_system(this->discretization, this->data);
    system_matrix = 0;
    system_rhs    = 0;
    for (const auto &cell : dof_handler->active_cell_iterators())
      if (cell->is_locally_owned())
        {
          cell_system.reinit_operator(cell);
          cell_system.set_loads(this->problem->cell_loads(cell));
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
  typename CoupledSystem<dim>::VectorType
  CoupledSystem<dim>::tension_scaling(const IndexSet &active_set) const
  {
    const double M       = this->data.mu[0] + this->data.mu[1];
    VectorType   scaling = tension;
    for (const auto &dofs : this->problem->locally_relevant_vertices())
      if (active_set.is_element(dofs[0]))
        for (const auto dof : dofs)
          if (this->problem->locally_owned_dofs().is_element(dof))
            scaling[dof] = M;
    for (auto &entry : scaling)
      entry = 1 / std::sqrt(entry);
    scaling.compress(VectorOperation::insert);
    return scaling;
  }



  template <int dim>
  void
  CoupledSystem<dim>::assemble(const IndexSet &active_set, VectorType &solution)
  {
    constraints.clear();
    constraints.reinit(this->problem->locally_relevant_dofs());
    for (const auto &dofs : this->problem->locally_relevant_vertices())
      if (active_set.is_element(dofs[0]))
        {
          constraints.add_line(dofs[0]);
          constraints.add_entry(dofs[0], dofs[1], 1.0);
        }
    constraints.merge(mesh_constraints);
    constraints.close();
    constraints.distribute(solution);
    assemble_system();
    scaling = tension_scaling(active_set);
  }



  template <int dim>
  void
  CoupledSystem<dim>::solve(VectorType             &solution,
                            const LinearTolerances &tolerances,
                            ActiveSetStatistics    &statistics)
  {
    if (this->linear_solver.is_direct())
      this->linear_solver.solve_direct(system_matrix, solution, system_rhs);
    else
      {
        // CG on the system scaled by D = diag(m_j^{-1/2}), m_j = μ_i for
        // the DoFs of membrane i at inactive vertices and on ∂ω, μ1 + μ2
        // for both DoFs of an active vertex: D K D y = D b, u = D y. Its
        // residual D r then has the norm Σ_a (r_W,a² / μ̄ + r_S,a² /
        // (μ1 + μ2)) (sums over active vertices only r_S), so one bound on
        // it bounds r_S and r_W each on its own scale. The AMG hierarchy of
        // K, seen through D⁻¹, preconditions it.
        VectorType inverse_scaling(scaling);
        for (auto &entry : inverse_scaling)
          entry = 1 / entry;
        VectorType rhs = system_rhs;
        rhs.scale(scaling);
        solution.scale(inverse_scaling);
        this->linear_solver.initialize_preconditioner(system_matrix);
        const double tolerance =
          std::min(tolerances.contact / std::sqrt(this->data.mu_bar),
                   tolerances.sum /
                     std::sqrt(this->data.mu[0] + this->data.mu[1]));
        statistics.linear_iterations += this->linear_solver.solve_cg(
          ScaledOperator<TrilinosWrappers::SparseMatrix>(system_matrix,
                                                         scaling),
          ScaledOperator<TrilinosWrappers::PreconditionAMG>(
            this->linear_solver.preconditioner(), inverse_scaling),
          solution,
          rhs,
          tolerance);
        this->linear_solver.clear();
        solution.scale(scaling);
      }
    constraints.distribute(solution);
  }



  template <int dim>
  void
  CoupledSystem<dim>::clear()
  {
    this->linear_solver.clear();
    system_matrix.clear();
    system_rhs.clear();
    tension.clear();
    scaling.clear();
    constraints.clear();
    mesh_constraints.clear();
  }



  template class CoupledSystem<2>;
} // namespace membranes
