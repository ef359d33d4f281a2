/**
 * The geometric multigrid of benchmarks/gmg_floor.cc on matrix-free
 * operators (`gmg_floor s gmg`, variants (a)-(c) of the `w` problem): the
 * V-cycle of deal.II's step-37 and step-50, whose level operators are
 * MatrixFreeOperators::LaplaceOperator in float. The head comment of
 * gmg_floor.cc says what is measured.
 */

#include "gmg_floor.h"

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/matrix_free/matrix_free.h>

namespace gmg_floor
{
  GeometricMultigrid::GeometricMultigrid(
    const DoFHandler<dim> &dof_handler,
    const Mapping<dim>    &mapping,
    const Shape            shape,
    const unsigned int     first_constrained_level,
    Recorder              &recorder,
    const std::string     &label)
  {
    recorder.timed(label + "levels: constrained DoFs, level MatrixFree", [&]() {
      setup_level_operators(dof_handler,
                            mapping,
                            shape,
                            first_constrained_level);
    });

    recorder.timed(label + "transfer", [&]() {
      transfer.initialize_constraints(constrained_dofs);
      transfer.build(dof_handler);
    });

    recorder.timed(label + "smoother: diagonals, eigenvalue estimates",
                   [&]() { setup_smoother_and_cycle(dof_handler); });
  }



  /**
   * The level operators: on each level a MatrixFree in float whose
   * constraints are the level boundary DoFs and, on the levels from
   * @p first_constrained_level on, the level DoFs at the vertices of the
   * active set, which are also user constraints of the transfer.
   */
  void
  GeometricMultigrid::setup_level_operators(
    const DoFHandler<dim> &dof_handler,
    const Mapping<dim>    &mapping,
    const Shape            shape,
    const unsigned int     first_constrained_level)
  {
    const unsigned int n_levels =
      dof_handler.get_triangulation().n_global_levels();
    constrained_dofs.initialize(dof_handler);
    constrained_dofs.make_zero_boundary_constraints(dof_handler, {0});
    matrices.resize(0, n_levels - 1);
    for (unsigned int level = 0; level < n_levels; ++level)
      {
        IndexSet relevant_dofs;
        DoFTools::extract_locally_relevant_level_dofs(dof_handler,
                                                      level,
                                                      relevant_dofs);
        AffineConstraints<double> level_constraints(relevant_dofs);
        level_constraints.add_lines(
          constrained_dofs.get_boundary_indices(level));

        if (shape != Shape::none && level >= first_constrained_level)
          {
            // The level DoFs at the vertices of the active set, as
            // homogeneous constraints of the level operator and as user
            // constraints of the transfer.
            AffineConstraints<double> active(relevant_dofs);
            active.add_lines(
              active_level_dofs(dof_handler, level, shape, constrained_dofs));
            active.close();
            level_constraints.merge(active,
                                    AffineConstraints<double>::
                                      MergeConflictBehavior::right_object_wins);
            constrained_dofs.add_user_constraints(level, active);
          }
        level_constraints.close();

        typename MatrixFree<dim, float>::AdditionalData data;
        data.tasks_parallel_scheme =
          MatrixFree<dim, float>::AdditionalData::none;
        data.mapping_update_flags = update_gradients | update_JxW_values;
        data.mg_level             = level;
        auto level_storage        = std::make_shared<MatrixFree<dim, float>>();
        level_storage->reinit(
          mapping, dof_handler, level_constraints, QGauss<1>(2), data);
        matrices[level].initialize(level_storage, constrained_dofs, level);
      }
  }



  /**
   * Chebyshev smoothing of degree 5 with the inverse diagonal of each level
   * operator, Chebyshev to accuracy on the coarse level, the interface
   * operators on the refinement edges, and the V-cycle.
   */
  void
  GeometricMultigrid::setup_smoother_and_cycle(
    const DoFHandler<dim> &dof_handler)
  {
    const unsigned int n_levels =
      dof_handler.get_triangulation().n_global_levels();
    MGLevelObject<SmootherType::AdditionalData> smoother_data(0, n_levels - 1);
    for (unsigned int level = 0; level < n_levels; ++level)
      {
        smoother_data[level] =
          chebyshev_settings<SmootherType::AdditionalData>(level,
                                                           5,
                                                           matrices[0].m());
        matrices[level].compute_diagonal();
        smoother_data[level].preconditioner =
          matrices[level].get_matrix_diagonal_inverse();
      }
    smoother.initialize(matrices, smoother_data);
    coarse.initialize(smoother);

    interface_matrices.resize(0, n_levels - 1);
    for (unsigned int level = 0; level < n_levels; ++level)
      interface_matrices[level].initialize(matrices[level]);
    matrix_wrapper.initialize(matrices);
    interface_wrapper.initialize(interface_matrices);

    multigrid = std::make_unique<Multigrid<LevelVectorType>>(
      matrix_wrapper, coarse, transfer, smoother, smoother);
    multigrid->set_edge_matrices(interface_wrapper, interface_wrapper);
    mg_preconditioner =
      std::make_unique<PreconditionType>(dof_handler, *multigrid, transfer);
  }
} // namespace gmg_floor
