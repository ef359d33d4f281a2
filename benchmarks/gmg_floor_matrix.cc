/**
 * The geometric multigrid of benchmarks/gmg_floor.cc on assembled level
 * matrices (`gmg_floor s gmgmatrix`, variant (d) of the `w` problem): the
 * V-cycle of deal.II's step-16 and of the matrix-based path of step-50,
 * whose smoother and residuals use the sparse product of Trilinos. The
 * head comment of gmg_floor.cc says what is measured.
 */

#include "gmg_floor.h"

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/multigrid/mg_tools.h>

namespace gmg_floor
{
  CellLaplacian::CellLaplacian(const Mapping<dim>       &mapping,
                               const FiniteElement<dim> &fe)
    : matrix(fe.n_dofs_per_cell(), fe.n_dofs_per_cell())
    , rhs(fe.n_dofs_per_cell())
    , indices(fe.n_dofs_per_cell())
    , fe_values(mapping,
                fe,
                QGauss<dim>(2),
                update_values | update_gradients | update_JxW_values)
  {}



  void
  CellLaplacian::compute()
  {
    const unsigned int n = fe_values.dofs_per_cell;
    matrix               = 0;
    rhs                  = 0;
    for (const unsigned int q : fe_values.quadrature_point_indices())
      for (unsigned int i = 0; i < n; ++i)
        {
          for (unsigned int j = 0; j < n; ++j)
            matrix(i, j) += fe_values.shape_grad(i, q) *
                            fe_values.shape_grad(j, q) * fe_values.JxW(q);
          rhs(i) += fe_values.shape_value(i, q) * fe_values.JxW(q);
        }
  }



  InverseDiagonal::InverseDiagonal(const SparseMatrixType &matrix)
    : inverse(matrix.locally_owned_range_indices(),
              matrix.get_mpi_communicator())
  {
    for (const auto i : matrix.locally_owned_range_indices())
      inverse(i) = 1. / matrix.diag_element(i);
    inverse.compress(VectorOperation::insert);
  }



  MatrixBasedMultigrid::MatrixBasedMultigrid(const DoFHandler<dim> &dof_handler,
                                             const Mapping<dim>    &mapping,
                                             const Shape            shape,
                                             const unsigned int     degree,
                                             Recorder              &recorder,
                                             const std::string     &label)
  {
    std::vector<IndexSet> relevant_dofs(
      dof_handler.get_triangulation().n_global_levels());

    recorder.timed(label + "level sparsity patterns, matrix reinit", [&]() {
      setup_level_matrices(dof_handler, shape, relevant_dofs);
    });

    recorder.timed(label + "level assembly", [&]() {
      assemble_level_matrices(dof_handler, mapping, relevant_dofs);
    });

    recorder.timed(label + "transfer", [&]() {
      transfer.initialize_constraints(constrained_dofs);
      transfer.build(dof_handler);
    });

    recorder.timed(label + "smoother: diagonals, eigenvalue estimates",
                   [&]() { setup_smoother_and_cycle(dof_handler, degree); });
  }



  /**
   * The level boundary DoFs (with the level DoFs at the vertices of the
   * active set of @p shape among them), the locally relevant level DoFs
   * into @p relevant_dofs, and the level and interface matrices with the
   * sparsity patterns of the levels.
   */
  void
  MatrixBasedMultigrid::setup_level_matrices(
    const DoFHandler<dim> &dof_handler,
    const Shape            shape,
    std::vector<IndexSet> &relevant_dofs)
  {
    const MPI_Comm     comm     = dof_handler.get_communicator();
    const unsigned int n_levels = relevant_dofs.size();
    constrained_dofs.initialize(dof_handler);
    constrained_dofs.make_zero_boundary_constraints(dof_handler, {0});
    // The level DoFs at the vertices of the active set as level boundary
    // DoFs: the level matrices keep only their diagonal, and
    // MGTransferPrebuilt does not prolongate from them.
    if (shape != Shape::none)
      for (unsigned int level = 0; level < n_levels; ++level)
        constrained_dofs.add_boundary_indices(
          dof_handler,
          level,
          active_level_dofs(dof_handler, level, shape, constrained_dofs));

    matrices.resize(0, n_levels - 1);
    interface_matrices.resize(0, n_levels - 1);
    for (unsigned int level = 0; level < n_levels; ++level)
      {
        DoFTools::extract_locally_relevant_level_dofs(dof_handler,
                                                      level,
                                                      relevant_dofs[level]);
        const IndexSet &owned  = dof_handler.locally_owned_mg_dofs(level);
        const auto      reinit = [&](SparseMatrixType       &matrix,
                                DynamicSparsityPattern &dsp) {
          SparsityTools::distribute_sparsity_pattern(dsp,
                                                     owned,
                                                     comm,
                                                     relevant_dofs[level]);
          matrix.reinit(owned, owned, dsp, comm);
        };
        DynamicSparsityPattern dsp(relevant_dofs[level]);
        MGTools::make_sparsity_pattern(dof_handler, dsp, level);
        reinit(matrices[level], dsp);
        DynamicSparsityPattern interface_dsp(relevant_dofs[level]);
        MGTools::make_interface_sparsity_pattern(dof_handler,
                                                 constrained_dofs,
                                                 interface_dsp,
                                                 level);
        reinit(interface_matrices[level], interface_dsp);
      }
  }



  /**
   * The Laplacian on the cells of each level into the level matrix, whose
   * rows at the level boundary and refinement edge DoFs keep only their
   * diagonal (step-16), and its entries that couple refinement edge DoFs
   * with the others into the interface matrix.
   */
  void
  MatrixBasedMultigrid::assemble_level_matrices(
    const DoFHandler<dim>       &dof_handler,
    const Mapping<dim>          &mapping,
    const std::vector<IndexSet> &relevant_dofs)
  {
    const unsigned int                     n_levels = relevant_dofs.size();
    std::vector<AffineConstraints<double>> level_constraints(n_levels);
    for (unsigned int level = 0; level < n_levels; ++level)
      {
        level_constraints[level].reinit(relevant_dofs[level]);
        level_constraints[level].add_lines(
          constrained_dofs.get_refinement_edge_indices(level));
        level_constraints[level].add_lines(
          constrained_dofs.get_boundary_indices(level));
        level_constraints[level].close();
      }
    CellLaplacian             local(mapping, dof_handler.get_fe());
    const unsigned int        n = local.indices.size();
    const types::subdomain_id owner =
      dof_handler.get_triangulation().locally_owned_subdomain();
    for (const auto &cell : dof_handler.mg_cell_iterators())
      if (cell->level_subdomain_id() == owner)
        {
          const unsigned int level = cell->level();
          local.reinit(cell);
          cell->get_mg_dof_indices(local.indices);
          level_constraints[level].distribute_local_to_global(local.matrix,
                                                              local.indices,
                                                              matrices[level]);
          for (unsigned int i = 0; i < n; ++i)
            for (unsigned int j = 0; j < n; ++j)
              if (constrained_dofs.is_interface_matrix_entry(level,
                                                             local.indices[i],
                                                             local.indices[j]))
                interface_matrices[level].add(local.indices[i],
                                              local.indices[j],
                                              local.matrix(i, j));
        }
    for (unsigned int level = 0; level < n_levels; ++level)
      {
        matrices[level].compress(VectorOperation::add);
        interface_matrices[level].compress(VectorOperation::add);
      }
  }



  /**
   * Chebyshev smoothing of degree @p degree with the inverse diagonal of
   * each level matrix, Chebyshev to accuracy on the coarse level, and the
   * V-cycle with the interface matrices on the refinement edges.
   */
  void
  MatrixBasedMultigrid::setup_smoother_and_cycle(
    const DoFHandler<dim> &dof_handler,
    const unsigned int     degree)
  {
    const unsigned int n_levels =
      dof_handler.get_triangulation().n_global_levels();
    MGLevelObject<SparseSmootherType::AdditionalData> smoother_data(0,
                                                                    n_levels -
                                                                      1);
    for (unsigned int level = 0; level < n_levels; ++level)
      {
        smoother_data[level] =
          chebyshev_settings<SparseSmootherType::AdditionalData>(
            level, degree, matrices[0].m());
        smoother_data[level].preconditioner =
          std::make_shared<InverseDiagonal>(matrices[level]);
      }
    smoother.initialize(matrices, smoother_data);
    coarse.initialize(smoother);

    matrix_wrapper.initialize(matrices);
    interface_wrapper.initialize(interface_matrices);
    multigrid = std::make_unique<Multigrid<SparseVectorType>>(
      matrix_wrapper, coarse, transfer, smoother, smoother);
    multigrid->set_edge_matrices(interface_wrapper, interface_wrapper);
    mg_preconditioner = std::make_unique<SparsePreconditionType>(dof_handler,
                                                                 *multigrid,
                                                                 transfer);
  }
} // namespace gmg_floor
