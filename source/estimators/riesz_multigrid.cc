#include <cmath>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_tools.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <membranes/estimators/riesz_multigrid.h>
#include <vector>

namespace membranes
{
  namespace
  {
    /**
     * The embedding P of the space of @p linear_dof_handler (degree 1,
     * @p linear_constraints) into that of @p dof_handler (@p constraints)
     * into @p prolongation: the row of an unconstrained DoF x_i of V_p holds
     * φ_J(x_i) for the DoFs J of V_1, read on any cell that holds x_i (the
     * functions of V_1 are continuous), with a constrained DoF of V_1
     * replaced by its masters. The rows of the constrained DoFs of V_p are
     * zero: the operator and its smoother leave them out.
     */
    template <int dim>
    void
    make_prolongation(const DoFHandler<dim>           &dof_handler,
                      const AffineConstraints<double> &constraints,
                      const DoFHandler<dim>           &linear_dof_handler,
                      const AffineConstraints<double> &linear_constraints,
                      TrilinosWrappers::SparseMatrix  &prolongation)
    {
      const FiniteElement<dim> &fe        = dof_handler.get_fe();
      const FiniteElement<dim> &linear_fe = linear_dof_handler.get_fe();
      FullMatrix<double>        interpolation(fe.n_dofs_per_cell(),
                                       linear_fe.n_dofs_per_cell());
      FETools::get_interpolation_matrix(linear_fe, fe, interpolation);

      const IndexSet &owned = dof_handler.locally_owned_dofs();
      std::vector<types::global_dof_index> dof_indices(fe.n_dofs_per_cell());
      std::vector<types::global_dof_index> linear_dof_indices(
        linear_fe.n_dofs_per_cell());
      std::vector<types::global_dof_index> columns;
      std::vector<double>                  values;

      // @p process(row, columns, values) once for each owned, unconstrained
      // DoF of V_p, with its entries.
      const auto for_each_row = [&](const auto &process) {
        std::vector<bool> done(owned.n_elements(), false);
        auto              linear_cell = linear_dof_handler.begin_active();
        for (const auto &cell : dof_handler.active_cell_iterators())
          {
            if (cell->is_locally_owned())
              {
                cell->get_dof_indices(dof_indices);
                linear_cell->get_dof_indices(linear_dof_indices);
                for (unsigned int i = 0; i < dof_indices.size(); ++i)
                  {
                    const types::global_dof_index row = dof_indices[i];
                    if (!owned.is_element(row) ||
                        constraints.is_constrained(row) ||
                        done[owned.index_within_set(row)])
                      continue;
                    done[owned.index_within_set(row)] = true;
                    columns.clear();
                    values.clear();
                    const auto add = [&](const types::global_dof_index column,
                                         const double                  value) {
                      const auto entry =
                        std::find(columns.begin(), columns.end(), column);
                      if (entry != columns.end())
                        values[entry - columns.begin()] += value;
                      else
                        {
                          columns.push_back(column);
                          values.push_back(value);
                        }
                    };
                    for (unsigned int j = 0; j < linear_dof_indices.size(); ++j)
                      {
                        const double phi = interpolation(i, j);
                        if (std::abs(phi) < 1e-12)
                          continue;
                        const types::global_dof_index column =
                          linear_dof_indices[j];
                        if (!linear_constraints.is_constrained(column))
                          add(column, phi);
                        else if (const auto *masters =
                                   linear_constraints.get_constraint_entries(
                                     column))
                          for (const auto &[master, weight] : *masters)
                            add(master, phi * weight);
                      }
                    process(row, columns, values);
                  }
              }
            ++linear_cell;
          }
      };

      DynamicSparsityPattern dsp(dof_handler.n_dofs(),
                                 linear_dof_handler.n_dofs(),
                                 owned);
      for_each_row([&](const types::global_dof_index               row,
                       const std::vector<types::global_dof_index> &columns,
                       const std::vector<double> &) {
        dsp.add_entries(row, columns.begin(), columns.end());
      });
      prolongation.reinit(owned,
                          linear_dof_handler.locally_owned_dofs(),
                          dsp,
                          dof_handler.get_triangulation().get_communicator());
      for_each_row([&](const types::global_dof_index               row,
                       const std::vector<types::global_dof_index> &columns,
                       const std::vector<double>                  &values) {
        prolongation.add(row, columns.size(), columns.data(), values.data());
      });
      prolongation.compress(VectorOperation::add);
    }
  } // namespace



  template <int dim>
  RieszMultigrid<dim>::RieszMultigrid(
    const RieszOperator<dim>        &riesz,
    const DoFHandler<dim>           &dof_handler,
    const AffineConstraints<double> &constraints,
    const DoFHandler<dim>           &linear_dof_handler,
    const AffineConstraints<double> &linear_constraints,
    const Mapping<dim>              &mapping,
    const Quadrature<dim>           &linear_quadrature)
    : riesz(riesz)
  {
    typename Smoother::AdditionalData smoother_data;
    smoother_data.preconditioner =
      std::make_shared<DiagonalMatrix<VectorType>>();
    riesz.compute_inverse_diagonal(smoother_data.preconditioner->get_vector());
    // Degree 1: one product with A + M a smoothing step. Degrees 2 to 4
    // save at most one CG iteration of the six to eight at 526 338 DoFs,
    // each at the price of two more products per V-cycle.
    smoother_data.degree              = 1;
    smoother_data.smoothing_range     = 10.;
    smoother_data.eig_cg_n_iterations = 10;
    smoother.initialize(riesz, smoother_data);

    // The matrix of degree 1 from the same cell integral; its matrix-free
    // operator is freed before the hierarchy is built.
    RieszOperator<dim>(mapping,
                       linear_dof_handler,
                       linear_constraints,
                       linear_quadrature)
      .compute_matrix(linear_matrix);
    TrilinosWrappers::PreconditionAMG::AdditionalData amg_data;
    amg_data.elliptic = true;
    amg.initialize(linear_matrix, amg_data);

    make_prolongation(dof_handler,
                      constraints,
                      linear_dof_handler,
                      linear_constraints,
                      prolongation);

    riesz.initialize_dof_vector(residual);
    const MPI_Comm communicator =
      dof_handler.get_triangulation().get_communicator();
    linear_residual.reinit(linear_dof_handler.locally_owned_dofs(),
                           communicator);
    linear_correction.reinit(linear_residual);
  }



  template <int dim>
  void
  RieszMultigrid<dim>::vmult(VectorType &dst, const VectorType &src) const
  {
    smoother.vmult(dst, src);
    riesz.vmult(residual, dst);
    residual.sadd(-1., 1., src);
    prolongation.Tvmult(linear_residual, residual);
    amg.vmult(linear_correction, linear_residual);
    prolongation.vmult(residual, linear_correction);
    dst += residual;
    smoother.step(dst, src);
  }



  template class RieszMultigrid<2>;
} // namespace membranes
