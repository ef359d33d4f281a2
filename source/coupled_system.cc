#include <Epetra_CrsMatrix.h>
#include <cmath>
#include <deal.II/dofs/dof_tools.h>
#include <membranes/coupled_system.h>

namespace membranes
{
  namespace
  {
    /**
     * @p matrix ← D @p matrix D in place, for the diagonal D of @p scaling
     * (ghosted: it holds the entries of every column of the locally owned
     * rows, see column_scaling()).
     */
    void
    scale_symmetrically(const TrilinosWrappers::SparseMatrix &matrix,
                        const TrilinosWrappers::MPI::Vector  &scaling)
    {
      // Epetra's row views point into the matrix's storage, writable even
      // through a const matrix (as in DecoupledSystem).
      const Epetra_CrsMatrix &epetra = matrix.trilinos_matrix();
      std::vector<double>     column_scaling(epetra.NumMyCols());
      for (int c = 0; c < epetra.NumMyCols(); ++c)
        column_scaling[c] = scaling[epetra.GCID64(c)];
      for (int row = 0; row < epetra.NumMyRows(); ++row)
        {
          int     n_entries;
          double *values;
          int    *columns;
          epetra.ExtractMyRowView(row, n_entries, values, columns);
          const double row_scaling = scaling[epetra.GRID64(row)];
          for (int k = 0; k < n_entries; ++k)
            values[k] *= row_scaling * column_scaling[columns[k]];
        }
    }



    /**
     * @p scaling with the entries of every column of the locally owned rows
     * of @p matrix. These are more than the locally relevant DoFs: a cell
     * of another process adds to an owned row the columns of the parents
     * of its hanging vertices, which need not lie on a cell of this
     * process.
     */
    TrilinosWrappers::MPI::Vector
    column_scaling(const TrilinosWrappers::SparseMatrix &matrix,
                   const TrilinosWrappers::MPI::Vector  &scaling)
    {
      IndexSet columns(matrix.trilinos_matrix().ColMap());
      columns.add_indices(scaling.locally_owned_elements());
      TrilinosWrappers::MPI::Vector ghosted(scaling.locally_owned_elements(),
                                            columns,
                                            scaling.get_mpi_communicator());
      ghosted = scaling;
      return ghosted;
    }
  } // namespace



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
  CoupledSystem<dim>::setup(const MeshOperator<dim> &mesh_operator)
  {
    this->mesh                         = &mesh_operator;
    const DoFHandler<dim> &dof_handler = mesh_operator.get_dof_handler();
    const IndexSet &locally_owned_dofs = mesh_operator.locally_owned_dofs();
    const IndexSet &locally_relevant_dofs =
      mesh_operator.locally_relevant_dofs();

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

    // The tension μ_i of the membrane of each locally owned DoF.
    tension.reinit(locally_owned_dofs, this->mpi_communicator);
    std::vector<types::global_dof_index> dof_indices(
      dof_handler.get_fe().n_dofs_per_cell());
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          cell->get_dof_indices(dof_indices);
          for (unsigned int i = 0; i < dof_indices.size(); ++i)
            if (locally_owned_dofs.is_element(dof_indices[i]))
              tension[dof_indices[i]] =
                this->data
                  .mu[dof_handler.get_fe().system_to_component_index(i).first];
        }
    tension.compress(VectorOperation::insert);
  }



  template <int dim>
  typename CoupledSystem<dim>::VectorType
  CoupledSystem<dim>::tension_scaling(const IndexSet &active_set) const
  {
    const double M       = this->data.mu[0] + this->data.mu[1];
    VectorType   scaling = tension;
    for (const auto &dofs : this->mesh->locally_relevant_vertices())
      if (active_set.is_element(dofs[0]))
        for (const auto dof : dofs)
          if (this->mesh->locally_owned_dofs().is_element(dof))
            scaling[dof] = M;
    for (auto &entry : scaling)
      entry = 1 / std::sqrt(entry);
    scaling.compress(VectorOperation::insert);
    return scaling;
  }



  template <int dim>
  void
  CoupledSystem<dim>::solve(const IndexSet         &active_set,
                            VectorType             &solution,
                            const LinearTolerances &tolerances,
                            ActiveSetStatistics    &statistics)
  {
    const MeshOperator<dim> &mesh = *this->mesh;
    VectorType               scaling;
    {
      TimerOutput::Scope scope(this->timer, "assembly");
      constraints.clear();
      constraints.reinit(mesh.locally_relevant_dofs());
      for (const auto &dofs : mesh.locally_relevant_vertices())
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
      for (const auto &cell : mesh.get_dof_handler().active_cell_iterators())
        if (cell->is_locally_owned())
          {
            cell_system.reinit_operator(cell);
            cell_system.set_loads(mesh.cell_loads(cell));
            constraints.distribute_local_to_global(cell_system.matrix,
                                                   cell_system.rhs,
                                                   cell_system.dof_indices,
                                                   this->system_matrix,
                                                   this->system_rhs);
          }
      this->system_matrix.compress(VectorOperation::add);
      this->system_rhs.compress(VectorOperation::add);

      // The system scaled by D = diag(m_j^{-1/2}), m_j = μ_i for the DoFs
      // of membrane i at inactive vertices and on ∂ω, μ1 + μ2 for both
      // DoFs of an active vertex. Its residual D r then has the norm
      // Σ_a (r_W,a² / μ̄ + r_S,a² / (μ1 + μ2)) (sums over active vertices
      // only r_S), so one bound on it bounds r_S and r_W each on its own
      // scale.
      scaling = tension_scaling(active_set);
      scale_symmetrically(this->system_matrix,
                          column_scaling(this->system_matrix, scaling));
      this->system_rhs.scale(scaling);
    }

    const double tolerance =
      std::min(tolerances.contact / std::sqrt(this->data.mu_bar),
               tolerances.sum / std::sqrt(this->data.mu[0] + this->data.mu[1]));
    this->solve_linear_system(this->system_matrix,
                              this->system_rhs,
                              constraints,
                              solution,
                              tolerance,
                              statistics,
                              nullptr,
                              &scaling);
  }



  template <int dim>
  void
  CoupledSystem<dim>::clear()
  {
    ActiveSetSystem<dim>::clear();
    tension.clear();
    constraints.clear();
  }



  template class CoupledSystem<2>;
} // namespace membranes
