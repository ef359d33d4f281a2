#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_tools.h>
#include <membranes/estimators/linear_embedding.h>

namespace membranes
{
  template <int dim>
  LinearEmbedding<dim>::LinearEmbedding(
    const DoFHandler<dim>                                    &dof_handler,
    const AffineConstraints<double>                          &constraints,
    const std::shared_ptr<const Utilities::MPI::Partitioner> &partitioner,
    const DoFHandler<dim>           &linear_dof_handler,
    const AffineConstraints<double> &linear_constraints)
    : interpolation(dof_handler.get_fe().n_dofs_per_cell(),
                    linear_dof_handler.get_fe().n_dofs_per_cell())
  {
    FETools::get_interpolation_matrix(linear_dof_handler.get_fe(),
                                      dof_handler.get_fe(),
                                      interpolation);
    IndexSet linear_relevant;
    DoFTools::extract_locally_relevant_dofs(linear_dof_handler,
                                            linear_relevant);
    linear_partitioner = std::make_shared<Utilities::MPI::Partitioner>(
      linear_dof_handler.locally_owned_dofs(),
      linear_relevant,
      dof_handler.get_triangulation().get_communicator());

    const IndexSet   &owned = dof_handler.locally_owned_dofs();
    std::vector<bool> assigned(owned.n_elements(), false);
    std::vector<types::global_dof_index> dof_indices(interpolation.m());
    std::vector<types::global_dof_index> linear_dof_indices(interpolation.n());
    cell_offsets.push_back(0);
    linear_offsets.push_back(0);
    auto linear_cell = linear_dof_handler.begin_active();
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        if (cell->is_locally_owned())
          {
            cell->get_dof_indices(dof_indices);
            for (unsigned int i = 0; i < dof_indices.size(); ++i)
              if (owned.is_element(dof_indices[i]) &&
                  !constraints.is_constrained(dof_indices[i]) &&
                  !assigned[owned.index_within_set(dof_indices[i])])
                {
                  assigned[owned.index_within_set(dof_indices[i])] = true;
                  cell_positions.push_back(i);
                  cell_dofs.push_back(
                    partitioner->global_to_local(dof_indices[i]));
                }
            cell_offsets.push_back(cell_dofs.size());

            linear_cell->get_dof_indices(linear_dof_indices);
            for (const types::global_dof_index index : linear_dof_indices)
              {
                if (const auto *masters =
                      linear_constraints.get_constraint_entries(index))
                  for (const auto &[master, weight] : *masters)
                    {
                      linear_dofs.push_back(
                        linear_partitioner->global_to_local(master));
                      linear_weights.push_back(weight);
                    }
                else if (!linear_constraints.is_constrained(index))
                  {
                    linear_dofs.push_back(
                      linear_partitioner->global_to_local(index));
                    linear_weights.push_back(1.);
                  }
                linear_offsets.push_back(linear_dofs.size());
              }
          }
        ++linear_cell;
      }
  }



  template <int dim>
  void
  LinearEmbedding<dim>::initialize_linear_vector(VectorType &vector) const
  {
    vector.reinit(linear_partitioner);
  }



  template <int dim>
  void
  LinearEmbedding<dim>::prolongate(VectorType &dst, const VectorType &src) const
  {
    src.update_ghost_values();
    dst = 0.;
    std::vector<double> values(interpolation.n());
    for (unsigned int c = 0; c + 1 < cell_offsets.size(); ++c)
      {
        for (unsigned int J = 0; J < values.size(); ++J)
          {
            const unsigned int n = c * values.size() + J;
            values[J]            = 0.;
            for (unsigned int k = linear_offsets[n]; k < linear_offsets[n + 1];
                 ++k)
              values[J] +=
                linear_weights[k] * src.local_element(linear_dofs[k]);
          }
        for (unsigned int k = cell_offsets[c]; k < cell_offsets[c + 1]; ++k)
          {
            double value = 0.;
            for (unsigned int J = 0; J < values.size(); ++J)
              value += interpolation(cell_positions[k], J) * values[J];
            dst.local_element(cell_dofs[k]) = value;
          }
      }
    src.zero_out_ghost_values();
  }



  template <int dim>
  void
  LinearEmbedding<dim>::restrict_and_add(VectorType       &dst,
                                         const VectorType &src) const
  {
    std::vector<double> values(interpolation.n());
    for (unsigned int c = 0; c + 1 < cell_offsets.size(); ++c)
      {
        std::fill(values.begin(), values.end(), 0.);
        for (unsigned int k = cell_offsets[c]; k < cell_offsets[c + 1]; ++k)
          for (unsigned int J = 0; J < values.size(); ++J)
            values[J] += interpolation(cell_positions[k], J) *
                         src.local_element(cell_dofs[k]);
        for (unsigned int J = 0; J < values.size(); ++J)
          {
            const unsigned int n = c * values.size() + J;
            for (unsigned int k = linear_offsets[n]; k < linear_offsets[n + 1];
                 ++k)
              dst.local_element(linear_dofs[k]) +=
                linear_weights[k] * values[J];
          }
      }
    dst.compress(VectorOperation::add);
  }



  template class LinearEmbedding<2>;
} // namespace membranes
