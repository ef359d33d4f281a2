#include <algorithm>
#include <deal.II/dofs/dof_tools.h>
#include <membranes/dual_mesh/dual_mesh.h>

namespace membranes
{
  template <int dim>
  DualMesh<dim>::DualMesh(const Discretization<dim> &discretization)
    : discretization(discretization)
  {}



  template <int dim>
  void
  DualMesh<dim>::reinit(const DoFHandler<dim> &dof_handler)
  {
    // The interior vertices of the owned and ghost cells, each once (by
    // its index in the mesh), by their DoFs.
    const IndexSet boundary_dofs = DoFTools::extract_boundary_dofs(dof_handler);
    const auto    &triangulation = dof_handler.get_triangulation();
    std::vector<char> seen(triangulation.n_vertices(), false);
    interior_vertex_flags.assign(triangulation.n_vertices(), false);
    interior_dofs.clear();
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (!cell->is_artificial())
        for (const unsigned int v : cell->vertex_indices())
          if (!seen[cell->vertex_index(v)])
            {
              seen[cell->vertex_index(v)] = true;
              if (boundary_dofs.is_element(cell->vertex_dof_index(v, 0)))
                continue;
              interior_vertex_flags[cell->vertex_index(v)] = true;
              interior_dofs.push_back(cell->vertex_dof_index(v, 0));
            }
    std::sort(interior_dofs.begin(), interior_dofs.end());
  }



  template <int dim>
  const std::vector<types::global_dof_index> &
  DualMesh<dim>::interior_vertices() const
  {
    return interior_dofs;
  }



  template <int dim>
  void
  DualMesh<dim>::lambda_h_values(
    const DualCellQuadrature<dim> &dual_cell_quadrature,
    const CellIterator            &cell,
    const VectorType              &lambda_h,
    std::vector<double>           &values,
    std::vector<bool>             *in_omega_h) const
  {
    // λ_h is constant on the pieces of each vertex: look it up once per
    // vertex, not once per point.
    std::array<double, GeometryInfo<dim>::vertices_per_cell> vertex_values;
    std::array<bool, GeometryInfo<dim>::vertices_per_cell>   vertex_in_omega_h;
    for (const unsigned int v : cell->vertex_indices())
      {
        vertex_values[v]     = lambda_h_value(cell, v, lambda_h);
        vertex_in_omega_h[v] = is_interior_vertex(cell, v);
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



  template class DualMesh<2>;
} // namespace membranes
