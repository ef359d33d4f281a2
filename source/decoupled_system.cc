#include <algorithm>
#include <deal.II/dofs/dof_tools.h>
#include <membranes/decoupled_system.h>
#include <membranes/matrix_rows.h>

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
    scalar_dof_handler.reinit(dof_handler.get_triangulation());
    scalar_dof_handler.distribute_dofs(
      this->discretization.fe->base_element(0));
    locally_owned_scalar_dofs = scalar_dof_handler.locally_owned_dofs();
    DoFTools::extract_locally_relevant_dofs(scalar_dof_handler,
                                            locally_relevant_scalar_dofs);

    // Both DoFHandlers number the vertices in the same order, the FESystem
    // the DoFs of u1 and u2 at a vertex one after the other: the DoFs of
    // scalar DoF k are 2k and 2k + 1 (membrane_dof()). Checked here on the
    // cells of this process.
    const FiniteElement<dim>            &fe = *this->discretization.fe;
    std::vector<types::global_dof_index> dof_indices(fe.n_dofs_per_cell());
    std::vector<types::global_dof_index> scalar_dof_indices(
      fe.base_element(0).n_dofs_per_cell());
    for (const auto &scalar_cell : scalar_dof_handler.active_cell_iterators())
      if (scalar_cell->is_locally_owned())
        {
          scalar_cell->get_dof_indices(scalar_dof_indices);
          cell_of(dof_handler, scalar_cell)->get_dof_indices(dof_indices);
          for (unsigned int v = 0; v < scalar_dof_indices.size(); ++v)
            for (unsigned int i = 0; i < 2; ++i)
              AssertThrow(dof_indices[fe.component_to_system_index(i, v)] ==
                            membrane_dof(scalar_dof_indices[v], i),
                          ExcInternalError());
        }

    // Both scalar problems have the hanging node constraints and boundary
    // values on ∂ω, those of S and those of W: the same lines, hence one
    // condensed operator A for both. W = 0 on active vertices only removes
    // couplings, so the pattern of A holds the matrix of W for every active
    // set.
    AffineConstraints<double> hanging_node_constraints(
      locally_relevant_scalar_dofs);
    DoFTools::make_hanging_node_constraints(scalar_dof_handler,
                                            hanging_node_constraints);
    hanging_node_constraints.close();
    this->make_mesh_constraints(scalar_dof_handler,
                                hanging_node_constraints,
                                *sum_boundary_values,
                                sum_constraints);
    this->make_mesh_constraints(scalar_dof_handler,
                                hanging_node_constraints,
                                *difference_boundary_values,
                                difference_constraints);
    this->reinit_linear_system(scalar_dof_handler,
                               sum_constraints,
                               locally_owned_scalar_dofs,
                               locally_relevant_scalar_dofs);
    constrained_scalar_dofs = IndexSet(scalar_dof_handler.n_dofs());
    for (const auto &line : sum_constraints.get_lines())
      constrained_scalar_dofs.add_index(line.index);
    constrained_scalar_dofs.compress();

    // The matrix of S, then that of W of the iteration that builds the AMG
    // hierarchy; the matrix of W of an iteration that reuses the hierarchy
    // is made by solve() when it is first needed.
    preconditioner_matrix.reinit(this->system_matrix);
    this->system_matrix.clear();
    const MatrixRows operator_rows(mesh_operator.stiffness_matrix());
    const MatrixRows rows(preconditioner_matrix);
    column_of_operator_column.resize(operator_rows.n_columns());
    for (unsigned int c = 0; c < operator_rows.n_columns(); ++c)
      column_of_operator_column[c] =
        rows.local_column(operator_rows.global_column(c) / 2);
    difference_rhs.reinit(locally_owned_scalar_dofs, this->mpi_communicator);
    sum.reinit(locally_owned_scalar_dofs, this->mpi_communicator);
    difference.reinit(locally_owned_scalar_dofs, this->mpi_communicator);
    sum_solved = false;
  }



  template <int dim>
  types::global_dof_index
  DecoupledSystem<dim>::membrane_dof(const types::global_dof_index k,
                                     const unsigned int            i)
  {
    return 2 * k + i;
  }



  template <int dim>
  void
  DecoupledSystem<dim>::make_right_hand_sides()
  {
    // The loads of S, F_1K + F_2K, and of W, (μ2 F_1K − μ1 F_2K)/M, of each
    // cell from the loads of the mesh, condensed by AffineConstraints as in
    // an assembly. The cell matrix (A_K for S, μ̄ A_K for W) is needed only
    // where a DoF of the cell has an inhomogeneous constraint (a boundary
    // value to lift); a cell without constrained DoFs adds its loads.
    // AffineConstraints condenses the right-hand side of S together with
    // its matrix; what it adds to the matrix of S here, make_operator()
    // overwrites.
    const double       mu1 = this->data.mu[0], mu2 = this->data.mu[1];
    const double       M = mu1 + mu2;
    const unsigned int n_vertices =
      this->discretization.fe->base_element(0).n_dofs_per_cell();
    CellSystem<dim>    cell_system(this->discretization, this->data);
    FullMatrix<double> laplace_matrix(n_vertices),
      difference_matrix(n_vertices);
    Vector<double> sum_loads(n_vertices), difference_loads(n_vertices);
    std::vector<types::global_dof_index> scalar_dof_indices(n_vertices);
    const auto is_constrained = [&](const types::global_dof_index k) {
      return constrained_scalar_dofs.is_element(k);
    };
    const auto lifts = [&](const types::global_dof_index k) {
      return sum_constraints.is_inhomogeneously_constrained(k) ||
             difference_constraints.is_inhomogeneously_constrained(k);
    };

    this->system_rhs = 0;
    difference_rhs   = 0;
    for (const auto &cell :
         this->mesh->get_dof_handler().active_cell_iterators())
      if (cell->is_locally_owned())
        {
          cell_of(scalar_dof_handler, cell)
            ->get_dof_indices(scalar_dof_indices);
          cell_system.set_loads(this->mesh->cell_loads(cell));
          sum_loads = cell_system.loads[0];
          sum_loads.add(1., cell_system.loads[1]);
          difference_loads = cell_system.loads[0];
          difference_loads *= mu2 / M;
          difference_loads.add(-mu1 / M, cell_system.loads[1]);
          if (std::none_of(scalar_dof_indices.begin(),
                           scalar_dof_indices.end(),
                           is_constrained))
            {
              this->system_rhs.add(scalar_dof_indices, sum_loads);
              difference_rhs.add(scalar_dof_indices, difference_loads);
              continue;
            }
          if (std::any_of(scalar_dof_indices.begin(),
                          scalar_dof_indices.end(),
                          lifts))
            {
              cell_system.reinit_operator(cell);
              laplace_matrix    = cell_system.laplace_matrix;
              difference_matrix = cell_system.laplace_matrix;
              difference_matrix *= this->data.mu_bar;
            }
          else
            {
              laplace_matrix    = 0;
              difference_matrix = 0;
            }
          sum_constraints.distribute_local_to_global(laplace_matrix,
                                                     sum_loads,
                                                     scalar_dof_indices,
                                                     preconditioner_matrix,
                                                     this->system_rhs);
          difference_constraints.distribute_local_to_global(difference_loads,
                                                            scalar_dof_indices,
                                                            difference_rhs,
                                                            difference_matrix);
        }
    preconditioner_matrix.compress(VectorOperation::add);
    this->system_rhs.compress(VectorOperation::add);
    difference_rhs.compress(VectorOperation::add);
  }



  template <int dim>
  void
  DecoupledSystem<dim>::make_operator(
    const double                    coefficient,
    const IndexSet                 &active_scalar_dofs,
    TrilinosWrappers::SparseMatrix &matrix) const
  {
    // Row a of A is row a of the block μ1 A of the mesh's operator divided
    // by μ1, restricted to the unconstrained columns (those of the pattern
    // of @p matrix); a constrained row keeps only the diagonal that the
    // condensation leaves, Σ_K A_K(a, a).
    const double      mu1              = this->data.mu[0];
    const auto       &laplace_diagonal = this->mesh->laplace_diagonal();
    const MatrixRows  operator_rows(this->mesh->stiffness_matrix());
    const MatrixRows  rows(matrix);
    std::vector<bool> active_column(rows.n_columns());
    for (unsigned int c = 0; c < rows.n_columns(); ++c)
      active_column[c] = active_scalar_dofs.is_element(rows.global_column(c));
    std::vector<int> position(rows.n_columns(), -1);
    for (const auto k : locally_owned_scalar_dofs)
      {
        const auto row = rows[rows.local_row(k)];
        if (constrained_scalar_dofs.is_element(k))
          {
            AssertDimension(row.values.size(), 1);
            row.values[0] = coefficient * laplace_diagonal[membrane_dof(k, 0)];
            continue;
          }
        for (unsigned int e = 0; e < row.values.size(); ++e)
          {
            position[row.columns[e]] = e;
            row.values[e]            = 0;
          }
        const bool active_row = active_scalar_dofs.is_element(k);
        const auto operator_row =
          operator_rows[operator_rows.local_row(membrane_dof(k, 0))];
        for (unsigned int e = 0; e < operator_row.values.size(); ++e)
          {
            const int c = column_of_operator_column[operator_row.columns[e]];
            if (c < 0 || position[c] < 0)
              continue;
            const bool off_diagonal = (rows.global_column(c) != k);
            row.values[position[c]] =
              (off_diagonal && (active_row || active_column[c])) ?
                0. :
                coefficient * (operator_row.values[e] / mu1);
          }
        for (const int c : row.columns)
          position[c] = -1;
      }
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
      for (const auto k : locally_owned_scalar_dofs)
        {
          const double u1 = solution[membrane_dof(k, 0)];
          const double u2 = solution[membrane_dof(k, 1)];
          sum[k]          = mu1 * u1 + mu2 * u2;
          difference[k]   = u1 - u2;
        }
      sum.compress(VectorOperation::insert);
      difference.compress(VectorOperation::insert);

      sum_constraints.distribute(sum);
      make_right_hand_sides();
      make_operator(1.,
                    IndexSet(scalar_dof_handler.n_dofs()),
                    preconditioner_matrix);
    }

    this->solve_linear_system(preconditioner_matrix,
                              this->system_rhs,
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
    const double       mu1 = this->data.mu[0], mu2 = this->data.mu[1];
    const double       M = mu1 + mu2;
    TimerOutput::Scope assembly(this->timer, "assembly");

    // The scalar DoFs of the active vertices; W = 0 there.
    IndexSet active_scalar_dofs(scalar_dof_handler.n_dofs());
    for (const auto dof : active_set)
      active_scalar_dofs.add_index(dof / 2);
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
      matrix.reinit(preconditioner_matrix);
    make_operator(this->data.mu_bar, active_scalar_dofs, matrix);
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
    for (const auto k : locally_owned_scalar_dofs)
      {
        solution[membrane_dof(k, 0)] = (sum[k] + mu2 * difference[k]) / M;
        solution[membrane_dof(k, 1)] = (sum[k] - mu1 * difference[k]) / M;
      }
    solution.compress(VectorOperation::insert);
  }



  template <int dim>
  void
  DecoupledSystem<dim>::clear()
  {
    ActiveSetSystem<dim>::clear();
    preconditioner_matrix.clear();
    for (VectorType *vector : {&difference_rhs, &sum, &difference})
      vector->clear();
    sum_constraints.clear();
    difference_constraints.clear();
    column_of_operator_column = {};
    constrained_scalar_dofs.clear();
    scalar_dof_handler.clear();
  }



  template class DecoupledSystem<2>;
} // namespace membranes
