#include <Epetra_CrsMatrix.h>
#include <deal.II/dofs/dof_tools.h>
#include <membranes/cell_loop.h>
#include <membranes/decoupled_system.h>

namespace membranes
{
  namespace
  {
    /** The scalar function c1 g + c2 g2 of the boundary values (g, g2). */
    template <int dim>
    std::unique_ptr<Function<dim>>
    combine_boundary_values(const ProblemData<dim> &data,
                            const double            c1,
                            const double            c2)
    {
      return std::make_unique<ScalarFunctionFromFunctionObject<dim>>(
        [&data, c1, c2](const Point<dim> &p) {
          return c1 * data.boundary_values().value(p, 0) +
                 c2 * data.boundary_values().value(p, 1);
        });
    }



    /** The cell of @p dof_handler that is the mesh cell @p cell. */
    template <int dim>
    typename DoFHandler<dim>::active_cell_iterator
    cell_of(const DoFHandler<dim>                            &dof_handler,
            const typename Triangulation<dim>::cell_iterator &cell)
    {
      return {&dof_handler.get_triangulation(),
              cell->level(),
              cell->index(),
              &dof_handler};
    }



    /**
     * @p matrix = @p coefficient · @p base with the off-diagonal entries of
     * the rows and columns of @p eliminated (locally relevant DoFs) set to
     * zero: the condensation of the homogeneous constraints x_k = 0, k in
     * @p eliminated, on the locally owned rows of a matrix with the
     * sparsity pattern of @p base, in one pass over its entries.
     */
    void
    eliminate_rows_and_columns(const TrilinosWrappers::SparseMatrix &base,
                               const double                    coefficient,
                               const IndexSet                 &eliminated,
                               TrilinosWrappers::SparseMatrix &matrix)
    {
      // Epetra's row views point into the matrices' storage, writable even
      // through a const matrix: the values of @p matrix are overwritten in
      // place, its pattern (that of @p base) stays.
      const Epetra_CrsMatrix &from = base.trilinos_matrix();
      const Epetra_CrsMatrix &to   = matrix.trilinos_matrix();
      std::vector<bool>       eliminated_column(from.NumMyCols());
      for (int c = 0; c < from.NumMyCols(); ++c)
        eliminated_column[c] = eliminated.is_element(from.GCID64(c));
      for (int row = 0; row < from.NumMyRows(); ++row)
        {
          int     n_entries, n_target_entries;
          double *values, *target_values;
          int    *columns, *target_columns;
          from.ExtractMyRowView(row, n_entries, values, columns);
          to.ExtractMyRowView(row,
                              n_target_entries,
                              target_values,
                              target_columns);
          AssertDimension(n_entries, n_target_entries);
          const auto global_row     = from.GRID64(row);
          const bool eliminated_row = eliminated.is_element(global_row);
          for (int k = 0; k < n_entries; ++k)
            {
              Assert(columns[k] == target_columns[k], ExcInternalError());
              const bool off_diagonal = (from.GCID64(columns[k]) != global_row);
              target_values[k] =
                (off_diagonal &&
                 (eliminated_row || eliminated_column[columns[k]])) ?
                  0. :
                  coefficient * values[k];
            }
        }
    }
  } // namespace



  template <int dim>
  DecoupledSystem<dim>::DecoupledSystem(
    const Parameters::Solver  &parameters,
    const Discretization<dim> &discretization,
    const ProblemData<dim>    &data,
    TimerOutput               &timer,
    const MPI_Comm             mpi_communicator)
    : ActiveSetSystem<dim>("decoupled",
                           parameters,
                           discretization,
                           data,
                           timer,
                           mpi_communicator)
    , sum_boundary_values(combine_boundary_values(data, data.mu[0], data.mu[1]))
    , difference_boundary_values(combine_boundary_values(data, 1., -1.))
    , sum_solved(false)
  {}



  template <int dim>
  void
  DecoupledSystem<dim>::setup(const MeshOperator<dim> &mesh_operator)
  {
    this->mesh                         = &mesh_operator;
    const DoFHandler<dim> &dof_handler = mesh_operator.get_dof_handler();
    const IndexSet        &locally_relevant_dofs =
      mesh_operator.locally_relevant_dofs();
    scalar_dof_handler.reinit(dof_handler.get_triangulation());
    scalar_dof_handler.distribute_dofs(
      this->discretization.fe->base_element(0));
    locally_owned_scalar_dofs = scalar_dof_handler.locally_owned_dofs();
    DoFTools::extract_locally_relevant_dofs(scalar_dof_handler,
                                            locally_relevant_scalar_dofs);

    // Shape function v of the scalar element and shape function
    // component_to_system_index(i, v) of the FESystem belong to the same
    // vertex of a cell.
    const FiniteElement<dim>            &fe = *this->discretization.fe;
    std::vector<types::global_dof_index> dof_indices(fe.n_dofs_per_cell());
    std::vector<types::global_dof_index> scalar_dof_indices(
      fe.base_element(0).n_dofs_per_cell());
    membrane_dofs.resize(locally_owned_scalar_dofs.n_elements());
    scalar_dof.resize(locally_relevant_dofs.n_elements());
    for (const auto &scalar_cell : scalar_dof_handler.active_cell_iterators())
      if (!scalar_cell->is_artificial())
        {
          scalar_cell->get_dof_indices(scalar_dof_indices);
          cell_of(dof_handler, scalar_cell)->get_dof_indices(dof_indices);
          for (unsigned int v = 0; v < scalar_dof_indices.size(); ++v)
            for (unsigned int i = 0; i < 2; ++i)
              {
                const auto k = scalar_dof_indices[v];
                const auto dof =
                  dof_indices[fe.component_to_system_index(i, v)];
                if (locally_owned_scalar_dofs.is_element(k))
                  membrane_dofs[locally_owned_scalar_dofs.index_within_set(k)]
                               [i] = dof;
                scalar_dof[locally_relevant_dofs.index_within_set(dof)] = k;
              }
        }

    // Both scalar problems have the hanging node constraints and boundary
    // values on ∂ω, those of S and those of W: the same lines, hence one
    // condensed operator A for both. W = 0 on active vertices only removes
    // couplings, so the pattern of A holds the matrix of W for every active
    // set.
    this->make_mesh_constraints(scalar_dof_handler,
                                *sum_boundary_values,
                                locally_relevant_scalar_dofs,
                                sum_constraints);
    this->make_mesh_constraints(scalar_dof_handler,
                                *difference_boundary_values,
                                locally_relevant_scalar_dofs,
                                difference_constraints);
    this->reinit_linear_system(scalar_dof_handler,
                               sum_constraints,
                               locally_owned_scalar_dofs,
                               locally_relevant_scalar_dofs);
    laplace_matrix.reinit(this->system_matrix);
    preconditioner_matrix.reinit(this->system_matrix);
    // The matrix of W of an iteration that reuses the AMG hierarchy is made
    // by solve() when it is first needed, after the hierarchy is built.
    this->system_matrix.clear();
    sum_rhs.reinit(locally_owned_scalar_dofs, this->mpi_communicator);
    difference_rhs.reinit(locally_owned_scalar_dofs, this->mpi_communicator);
    sum.reinit(locally_owned_scalar_dofs, this->mpi_communicator);
    difference.reinit(locally_owned_scalar_dofs, this->mpi_communicator);
    sum_solved = false;
  }



  template <int dim>
  void
  DecoupledSystem<dim>::assemble_operator()
  {
    const double mu1 = this->data.mu[0], mu2 = this->data.mu[1];
    const double M = mu1 + mu2;
    // A_K, the loads of S and of W and the scalar DoFs of a cell, computed
    // on threads; the copier adds them to the global systems.
    struct CellContribution
    {
      FullMatrix<double>                   laplace_matrix, difference_matrix;
      Vector<double>                       sum_loads, difference_loads;
      std::vector<types::global_dof_index> scalar_dof_indices;
    };

    laplace_matrix = 0;
    sum_rhs        = 0;
    difference_rhs = 0;
    run_on_cells<CellContribution>(
      this->mesh->get_dof_handler(),
      [&]() {
        return std::make_unique<CellSystem<dim>>(this->discretization,
                                                 this->data);
      },
      [&](const auto       &cell,
          CellSystem<dim>  &cell_system,
          CellContribution &contribution) {
        contribution.scalar_dof_indices.clear();
        if (!cell->is_locally_owned())
          return;
        cell_system.reinit_operator(cell);
        cell_system.set_loads(this->mesh->cell_loads(cell));
        contribution.scalar_dof_indices.resize(cell_system.laplace_matrix.m());
        cell_of(scalar_dof_handler, cell)
          ->get_dof_indices(contribution.scalar_dof_indices);
        contribution.laplace_matrix = cell_system.laplace_matrix;
        contribution.sum_loads      = cell_system.loads[0];
        contribution.sum_loads.add(1., cell_system.loads[1]);
        // The loads of W, with its boundary values lifted by the cell
        // matrix of its system, μ̄ A_K.
        contribution.difference_matrix = cell_system.laplace_matrix;
        contribution.difference_matrix *= this->data.mu_bar;
        contribution.difference_loads = cell_system.loads[0];
        contribution.difference_loads *= mu2 / M;
        contribution.difference_loads.add(-mu1 / M, cell_system.loads[1]);
      },
      [&](const CellContribution &contribution) {
        if (contribution.scalar_dof_indices.empty())
          return;
        sum_constraints.distribute_local_to_global(
          contribution.laplace_matrix,
          contribution.sum_loads,
          contribution.scalar_dof_indices,
          laplace_matrix,
          sum_rhs);
        difference_constraints.distribute_local_to_global(
          contribution.difference_loads,
          contribution.scalar_dof_indices,
          difference_rhs,
          contribution.difference_matrix);
      });
    laplace_matrix.compress(VectorOperation::add);
    sum_rhs.compress(VectorOperation::add);
    difference_rhs.compress(VectorOperation::add);
  }



  template <int dim>
  void
  DecoupledSystem<dim>::solve_sum(const VectorType       &solution,
                                  const LinearTolerances &tolerances,
                                  ActiveSetStatistics    &statistics)
  {
    {
      TimerOutput::Scope scope(this->timer, "assembly");
      const double       mu1 = this->data.mu[0], mu2 = this->data.mu[1];
      for (unsigned int j = 0; j < membrane_dofs.size(); ++j)
        {
          const auto   k  = locally_owned_scalar_dofs.nth_index_in_set(j);
          const double u1 = solution[membrane_dofs[j][0]];
          const double u2 = solution[membrane_dofs[j][1]];
          sum[k]          = mu1 * u1 + mu2 * u2;
          difference[k]   = u1 - u2;
        }
      sum.compress(VectorOperation::insert);
      difference.compress(VectorOperation::insert);

      sum_constraints.distribute(sum);
      assemble_operator();
    }

    this->solve_linear_system(laplace_matrix,
                              sum_rhs,
                              sum_constraints,
                              sum,
                              tolerances.sum,
                              statistics);
    sum_solved = true;
  }



  template <int dim>
  void
  DecoupledSystem<dim>::solve(const IndexSet         &active_set,
                              VectorType             &solution,
                              const LinearTolerances &tolerances,
                              ActiveSetStatistics    &statistics)
  {
    if (!sum_solved)
      solve_sum(solution, tolerances, statistics);
    const IndexSet &locally_relevant_dofs = this->mesh->locally_relevant_dofs();
    const double    mu1 = this->data.mu[0], mu2 = this->data.mu[1];
    const double    M = mu1 + mu2;
    TimerOutput::Scope assembly(this->timer, "assembly");

    // The scalar DoFs of the active vertices; W = 0 there.
    IndexSet active_scalar_dofs(scalar_dof_handler.n_dofs());
    for (const auto dof : active_set)
      active_scalar_dofs.add_index(
        scalar_dof[locally_relevant_dofs.index_within_set(dof)]);
    active_scalar_dofs.compress();
    const IndexSet owned_active_scalar_dofs =
      active_scalar_dofs & locally_owned_scalar_dofs;
    const auto set_active_to_zero = [&](VectorType &vector) {
      for (const auto k : owned_active_scalar_dofs)
        vector[k] = 0;
      vector.compress(VectorOperation::insert);
    };

    // The system of W: μ̄ A and the loads of the mesh, with the rows and
    // columns of the active vertices eliminated (the constraints W_a = 0
    // condensed, as AffineConstraints would do it in the assembly). An
    // iteration that builds the AMG hierarchy writes its matrix into
    // preconditioner_matrix, which the hierarchy refers to for the rest of
    // the mesh; one that reuses the hierarchy writes into system_matrix.
    const bool builds_preconditioner = !this->has_mesh_preconditioner();
    TrilinosWrappers::SparseMatrix &matrix =
      builds_preconditioner ? preconditioner_matrix : this->system_matrix;
    if (matrix.m() == 0)
      matrix.reinit(laplace_matrix);
    eliminate_rows_and_columns(laplace_matrix,
                               this->data.mu_bar,
                               active_scalar_dofs,
                               matrix);
    this->system_rhs = difference_rhs;
    set_active_to_zero(this->system_rhs);
    set_active_to_zero(difference);
    difference_constraints.distribute(difference);
    assembly.stop();

    // The AMG hierarchy of the system of an earlier iteration on this mesh
    // preconditions this one: the two differ near the free boundary only.
    this->solve_linear_system(matrix,
                              this->system_rhs,
                              difference_constraints,
                              difference,
                              tolerances.contact,
                              statistics,
                              &preconditioner_matrix);

    TimerOutput::Scope scope(this->timer, "solve");
    set_active_to_zero(difference);
    difference_constraints.distribute(difference);
    for (unsigned int j = 0; j < membrane_dofs.size(); ++j)
      {
        const auto k = locally_owned_scalar_dofs.nth_index_in_set(j);
        solution[membrane_dofs[j][0]] = (sum[k] + mu2 * difference[k]) / M;
        solution[membrane_dofs[j][1]] = (sum[k] - mu1 * difference[k]) / M;
      }
    solution.compress(VectorOperation::insert);
  }



  template <int dim>
  void
  DecoupledSystem<dim>::clear()
  {
    ActiveSetSystem<dim>::clear();
    laplace_matrix.clear();
    preconditioner_matrix.clear();
    for (VectorType *vector : {&sum_rhs, &difference_rhs, &sum, &difference})
      vector->clear();
    sum_constraints.clear();
    difference_constraints.clear();
    membrane_dofs = {};
    scalar_dof    = {};
    scalar_dof_handler.clear();
  }



  template class DecoupledSystem<2>;
} // namespace membranes
