#include <membranes/cell_system.h>

namespace membranes
{
  template <int dim>
  CellSystem<dim>::CellSystem(const Discretization<dim> &discretization,
                              const ProblemData<dim>    &data)
    : matrix(discretization.fe->n_dofs_per_cell(),
             discretization.fe->n_dofs_per_cell())
    , rhs(discretization.fe->n_dofs_per_cell())
    , lumped_mass(discretization.fe->n_dofs_per_cell())
    , dof_indices(discretization.fe->n_dofs_per_cell())
    , data(data)
    , fe_values(*discretization.mapping,
                *discretization.fe,
                discretization.cell_quadrature,
                update_values | update_gradients | update_quadrature_points |
                  update_JxW_values)
  {
    for (unsigned int i = 0; i < discretization.fe->n_dofs_per_cell(); ++i)
      membrane.push_back(discretization.fe->system_to_component_index(i).first);
    for (auto &load : loads)
      load.resize(fe_values.n_quadrature_points);
  }



  template <int dim>
  void
  CellSystem<dim>::reinit(
    const typename DoFHandler<dim>::active_cell_iterator &cell)
  {
    fe_values.reinit(cell);
    cell->get_dof_indices(dof_indices);
    for (unsigned int c = 0; c < 2; ++c)
      data.load(c).value_list(fe_values.get_quadrature_points(), loads[c]);

    matrix      = 0;
    rhs         = 0;
    lumped_mass = 0;
    // Both base elements are primitive: shape_grad(i, q) is the gradient of
    // the one non-zero component of φ_i, and the membranes do not couple.
    for (const unsigned int q : fe_values.quadrature_point_indices())
      for (const unsigned int i : fe_values.dof_indices())
        {
          const unsigned int c = membrane[i];
          for (const unsigned int j : fe_values.dof_indices())
            if (membrane[j] == c)
              matrix(i, j) += data.mu[c] * fe_values.shape_grad(i, q) *
                              fe_values.shape_grad(j, q) * fe_values.JxW(q);
          rhs(i) +=
            loads[c][q] * fe_values.shape_value(i, q) * fe_values.JxW(q);
          lumped_mass(i) += fe_values.shape_value(i, q) * fe_values.JxW(q);
        }
  }



  template <int dim>
  unsigned int
  CellSystem<dim>::membrane_of(const unsigned int i) const
  {
    return membrane[i];
  }



  template class CellSystem<2>;
} // namespace membranes
