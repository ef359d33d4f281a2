#include <algorithm>
#include <cmath>
#include <membranes/mesh/cell_system.h>

namespace membranes
{
  template <int dim>
  CellSystem<dim>::CellSystem(const Discretization<dim> &discretization,
                              const ProblemData<dim>    &data)
    : laplace_matrix(discretization.fe->n_dofs_per_cell(),
                     discretization.fe->n_dofs_per_cell())
    , lumped_mass(discretization.fe->n_dofs_per_cell())
    , dof_indices(discretization.fe->n_dofs_per_cell())
    , data(data)
    , fe_values(*discretization.mapping,
                *discretization.fe,
                discretization.cell_quadrature,
                update_values | update_gradients | update_quadrature_points |
                  update_JxW_values)
  {
    for (unsigned int i = 0; i < 2; ++i)
      loads[i].reinit(laplace_matrix.m());
  }



  template <int dim>
  void
  CellSystem<dim>::reinit(
    const typename DoFHandler<dim>::active_cell_iterator &cell)
  {
    fe_values.reinit(cell);
    cell->get_dof_indices(dof_indices);
    laplace_matrix = 0;
    lumped_mass    = 0;
    for (const unsigned int q : fe_values.quadrature_point_indices())
      for (const unsigned int v : fe_values.dof_indices())
        {
          for (const unsigned int w : fe_values.dof_indices())
            laplace_matrix(v, w) += fe_values.shape_grad(v, q) *
                                    fe_values.shape_grad(w, q) *
                                    fe_values.JxW(q);
          lumped_mass(v) += fe_values.shape_value(v, q) * fe_values.JxW(q);
        }

    data.load_list(fe_values.get_quadrature_points(), load_values);
    for (unsigned int i = 0; i < 2; ++i)
      {
        const std::vector<double> &f = load_values.f[i];
        loads[i]                     = 0;
        double measure = 0, integral = 0;
        for (const unsigned int q : fe_values.quadrature_point_indices())
          {
            measure += fe_values.JxW(q);
            integral += f[q] * fe_values.JxW(q);
            for (const unsigned int v : fe_values.dof_indices())
              loads[i](v) +=
                f[q] * fe_values.shape_value(v, q) * fe_values.JxW(q);
          }
        load_mean[i]        = integral / measure;
        load_oscillation[i] = 0;
        for (const unsigned int q : fe_values.quadrature_point_indices())
          load_oscillation[i] +=
            std::pow(f[q] - load_mean[i], 2) * fe_values.JxW(q);
      }
  }



  template class CellSystem<2>;
} // namespace membranes
