#include <algorithm>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparsity_tools.h>
#include <membranes/cell_loop.h>
#include <membranes/cell_system.h>
#include <membranes/matrix_rows.h>
#include <membranes/mesh_operator.h>

namespace membranes
{
  template <int dim>
  MeshOperator<dim>::MeshOperator(const Discretization<dim> &discretization,
                                  const ProblemData<dim>    &data)
    : discretization(discretization)
    , data(data)
    , owned_dofs(nullptr)
    , relevant_dofs(nullptr)
    , mpi_communicator(MPI_COMM_SELF)
    , loads_per_cell(0)
  {}



  template <int dim>
  void
  MeshOperator<dim>::reinit(
    const DoFHandler<dim>           &dof_handler,
    const AffineConstraints<double> &hanging_node_constraints,
    const IndexSet                  &locally_owned_dofs,
    const IndexSet                  &locally_relevant_dofs,
    const MPI_Comm                   mpi_communicator)
  {
    this->dof_handler      = &dof_handler;
    this->constraints      = &hanging_node_constraints;
    this->owned_dofs       = &locally_owned_dofs;
    this->relevant_dofs    = &locally_relevant_dofs;
    this->mpi_communicator = mpi_communicator;

    // μ_i times the Laplacian on each membrane, the membranes not coupled,
    // condensed with the hanging node constraints (rows and columns of
    // constrained DoFs moved to their parents).
    const FiniteElement<dim>    &fe = *discretization.fe;
    Table<2, DoFTools::Coupling> coupling(fe.n_components(), fe.n_components());
    for (unsigned int c = 0; c < fe.n_components(); ++c)
      coupling(c, c) = DoFTools::always;
    DynamicSparsityPattern dsp(locally_relevant_dofs);
    DoFTools::make_sparsity_pattern(
      dof_handler, coupling, dsp, hanging_node_constraints, false);
    SparsityTools::distribute_sparsity_pattern(dsp,
                                               locally_owned_dofs,
                                               mpi_communicator,
                                               locally_relevant_dofs);
    matrix.reinit(locally_owned_dofs,
                  locally_owned_dofs,
                  dsp,
                  mpi_communicator);
    loads.reinit(locally_owned_dofs, mpi_communicator);

    VectorType dual_cell_measure(locally_owned_dofs, mpi_communicator);
    diagonal.reinit(locally_owned_dofs, mpi_communicator);
    assemble(dual_cell_measure, diagonal);
    find_vertices(dual_cell_measure, diagonal);
  }



  template <int dim>
  void
  MeshOperator<dim>::assemble(VectorType &dual_cell_measure,
                              VectorType &stiffness_diagonal)
  {
    // The cell loop on threads: each works with its own CellSystem, the
    // loads of every cell go to that cell's own slot of loads_of_cells, and
    // the copier adds the cell's matrix and vectors to the global ones: the
    // loads ∫ f_i φ, d_a = ∫ φ_a as the row sums of the mass matrix, all
    // condensed with the hanging node constraints, and the diagonal
    // ∫ |∇φ_a|².
    struct CellContribution
    {
      FullMatrix<double>                   matrix;
      Vector<double>                       rhs, lumped_mass, stiffness_diagonal;
      std::vector<types::global_dof_index> dof_indices;
    };
    loads_per_cell = CellSystem<dim>(discretization, data).n_load_entries();
    loads_of_cells.assign(dof_handler->get_triangulation().n_active_cells() *
                            loads_per_cell,
                          0.);
    run_on_cells<CellContribution>(
      *dof_handler,
      [&]() { return std::make_unique<CellSystem<dim>>(discretization, data); },
      [&](const auto       &cell,
          CellSystem<dim>  &cell_system,
          CellContribution &contribution) {
        contribution.dof_indices.clear();
        if (!cell->is_locally_owned())
          return;
        cell_system.reinit(cell);
        cell_system.copy_loads(
          &loads_of_cells[cell->active_cell_index() * loads_per_cell]);
        contribution.matrix      = cell_system.matrix;
        contribution.rhs         = cell_system.rhs;
        contribution.lumped_mass = cell_system.lumped_mass;
        contribution.dof_indices = cell_system.dof_indices;
        contribution.stiffness_diagonal.reinit(contribution.dof_indices.size());
        for (unsigned int i = 0; i < contribution.dof_indices.size(); ++i)
          {
            const unsigned int v = cell_system.scalar_index_of(i);
            contribution.stiffness_diagonal(i) =
              cell_system.laplace_matrix(v, v);
          }
      },
      [&](const CellContribution &contribution) {
        if (contribution.dof_indices.empty())
          return;
        constraints->distribute_local_to_global(contribution.matrix,
                                                contribution.dof_indices,
                                                matrix);
        constraints->distribute_local_to_global(contribution.rhs,
                                                contribution.dof_indices,
                                                loads);
        constraints->distribute_local_to_global(contribution.lumped_mass,
                                                contribution.dof_indices,
                                                dual_cell_measure);
        stiffness_diagonal.add(contribution.dof_indices,
                               contribution.stiffness_diagonal);
      });
    matrix.compress(VectorOperation::add);
    loads.compress(VectorOperation::add);
    dual_cell_measure.compress(VectorOperation::add);
    stiffness_diagonal.compress(VectorOperation::add);
  }



  template <int dim>
  void
  MeshOperator<dim>::find_vertices(const VectorType &dual_cell_measure,
                                   const VectorType &stiffness_diagonal)
  {
    // The interior vertices of the owned and ghost cells, each once, by
    // their DoFs (u1, u2).
    const IndexSet boundary_dofs =
      DoFTools::extract_boundary_dofs(*dof_handler);
    std::vector<std::array<types::global_dof_index, 2>> candidates;
    for (const auto &cell : dof_handler->active_cell_iterators())
      if (!cell->is_artificial())
        for (const unsigned int v : cell->vertex_indices())
          if (!boundary_dofs.is_element(cell->vertex_dof_index(v, 0)))
            candidates.push_back(
              {{cell->vertex_dof_index(v, 0), cell->vertex_dof_index(v, 1)}});
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()),
                     candidates.end());

    // The row of the assembled operator, read in place.
    const MatrixRows rows(matrix);
    const auto       row_l1_norm = [&](const types::global_dof_index row) {
      double norm = 0;
      for (const double value : rows[rows.local_row(row)].values)
        norm += std::abs(value);
      return norm;
    };

    // V_h: the unconstrained ones; its owned vertices carry λ_a.
    interior_vertices.clear();
    relevant_vertices.clear();
    interior_vertex_dofs = IndexSet(dof_handler->n_dofs());
    for (const auto &dofs : candidates)
      {
        interior_vertex_dofs.add_index(dofs[0]);
        if (constraints->is_constrained(dofs[0]))
          continue;
        relevant_vertices.push_back(dofs);
        if (owned_dofs->is_element(dofs[0]))
          interior_vertices.push_back({dofs,
                                       dual_cell_measure[dofs[0]],
                                       stiffness_diagonal[dofs[0]],
                                       row_l1_norm(dofs[0]) / data.mu[0]});
      }
    interior_vertex_dofs.compress();
    positions.resize(interior_vertices.size());
    for (unsigned int k = 0; k < interior_vertices.size(); ++k)
      for (unsigned int i = 0; i < 2; ++i)
        positions[k][i] =
          owned_dofs->index_within_set(interior_vertices[k].dof[i]);
  }



  template <int dim>
  const DoFHandler<dim> &
  MeshOperator<dim>::get_dof_handler() const
  {
    return *dof_handler;
  }



  template <int dim>
  const AffineConstraints<double> &
  MeshOperator<dim>::hanging_node_constraints() const
  {
    return *constraints;
  }



  template <int dim>
  const IndexSet &
  MeshOperator<dim>::locally_owned_dofs() const
  {
    return *owned_dofs;
  }



  template <int dim>
  const IndexSet &
  MeshOperator<dim>::locally_relevant_dofs() const
  {
    return *relevant_dofs;
  }



  template <int dim>
  MPI_Comm
  MeshOperator<dim>::get_mpi_communicator() const
  {
    return mpi_communicator;
  }



  template <int dim>
  const TrilinosWrappers::SparseMatrix &
  MeshOperator<dim>::stiffness_matrix() const
  {
    return matrix;
  }



  template <int dim>
  const typename MeshOperator<dim>::VectorType &
  MeshOperator<dim>::laplace_diagonal() const
  {
    return diagonal;
  }



  template <int dim>
  const typename MeshOperator<dim>::VectorType &
  MeshOperator<dim>::load_vector() const
  {
    return loads;
  }



  template <int dim>
  const double *
  MeshOperator<dim>::cell_loads(
    const typename DoFHandler<dim>::active_cell_iterator &cell) const
  {
    return &loads_of_cells[cell->active_cell_index() * loads_per_cell];
  }



  template <int dim>
  std::pair<double, double>
  MeshOperator<dim>::load_mean_and_oscillation(
    const typename DoFHandler<dim>::active_cell_iterator &cell,
    const unsigned int                                    i) const
  {
    const double *statistics =
      cell_loads(cell) + loads_per_cell - 4; // f̄_1K, f̄_2K, osc_1K, osc_2K
    return {statistics[i], statistics[2 + i]};
  }



  template <int dim>
  const std::vector<typename MeshOperator<dim>::Vertex> &
  MeshOperator<dim>::vertices() const
  {
    return interior_vertices;
  }



  template <int dim>
  const std::vector<std::array<int, 2>> &
  MeshOperator<dim>::local_positions() const
  {
    return positions;
  }



  template <int dim>
  const std::vector<std::array<types::global_dof_index, 2>> &
  MeshOperator<dim>::locally_relevant_vertices() const
  {
    return relevant_vertices;
  }



  template <int dim>
  bool
  MeshOperator<dim>::is_interior_vertex(const types::global_dof_index a) const
  {
    return interior_vertex_dofs.is_element(a);
  }



  template class MeshOperator<2>;
} // namespace membranes
