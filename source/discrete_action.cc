#include <Epetra_CrsMatrix.h>
#include <algorithm>
#include <deal.II/base/mpi.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparsity_tools.h>
#include <membranes/cell_loop.h>
#include <membranes/cell_system.h>
#include <membranes/discrete_action.h>

namespace membranes
{
  template <int dim>
  DiscreteAction<dim>::DiscreteAction(const Discretization<dim> &discretization,
                                      const ProblemData<dim>    &data)
    : discretization(discretization)
    , data(data)
    , dual_cell_quadrature(discretization.fe->reference_cell(), 2)
    , lambda_h_vector(nullptr)
    , loads_per_cell(0)
    , max_force(0)
    , max_contact_force(0)
  {}



  template <int dim>
  void
  DiscreteAction<dim>::reinit(
    const DoFHandler<dim>           &dof_handler,
    const AffineConstraints<double> &hanging_node_constraints,
    const IndexSet                  &locally_owned_dofs,
    const IndexSet                  &locally_relevant_dofs,
    const MPI_Comm                   mpi_communicator)
  {
    this->locally_owned_dofs = locally_owned_dofs;
    this->mpi_communicator   = mpi_communicator;

    const FiniteElement<dim> &fe = *discretization.fe;
    const IndexSet boundary_dofs = DoFTools::extract_boundary_dofs(dof_handler);

    // The operator of (4.5): μ_i times the Laplacian on each membrane, the
    // membranes not coupled, condensed with the hanging node constraints
    // (rows and columns of constrained DoFs moved to their parents).
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
    stiffness_matrix.reinit(locally_owned_dofs,
                            locally_owned_dofs,
                            dsp,
                            mpi_communicator);
    load_vector.reinit(locally_owned_dofs, mpi_communicator);

    // The matrix and the loads ∫ f_i φ, d_a = ∫ φ_a as the row sums of the
    // mass matrix, all condensed with the hanging node constraints, and the
    // diagonal ∫ |∇φ_a|².
    VectorType dual_cell_measure(locally_owned_dofs, mpi_communicator);
    VectorType stiffness_diagonal(locally_owned_dofs, mpi_communicator);

    // The cell loop on threads: each works with its own CellSystem, the
    // loads of every cell go to that cell's own slot of loads_of_cells, and
    // the copier adds the cell's matrix and vectors to the global ones.
    struct CellContribution
    {
      FullMatrix<double>                   matrix;
      Vector<double>                       rhs, lumped_mass, stiffness_diagonal;
      std::vector<types::global_dof_index> dof_indices;
    };
    loads_per_cell = CellSystem<dim>(discretization, data).n_load_entries();
    loads_of_cells.assign(dof_handler.get_triangulation().n_active_cells() *
                            loads_per_cell,
                          0.);
    run_on_cells<CellContribution>(
      dof_handler,
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
        hanging_node_constraints.distribute_local_to_global(
          contribution.matrix, contribution.dof_indices, stiffness_matrix);
        hanging_node_constraints.distribute_local_to_global(
          contribution.rhs, contribution.dof_indices, load_vector);
        hanging_node_constraints.distribute_local_to_global(
          contribution.lumped_mass,
          contribution.dof_indices,
          dual_cell_measure);
        stiffness_diagonal.add(contribution.dof_indices,
                               contribution.stiffness_diagonal);
      });
    stiffness_matrix.compress(VectorOperation::add);
    load_vector.compress(VectorOperation::add);
    dual_cell_measure.compress(VectorOperation::add);
    stiffness_diagonal.compress(VectorOperation::add);
    stiffness_product.reinit(locally_owned_dofs, mpi_communicator);

    // The interior vertices of the owned and ghost cells, each once, by
    // their DoFs (u1, u2).
    std::vector<std::array<types::global_dof_index, 2>> candidates;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (!cell->is_artificial())
        for (const unsigned int v : cell->vertex_indices())
          if (!boundary_dofs.is_element(cell->vertex_dof_index(v, 0)))
            candidates.push_back(
              {{cell->vertex_dof_index(v, 0), cell->vertex_dof_index(v, 1)}});
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()),
                     candidates.end());

    const Epetra_CrsMatrix &epetra = stiffness_matrix.trilinos_matrix();
    const auto row_l1_norm         = [&](const types::global_dof_index row) {
      int     n_entries;
      double *values;
      int    *columns;
      epetra.ExtractMyRowView(epetra.LRID(static_cast<long long>(row)),
                              n_entries,
                              values,
                              columns);
      double norm = 0;
      for (int k = 0; k < n_entries; ++k)
        norm += std::abs(values[k]);
      return norm;
    };

    // V_h: the unconstrained ones; its owned vertices carry λ_a.
    interior_vertices.clear();
    relevant_vertices.clear();
    interior_vertex_dofs = IndexSet(dof_handler.n_dofs());
    for (const auto &dofs : candidates)
      {
        interior_vertex_dofs.add_index(dofs[0]);
        if (hanging_node_constraints.is_constrained(dofs[0]))
          continue;
        relevant_vertices.push_back(dofs);
        if (locally_owned_dofs.is_element(dofs[0]))
          interior_vertices.push_back({dofs,
                                       dual_cell_measure[dofs[0]],
                                       stiffness_diagonal[dofs[0]],
                                       row_l1_norm(dofs[0]) / data.mu[0]});
      }
    interior_vertex_dofs.compress();
    const auto &map = stiffness_product.trilinos_vector().Map();
    local_positions.resize(interior_vertices.size());
    for (unsigned int k = 0; k < interior_vertices.size(); ++k)
      for (unsigned int i = 0; i < 2; ++i)
        local_positions[k][i] =
          map.LID(static_cast<long long>(interior_vertices[k].dof[i]));
  }



  template <int dim>
  void
  DiscreteAction<dim>::compute(const VectorType &solution)
  {
    // The two terms of (4.5) at every DoF: μ_i ∫ ∇u_ih·∇φ as the product of
    // the operator with the nodal values (those of hanging nodes follow
    // from their parents, whose columns hold the condensed couplings), and
    // the loads ∫ f_i φ of this mesh.
    stiffness_matrix.vmult(stiffness_product, solution);

    // The size of the terms that (4.5) balances at a: the stiffness term
    // μ_i ∫ ∇u_ih·∇φ_a is a sum whose largest part is the diagonal one,
    // μ_i ∫|∇φ_a|² |u_ih(a)|; on fine meshes it cancels down to O(h²) and
    // its rounding error is relative to that diagonal part. Likewise for
    // the terms of the obstacle problem for w, whose combination
    // (μ2 · membrane 1 + μ1 · membrane 2)/(μ1 + μ2) carries the rounding
    // error of forces of tension μ̄.
    // The vectors of the locally owned DoFs, read at local_positions.
    const double *const products = stiffness_product.trilinos_vector()[0];
    const double *const loads    = load_vector.trilinos_vector()[0];
    const double *const values   = solution.trilinos_vector()[0];
    const double        mu1 = data.mu[0], mu2 = data.mu[1], M = mu1 + mu2;
    double              local_max = 0, local_contact_max = 0;
    for (unsigned int k = 0; k < interior_vertices.size(); ++k)
      {
        const Vertex &a        = interior_vertices[k];
        const auto   &position = local_positions[k];
        for (unsigned int i = 0; i < 2; ++i)
          local_max = std::max({local_max,
                                std::abs(products[position[i]]),
                                std::abs(loads[position[i]]),
                                data.mu[i] * a.stiffness_diagonal *
                                  std::abs(values[position[i]])});
        local_contact_max = std::max(
          {local_contact_max,
           std::abs(mu2 * products[position[0]] - mu1 * products[position[1]]) /
             M,
           std::abs(mu2 * loads[position[0]] - mu1 * loads[position[1]]) / M,
           data.mu_bar * a.stiffness_diagonal *
             std::max(std::abs(values[position[0]]),
                      std::abs(values[position[1]]))});
      }
    max_force = Utilities::MPI::max(local_max, mpi_communicator);
    max_contact_force =
      Utilities::MPI::max(local_contact_max, mpi_communicator);
  }



  template <int dim>
  std::pair<double, double>
  DiscreteAction<dim>::load_mean_and_oscillation(
    const typename DoFHandler<dim>::active_cell_iterator &cell,
    const unsigned int                                    i) const
  {
    const double *statistics =
      cell_loads(cell) + loads_per_cell - 4; // f̄_1K, f̄_2K, osc_1K, osc_2K
    return {statistics[i], statistics[2 + i]};
  }



  template <int dim>
  const double *
  DiscreteAction<dim>::cell_loads(
    const typename DoFHandler<dim>::active_cell_iterator &cell) const
  {
    return &loads_of_cells[cell->active_cell_index() * loads_per_cell];
  }



  template <int dim>
  const std::vector<typename DiscreteAction<dim>::Vertex> &
  DiscreteAction<dim>::vertices() const
  {
    return interior_vertices;
  }



  template <int dim>
  const std::vector<std::array<types::global_dof_index, 2>> &
  DiscreteAction<dim>::locally_relevant_vertices() const
  {
    return relevant_vertices;
  }



  template <int dim>
  const IndexSet &
  DiscreteAction<dim>::dual_mesh_vertices() const
  {
    return interior_vertex_dofs;
  }



  template <int dim>
  void
  DiscreteAction<dim>::fill_nodal_vector(VectorType &lambda_h) const
  {
    lambda_h = 0;
    for (unsigned int k = 0; k < interior_vertices.size(); ++k)
      for (const auto dof : interior_vertices[k].dof)
        lambda_h[dof] = lambda(k);
    lambda_h.compress(VectorOperation::insert);
  }



  template <int dim>
  double
  DiscreteAction<dim>::lambda_from_membrane(const unsigned int i,
                                            const unsigned int k) const
  {
    const double sign = (i == 0 ? 1. : -1.);
    return sign * (stiffness_term(i, k) - load_term(i, k)) /
           interior_vertices[k].dual_cell_measure;
  }



  template <int dim>
  double
  DiscreteAction<dim>::stiffness_term(const unsigned int i,
                                      const unsigned int k) const
  {
    return stiffness_product.trilinos_vector()[0][local_positions[k][i]];
  }



  template <int dim>
  double
  DiscreteAction<dim>::load_term(const unsigned int i,
                                 const unsigned int k) const
  {
    return load_vector.trilinos_vector()[0][local_positions[k][i]];
  }



  template <int dim>
  double
  DiscreteAction<dim>::lambda(const unsigned int k) const
  {
    return (data.mu[1] * lambda_from_membrane(0, k) +
            data.mu[0] * lambda_from_membrane(1, k)) /
           (data.mu[0] + data.mu[1]);
  }



  template <int dim>
  double
  DiscreteAction<dim>::force_scale() const
  {
    return max_force;
  }



  template <int dim>
  double
  DiscreteAction<dim>::contact_force_scale() const
  {
    return max_contact_force;
  }



  template <int dim>
  void
  DiscreteAction<dim>::set_lambda_h(const VectorType &lambda_h)
  {
    lambda_h_vector = &lambda_h;
  }



  template <int dim>
  const DualCellQuadrature<dim> &
  DiscreteAction<dim>::dual_quadrature() const
  {
    return dual_cell_quadrature;
  }



  template <int dim>
  double
  DiscreteAction<dim>::lambda_h_value(
    const typename DoFHandler<dim>::active_cell_iterator &cell,
    const unsigned int                                    v) const
  {
    return lambda_h_at_vertex(cell->vertex_dof_index(v, 0));
  }



  template <int dim>
  double
  DiscreteAction<dim>::lambda_h_at_vertex(const types::global_dof_index a) const
  {
    return interior_vertex_dofs.is_element(a) ? (*lambda_h_vector)[a] : 0.;
  }



  template <int dim>
  void
  DiscreteAction<dim>::lambda_h_values(
    const typename DoFHandler<dim>::active_cell_iterator &cell,
    std::vector<double>                                  &values,
    std::vector<bool>                                    *in_omega_h) const
  {
    // λ_h is constant on the pieces of each vertex: look it up once per
    // vertex, not once per point.
    std::array<double, GeometryInfo<dim>::vertices_per_cell> vertex_values;
    std::array<bool, GeometryInfo<dim>::vertices_per_cell>   vertex_in_omega_h;
    for (const unsigned int v : cell->vertex_indices())
      {
        vertex_values[v] = lambda_h_value(cell, v);
        vertex_in_omega_h[v] =
          interior_vertex_dofs.is_element(cell->vertex_dof_index(v, 0));
      }
    values.resize(dual_cell_quadrature.quadrature().size());
    if (in_omega_h)
      in_omega_h->resize(values.size());
    for (unsigned int q = 0; q < values.size(); ++q)
      {
        const unsigned int v = dual_cell_quadrature.vertex_of_point(q);
        values[q]            = vertex_values[v];
        if (in_omega_h)
          (*in_omega_h)[q] = vertex_in_omega_h[v];
      }
  }



  template <int dim>
  void
  DiscreteAction<dim>::nodal_lambda_values(const FEValues<dim> &fe_values,
                                           std::vector<double> &values) const
  {
    values.resize(fe_values.n_quadrature_points);
    fe_values[FEValuesExtractors::Scalar(0)].get_function_values(
      *lambda_h_vector, values);
  }



  template class DiscreteAction<2>;
} // namespace membranes
