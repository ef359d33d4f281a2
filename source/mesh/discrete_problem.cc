#include <algorithm>
#include <deal.II/base/function.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/numerics/vector_tools.h>
#include <map>
#include <membranes/mesh/cell_loop.h>
#include <membranes/mesh/cell_system.h>
#include <membranes/mesh/discrete_problem.h>

namespace membranes
{
  template <int dim>
  DiscreteProblem<dim>::DiscreteProblem(
    const Discretization<dim> &discretization,
    const ProblemData<dim>    &data)
    : discretization(discretization)
    , data(data)
    , mpi_communicator(MPI_COMM_SELF)
  {}



  template <int dim>
  void
  DiscreteProblem<dim>::reinit(
    const DoFHandler<dim>           &dof_handler,
    const IndexSet                  &locally_relevant_dofs,
    const AffineConstraints<double> &hanging_node_constraints,
    const DualMesh<dim>             &dual_mesh,
    const MPI_Comm                   mpi_communicator)
  {
    this->mpi_communicator = mpi_communicator;
    owned_dofs             = dof_handler.locally_owned_dofs();
    relevant_dofs          = locally_relevant_dofs;
    make_constraints(dof_handler, hanging_node_constraints);

    // Both membranes constrain the same lines: one pattern, without the
    // rows and columns of constrained DoFs.
    DynamicSparsityPattern dsp(relevant_dofs);
    DoFTools::make_sparsity_pattern(dof_handler,
                                    dsp,
                                    membrane_constraints[0],
                                    false);
    SparsityTools::distribute_sparsity_pattern(dsp,
                                               owned_dofs,
                                               mpi_communicator,
                                               relevant_dofs);
    matrix.reinit(owned_dofs, owned_dofs, dsp, mpi_communicator);
    for (unsigned int i = 0; i < 2; ++i)
      {
        load_vectors[i].reinit(owned_dofs, mpi_communicator);
        lifted_load_vectors[i].reinit(owned_dofs, mpi_communicator);
      }

    VectorType dual_cell_measure(owned_dofs, mpi_communicator);
    VectorType stiffness_diagonal(owned_dofs, mpi_communicator);
    assemble(dof_handler,
             hanging_node_constraints,
             dual_cell_measure,
             stiffness_diagonal);
    find_vertices(dual_mesh,
                  hanging_node_constraints,
                  dual_cell_measure,
                  stiffness_diagonal);
  }



  template <int dim>
  void
  DiscreteProblem<dim>::make_constraints(
    const DoFHandler<dim>           &dof_handler,
    const AffineConstraints<double> &hanging_node_constraints)
  {
    for (unsigned int i = 0; i < 2; ++i)
      {
        AffineConstraints<double> &constraints = membrane_constraints[i];
        constraints.clear();
        constraints.reinit(relevant_dofs);
        const ScalarFunctionFromFunctionObject<dim> boundary_values(
          [this, i](const Point<dim> &p) {
            return data.boundary_values().value(p, i);
          });
        std::map<types::boundary_id, const Function<dim> *> boundary_functions;
        for (const auto id : dof_handler.get_triangulation().get_boundary_ids())
          boundary_functions[id] = &boundary_values;
        VectorTools::interpolate_boundary_values(*discretization.mapping,
                                                 dof_handler,
                                                 boundary_functions,
                                                 constraints);
        // A hanging vertex on ∂ω keeps its hanging node constraint, its
        // value that of the boundary values of its parents.
        constraints.merge(hanging_node_constraints,
                          AffineConstraints<double>::right_object_wins);
        constraints.close();
      }
  }



  template <int dim>
  void
  DiscreteProblem<dim>::assemble(
    const DoFHandler<dim>           &dof_handler,
    const AffineConstraints<double> &hanging_node_constraints,
    VectorType                      &dual_cell_measure,
    VectorType                      &stiffness_diagonal)
  {
    // The cell loop on threads: each works with its own CellSystem, the
    // mean and oscillation of the loads of every cell go to that cell's own
    // entry of load_statistics, and
    // the copier adds the cell's contributions to the global objects, as
    // step-41 does, by distribute_local_to_global: A_K condensed with the
    // constraints of the mesh, the loads F_iK with the hanging node
    // constraints alone and, lifted by μ_i A_K, with the boundary values of
    // membrane i, d_a = ∫ φ_a as the row sums of the mass matrix, and the
    // diagonal ∫ |∇φ_a|².
    struct CellContribution
    {
      FullMatrix<double>                   laplace_matrix;
      std::array<Vector<double>, 2>        loads;
      Vector<double>                       lumped_mass, diagonal;
      std::vector<types::global_dof_index> dof_indices;
    };
    const unsigned int n_vertices = dof_handler.get_fe().n_dofs_per_cell();
    load_statistics.assign(dof_handler.get_triangulation().n_active_cells(),
                           {});
    FullMatrix<double> membrane_matrix(n_vertices);
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
        load_statistics[cell->active_cell_index()] = {
          {cell_system.load_mean[0],
           cell_system.load_mean[1],
           cell_system.load_oscillation[0],
           cell_system.load_oscillation[1]}};
        contribution.laplace_matrix = cell_system.laplace_matrix;
        contribution.loads          = cell_system.loads;
        contribution.lumped_mass    = cell_system.lumped_mass;
        contribution.dof_indices    = cell_system.dof_indices;
        contribution.diagonal.reinit(n_vertices);
        for (unsigned int v = 0; v < n_vertices; ++v)
          contribution.diagonal(v) = cell_system.laplace_matrix(v, v);
      },
      [&](const CellContribution &contribution) {
        if (contribution.dof_indices.empty())
          return;
        const auto &dofs = contribution.dof_indices;
        membrane_constraints[0].distribute_local_to_global(
          contribution.laplace_matrix, dofs, matrix);
        for (unsigned int i = 0; i < 2; ++i)
          {
            hanging_node_constraints.distribute_local_to_global(
              contribution.loads[i], dofs, load_vectors[i]);
            membrane_matrix.equ(data.mu[i], contribution.laplace_matrix);
            membrane_constraints[i].distribute_local_to_global(
              contribution.loads[i],
              dofs,
              lifted_load_vectors[i],
              membrane_matrix);
          }
        hanging_node_constraints.distribute_local_to_global(
          contribution.lumped_mass, dofs, dual_cell_measure);
        stiffness_diagonal.add(dofs, contribution.diagonal);
      });
    matrix.compress(VectorOperation::add);
    for (unsigned int i = 0; i < 2; ++i)
      {
        load_vectors[i].compress(VectorOperation::add);
        lifted_load_vectors[i].compress(VectorOperation::add);
      }
    dual_cell_measure.compress(VectorOperation::add);
    stiffness_diagonal.compress(VectorOperation::add);
  }



  template <int dim>
  void
  DiscreteProblem<dim>::find_vertices(
    const DualMesh<dim>             &dual_mesh,
    const AffineConstraints<double> &hanging_node_constraints,
    const VectorType                &dual_cell_measure,
    const VectorType                &stiffness_diagonal)
  {
    // 1/‖A_a‖₁ of the locally owned rows of A, by Epetra's own inverse row
    // sums of absolute values (benchmarks/choices.md, "The matrices of an
    // active set from the mesh's A", says why not deal.II's row iterator).
    VectorType inverse_row_l1_norm(owned_dofs, mpi_communicator);
    AssertThrow(matrix.trilinos_matrix().InvRowSums(
                  *inverse_row_l1_norm.trilinos_vector()(0)) == 0,
                ExcInternalError());

    // V_h: the unconstrained interior vertices; its owned vertices carry
    // λ_a.
    interior_vertices.clear();
    relevant_vertices.clear();
    for (const auto dof : dual_mesh.interior_vertices())
      {
        if (hanging_node_constraints.is_constrained(dof))
          continue;
        relevant_vertices.push_back(dof);
        if (owned_dofs.is_element(dof))
          interior_vertices.push_back({dof,
                                       dual_cell_measure[dof],
                                       stiffness_diagonal[dof],
                                       1 / inverse_row_l1_norm[dof]});
      }
    positions.resize(interior_vertices.size());
    for (unsigned int k = 0; k < interior_vertices.size(); ++k)
      positions[k] = owned_dofs.index_within_set(interior_vertices[k].dof);
  }



  template <int dim>
  std::pair<double, double>
  DiscreteProblem<dim>::load_mean_and_oscillation(
    const typename DoFHandler<dim>::active_cell_iterator &cell,
    const unsigned int                                    i) const
  {
    const auto &statistics = load_statistics[cell->active_cell_index()];
    return {statistics[i], statistics[2 + i]};
  }



  template class DiscreteProblem<2>;
} // namespace membranes
