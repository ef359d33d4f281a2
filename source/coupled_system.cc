#include <algorithm>
#include <cmath>
#include <membranes/coupled_system.h>
#include <membranes/matrix_rows.h>

namespace membranes
{
  namespace
  {
    /**
     * @p owned with the entries of every column of the locally owned rows
     * of @p matrix as well. These are more than the locally relevant DoFs:
     * a cell of another process adds to an owned row the columns of the
     * parents of its hanging vertices, which need not lie on a cell of
     * this process.
     */
    TrilinosWrappers::MPI::Vector
    on_columns_of(const TrilinosWrappers::SparseMatrix &matrix,
                  const TrilinosWrappers::MPI::Vector  &owned)
    {
      IndexSet columns(matrix.trilinos_matrix().ColMap());
      columns.add_indices(owned.locally_owned_elements());
      TrilinosWrappers::MPI::Vector ghosted(owned.locally_owned_elements(),
                                            columns,
                                            owned.get_mpi_communicator());
      ghosted = owned;
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
                                mesh_operator.hanging_node_constraints(),
                                this->data.boundary_values(),
                                mesh_constraints);
    this->reinit_linear_system(dof_handler,
                               mesh_constraints,
                               locally_owned_dofs,
                               locally_relevant_dofs);

    // Where the entries of each column of the mesh's operator go in the
    // system matrix.
    const MatrixRows operator_rows(mesh_operator.stiffness_matrix());
    const MatrixRows rows(this->system_matrix);
    column_of_operator_column.resize(operator_rows.n_columns());
    for (unsigned int c = 0; c < operator_rows.n_columns(); ++c)
      column_of_operator_column[c] =
        rows.local_column(operator_rows.global_column(c));
    make_mesh_rhs();

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
  void
  CoupledSystem<dim>::make_mesh_rhs()
  {
    // The loads of each cell, condensed with mesh_constraints; the cell
    // matrix lifts the boundary values on the cells that have DoFs with
    // one, and is not needed elsewhere.
    const MeshOperator<dim> &mesh = *this->mesh;
    CellSystem<dim>          cell_system(this->discretization, this->data);
    const FullMatrix<double> no_matrix(cell_system.matrix.m());
    const auto               lifts = [&](const types::global_dof_index j) {
      return mesh_constraints.is_inhomogeneously_constrained(j);
    };
    mesh_rhs.reinit(mesh.locally_owned_dofs(), this->mpi_communicator);
    for (const auto &cell : mesh.get_dof_handler().active_cell_iterators())
      if (cell->is_locally_owned())
        {
          cell->get_dof_indices(cell_system.dof_indices);
          const bool lifting = std::any_of(cell_system.dof_indices.begin(),
                                           cell_system.dof_indices.end(),
                                           lifts);
          if (lifting)
            cell_system.reinit_operator(cell);
          cell_system.set_loads(mesh.cell_loads(cell));
          mesh_constraints.distribute_local_to_global(cell_system.rhs,
                                                      cell_system.dof_indices,
                                                      mesh_rhs,
                                                      lifting ?
                                                        cell_system.matrix :
                                                        no_matrix);
        }
    mesh_rhs.compress(VectorOperation::add);
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
  CoupledSystem<dim>::make_system(const IndexSet   &active_set,
                                  const VectorType &scaling)
  {
    const MeshOperator<dim> &mesh             = *this->mesh;
    const auto              &laplace_diagonal = mesh.laplace_diagonal();
    const MatrixRows         operator_rows(mesh.stiffness_matrix());
    const MatrixRows         rows(this->system_matrix);

    // The contact lines: the u1 column of an active vertex goes to its u2
    // column, and the row of u2 of an owned active vertex also takes the
    // row of u1. The owner of a vertex tells the columns (u2's index + 1
    // in u1's entry, 0 for an inactive vertex): with hanging vertices, the
    // operator's rows can have columns of vertices that lie on no cell of
    // this process.
    VectorType u2_of_active_u1(mesh.locally_owned_dofs(),
                               this->mpi_communicator);
    std::vector<types::global_dof_index> contact_row(
      rows.n_rows(), numbers::invalid_dof_index);
    for (const auto &dofs : mesh.locally_relevant_vertices())
      if (active_set.is_element(dofs[0]))
        {
          if (mesh.locally_owned_dofs().is_element(dofs[0]))
            u2_of_active_u1[dofs[0]] = dofs[1] + 1.;
          const int r = rows.local_row(dofs[1]);
          if (r >= 0)
            contact_row[r] = dofs[0];
        }
    u2_of_active_u1.compress(VectorOperation::insert);
    const VectorType u2_of_column =
      on_columns_of(mesh.stiffness_matrix(), u2_of_active_u1);
    std::vector<int> column = column_of_operator_column;
    for (unsigned int c = 0; c < operator_rows.n_columns(); ++c)
      if (const double u2 = u2_of_column[operator_rows.global_column(c)];
          u2 > 0)
        column[c] =
          rows.local_column(static_cast<types::global_dof_index>(u2) - 1);

    const VectorType ghosted_scaling =
      on_columns_of(this->system_matrix, scaling);
    std::vector<double> column_scaling(rows.n_columns());
    for (unsigned int c = 0; c < rows.n_columns(); ++c)
      column_scaling[c] = ghosted_scaling[rows.global_column(c)];

    std::vector<int> position(rows.n_columns(), -1);
    for (unsigned int r = 0; r < rows.n_rows(); ++r)
      {
        const auto   i           = rows.global_row(r);
        const auto   row         = rows[r];
        const double row_scaling = scaling[i];
        if (mesh_constraints.is_constrained(i) || active_set.is_element(i))
          {
            // A constrained row keeps the diagonal Σ_K μ_i A_K(i, i).
            for (unsigned int e = 0; e < row.values.size(); ++e)
              row.values[e] = (rows.global_column(row.columns[e]) == i) ?
                                tension[i] * laplace_diagonal[i] *
                                  (row_scaling * row_scaling) :
                                0.;
            this->system_rhs[i] = 0;
            continue;
          }
        for (unsigned int e = 0; e < row.values.size(); ++e)
          {
            position[row.columns[e]] = e;
            row.values[e]            = 0;
          }
        // Row j of the mesh's operator and of its right-hand side; the
        // columns of constrained DoFs, not in the system's pattern, are
        // lifted in mesh_rhs.
        double     rhs     = 0;
        const auto add_row = [&](const types::global_dof_index j) {
          const auto operator_row = operator_rows[operator_rows.local_row(j)];
          rhs += mesh_rhs[j];
          for (unsigned int e = 0; e < operator_row.values.size(); ++e)
            {
              const int c = column[operator_row.columns[e]];
              if (c >= 0 && position[c] >= 0)
                row.values[position[c]] += operator_row.values[e];
            }
        };
        add_row(i);
        if (contact_row[r] != numbers::invalid_dof_index)
          add_row(contact_row[r]);
        for (unsigned int e = 0; e < row.values.size(); ++e)
          {
            row.values[e] *= row_scaling * column_scaling[row.columns[e]];
            position[row.columns[e]] = -1;
          }
        this->system_rhs[i] = rhs * row_scaling;
      }
    this->system_rhs.compress(VectorOperation::insert);
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

      // The system scaled by D = diag(m_j^{-1/2}), m_j = μ_i for the DoFs
      // of membrane i at inactive vertices and on ∂ω, μ1 + μ2 for both
      // DoFs of an active vertex. Its residual D r then has the norm
      // Σ_a (r_W,a² / μ̄ + r_S,a² / (μ1 + μ2)) (sums over active vertices
      // only r_S), so one bound on it bounds r_S and r_W each on its own
      // scale.
      scaling = tension_scaling(active_set);
      make_system(active_set, scaling);
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
    mesh_rhs.clear();
    column_of_operator_column = {};
  }



  template class CoupledSystem<2>;
} // namespace membranes
