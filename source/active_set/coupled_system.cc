#include <algorithm>
#include <cmath>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/lac/diagonal_matrix.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/linear_operator.h>
#include <deal.II/lac/sparsity_tools.h>
#include <membranes/active_set/coupled_system.h>

namespace membranes
{
  template <int dim>
  CoupledSystem<dim>::CoupledSystem(const Parameters::Solver &parameters,
                                    const ProblemData<dim>   &data,
                                    const MPI_Comm            mpi_communicator)
    : ActiveSetSystem<dim>("coupled", parameters, data, mpi_communicator)
  {}



  template <int dim>
  IndexSet
  CoupledSystem<dim>::system_unknowns(const IndexSet &dofs) const
  {
    IndexSet unknowns(block_indices.total_size());
    for (unsigned int i = 0; i < 2; ++i)
      unknowns.add_indices(dofs, block_indices.block_start(i));
    unknowns.compress();
    return unknowns;
  }



  template <int dim>
  void
  CoupledSystem<dim>::get_system_indices(
    const std::vector<types::global_dof_index> &dofs,
    std::vector<types::global_dof_index>       &indices) const
  {
    indices.resize(2 * dofs.size());
    for (unsigned int i = 0; i < 2; ++i)
      for (unsigned int v = 0; v < dofs.size(); ++v)
        indices[i * dofs.size() + v] =
          block_indices.local_to_global(i, dofs[v]);
  }



  template <int dim>
  void
  CoupledSystem<dim>::setup(const DiscreteProblem<dim> &problem,
                            const DoFHandler<dim>      &dof_handler)
  {
    block_indices.reinit(2, dof_handler.n_dofs());
    const IndexSet owned    = system_unknowns(problem.locally_owned_dofs());
    const IndexSet relevant = system_unknowns(problem.locally_relevant_dofs());

    // The constraints of membrane i (hanging nodes, boundary values g_i)
    // on the unknowns of block i.
    mesh_constraints.clear();
    mesh_constraints.reinit(relevant);
    for (unsigned int i = 0; i < 2; ++i)
      {
        for (const auto &line : problem.constraints(i).get_lines())
          {
            const auto row = block_indices.local_to_global(i, line.index);
            mesh_constraints.add_line(row);
            for (const auto &[column, weight] : line.entries)
              mesh_constraints.add_entry(
                row, block_indices.local_to_global(i, column), weight);
            mesh_constraints.set_inhomogeneity(row, line.inhomogeneity);
          }
      }
    mesh_constraints.close();

    // The constants of each membrane are the near null space of the system.
    const unsigned int n_owned = problem.locally_owned_dofs().n_elements();
    std::vector<std::vector<bool>> constant_modes(2,
                                                  std::vector<bool>(2 * n_owned,
                                                                    false));
    for (unsigned int i = 0; i < 2; ++i)
      std::fill_n(constant_modes[i].begin() + i * n_owned, n_owned, true);
    this->linear_solver.reinit(block_indices.total_size(), constant_modes);

    // The contact constraint u1(a) = u2(a) only ever couples unknowns of
    // vertices that share a cell, so the full coupling of all unknowns of a
    // cell (condensed with the constraints of the mesh) holds the matrix
    // of every active set, as step-41's pattern holds that of every active
    // set of its obstacle problem.
    DynamicSparsityPattern               dsp(relevant);
    std::vector<types::global_dof_index> dofs(
      dof_handler.get_fe().n_dofs_per_cell());
    std::vector<types::global_dof_index> indices;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          cell->get_dof_indices(dofs);
          get_system_indices(dofs, indices);
          mesh_constraints.add_entries_local_to_global(indices, dsp, false);
        }
    SparsityTools::distribute_sparsity_pattern(dsp,
                                               owned,
                                               this->mpi_communicator,
                                               relevant);
    system_matrix.reinit(owned, owned, dsp, this->mpi_communicator);
    system_rhs.reinit(owned, this->mpi_communicator);
    system_solution.reinit(owned, this->mpi_communicator);
    scaling.get_vector().reinit(owned, this->mpi_communicator);
    inverse_scaling.get_vector().reinit(owned, this->mpi_communicator);
  }



  template <int dim>
  void
  CoupledSystem<dim>::copy_to_system(const BlockVectorType &solution)
  {
    // The local storage of system_solution holds the owned entries of u1,
    // then those of u2.
    const unsigned int n_owned = solution.block(0).locally_owned_size();
    for (unsigned int i = 0; i < 2; ++i)
      std::copy_n(solution.block(i).begin(),
                  n_owned,
                  system_solution.begin() + i * n_owned);
  }



  template <int dim>
  void
  CoupledSystem<dim>::copy_from_system(BlockVectorType &solution) const
  {
    const unsigned int n_owned = solution.block(0).locally_owned_size();
    for (unsigned int i = 0; i < 2; ++i)
      std::copy_n(system_solution.begin() + i * n_owned,
                  n_owned,
                  solution.block(i).begin());
  }



  template <int dim>
  void
  CoupledSystem<dim>::assemble_system(const DiscreteProblem<dim> &problem,
                                      const IndexSet             &active_set)
  {
    // The block diagonal system of μ1 A and μ2 A with the lifted loads,
    // condensed with the contact lines u1(a) = u2(a) as AffineConstraints
    // condenses them in a cell loop (step-41): the equation of u1 at an
    // active vertex added to that of u2, the column of u1(a) to that of
    // u2(a), and μ1 ∫|∇φ_a|² left alone on the diagonal of u1(a). A is
    // condensed with the hanging node and boundary constraints already, so
    // that this gives the system of a cell loop without a cell matrix.
    const double mu1 = this->data.mu[0], mu2 = this->data.mu[1];
    const auto   u1 = [this](const types::global_dof_index dof) {
      return block_indices.local_to_global(0, dof);
    };
    const auto u2 = [this](const types::global_dof_index dof) {
      return block_indices.local_to_global(1, dof);
    };
    system_matrix = 0;
    std::array<std::vector<types::global_dof_index>, 2> columns;
    std::array<std::vector<double>, 2>                  values;
    this->for_each_row(
      problem,
      problem.laplace_matrix(),
      active_set,
      [&](const typename ActiveSetSystem<dim>::MatrixRow &row) {
        for (unsigned int i = 0; i < 2; ++i)
          {
            columns[i].clear();
            values[i].clear();
          }
        // The equation of membrane 1 in the row of u1, or of u2 if active.
        const unsigned int row_1 = row.active ? 1 : 0;
        for (int e = 0; e < row.n_entries; ++e)
          {
            const auto dof = row.column(e);
            columns[row_1].push_back(row.active_column(e) ? u2(dof) : u1(dof));
            values[row_1].push_back(mu1 * row.values[e]);
            columns[1].push_back(u2(dof));
            values[1].push_back(mu2 * row.values[e]);
          }
        if (row.active)
          {
            columns[0] = {u1(row.dof)};
            values[0]  = {mu1 * row.stiffness_diagonal};
          }
        for (unsigned int i = 0; i < 2; ++i)
          system_matrix.add(block_indices.local_to_global(i, row.dof),
                            columns[i].size(),
                            columns[i].data(),
                            values[i].data(),
                            false);
      });
    system_matrix.compress(VectorOperation::add);

    // The loads, those of u1 at an active vertex added to those of u2.
    const unsigned int  n_owned  = problem.locally_owned_dofs().n_elements();
    const double *const lifted_1 = problem.lifted_loads(0).begin();
    const double *const lifted_2 = problem.lifted_loads(1).begin();
    std::copy_n(lifted_1, n_owned, system_rhs.begin());
    std::copy_n(lifted_2, n_owned, system_rhs.begin() + n_owned);
    for (unsigned int k = 0; k < problem.vertices().size(); ++k)
      if (active_set.is_element(problem.vertices()[k].dof))
        {
          const unsigned int p = problem.local_positions()[k];
          system_rhs.begin()[n_owned + p] += lifted_1[p];
          system_rhs.begin()[p] = 0;
        }
  }



  template <int dim>
  void
  CoupledSystem<dim>::set_scaling(const DiscreteProblem<dim> &problem,
                                  const IndexSet             &active_set)
  {
    // m_j = μ_i at the unknowns of membrane i (the owned entries of u1, then
    // those of u2), μ1 + μ2 at both unknowns of an active vertex.
    const double       M       = this->data.mu[0] + this->data.mu[1];
    VectorType        &d       = scaling.get_vector();
    const unsigned int n_owned = problem.locally_owned_dofs().n_elements();
    for (unsigned int i = 0; i < 2; ++i)
      std::fill_n(d.begin() + i * n_owned,
                  n_owned,
                  1 / std::sqrt(this->data.mu[i]));
    for (const auto dof : active_set)
      if (problem.locally_owned_dofs().is_element(dof))
        for (unsigned int i = 0; i < 2; ++i)
          d[block_indices.local_to_global(i, dof)] = 1 / std::sqrt(M);
    d.compress(VectorOperation::insert);
    std::transform(d.begin(),
                   d.end(),
                   inverse_scaling.get_vector().begin(),
                   [](const double entry) { return 1 / entry; });
  }



  template <int dim>
  void
  CoupledSystem<dim>::set_active_set(const DiscreteProblem<dim> &problem,
                                     const IndexSet             &active_set)
  {
    constraints.clear();
    constraints.reinit(mesh_constraints.get_local_lines());
    for (const auto dof : problem.locally_relevant_vertices())
      if (active_set.is_element(dof))
        {
          const auto u1 = block_indices.local_to_global(0, dof);
          constraints.add_line(u1);
          constraints.add_entry(u1, block_indices.local_to_global(1, dof), 1.0);
        }
    constraints.merge(mesh_constraints);
    constraints.close();
    assemble_system(problem, active_set);
    set_scaling(problem, active_set);
  }



  template <int dim>
  void
  CoupledSystem<dim>::solve(const DiscreteProblem<dim> &,
                            BlockVectorType        &solution,
                            const LinearTolerances &tolerances,
                            ActiveSetStatistics    &statistics)
  {
    VectorType &x = system_solution;
    copy_to_system(solution);
    constraints.set_zero(x);
    if (this->linear_solver.is_direct())
      this->linear_solver.solve_direct(system_matrix, x, system_rhs);
    else
      {
        // CG on the system scaled by D = diag(m_j^{-1/2}), m_j = μ_i for
        // the DoFs of membrane i at inactive vertices and on ∂ω, μ1 + μ2
        // for both DoFs of an active vertex: D K D y = D b, u = D y. Its
        // residual D r then has the norm Σ_a (r_W,a² / μ̄ + r_S,a² /
        // (μ1 + μ2)) (sums over active vertices only r_S), so one bound on
        // it bounds r_S and r_W each on its own scale. D⁻¹ P D⁻¹, P the AMG
        // hierarchy of K built on every iteration, preconditions it.
        // The right-hand side is scaled in place: it is assembled anew for
        // the next iteration.
        system_rhs.scale(scaling.get_vector());
        x.scale(inverse_scaling.get_vector());
        this->linear_solver.initialize_preconditioner(system_matrix);
        const double tolerance =
          std::min(tolerances.contact / std::sqrt(this->data.mu_bar),
                   tolerances.sum /
                     std::sqrt(this->data.mu[0] + this->data.mu[1]));
        const auto K = linear_operator<VectorType>(system_matrix);
        const auto D = linear_operator<VectorType>(system_matrix, scaling);
        const auto D_inverse =
          linear_operator<VectorType>(system_matrix, inverse_scaling);
        const auto amg =
          linear_operator<VectorType>(system_matrix,
                                      this->linear_solver.preconditioner());
        statistics.linear_iterations += this->linear_solver.solve_cg(
          D * K * D, D_inverse * amg * D_inverse, x, system_rhs, tolerance);
        this->linear_solver.clear();
        x.scale(scaling.get_vector());
      }
    constraints.distribute(x);
    copy_from_system(solution);
  }



  template <int dim>
  void
  CoupledSystem<dim>::clear()
  {
    this->linear_solver.clear();
    system_matrix.clear();
    system_rhs.clear();
    system_solution.clear();
    scaling.get_vector().clear();
    inverse_scaling.get_vector().clear();
    constraints.clear();
    mesh_constraints.clear();
  }



  template class CoupledSystem<2>;
} // namespace membranes
