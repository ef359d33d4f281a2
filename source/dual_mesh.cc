#include <deal.II/base/quadrature_lib.h>
#include <membranes/dual_mesh.h>

namespace membranes
{
  template <int dim>
  DualCellQuadrature<dim>::DualCellQuadrature(
    const ReferenceCell &reference_cell,
    const unsigned int   degree)
  {
    static_assert(dim == 2, "The dual mesh is implemented for dim = 2.");
    const unsigned int n_vertices = reference_cell.n_vertices();

    std::vector<Point<dim>> vertices(n_vertices);
    Point<dim>              barycentre;
    for (unsigned int v = 0; v < n_vertices; ++v)
      {
        vertices[v] = reference_cell.template vertex<dim>(v);
        barycentre += vertices[v] / n_vertices;
      }

    // Every edge (face in 2d) of the reference cell contributes the
    // triangles (a, m_e, b) for both of its end points a.
    const QGaussSimplex<dim> simplex_rule((degree + 2) / 2);
    std::vector<Point<dim>>  points;
    std::vector<double>      weights;
    for (const unsigned int e : reference_cell.face_indices())
      for (unsigned int end = 0; end < 2; ++end)
        {
          const unsigned int a =
            reference_cell.face_to_cell_vertices(e, end, 1);
          const unsigned int other =
            reference_cell.face_to_cell_vertices(e, 1 - end, 1);
          const Point<dim>     midpoint = (vertices[a] + vertices[other]) / 2;
          const Tensor<1, dim> edge_1   = midpoint - vertices[a];
          const Tensor<1, dim> edge_2   = barycentre - vertices[a];
          const double         jacobian =
            std::abs(edge_1[0] * edge_2[1] - edge_1[1] * edge_2[0]);
          for (unsigned int q = 0; q < simplex_rule.size(); ++q)
            {
              const Point<dim> &xi = simplex_rule.point(q);
              points.push_back(vertices[a] + xi[0] * edge_1 + xi[1] * edge_2);
              weights.push_back(simplex_rule.weight(q) * jacobian);
              vertex_of_points.push_back(a);
            }
        }
    rule = Quadrature<dim>(points, weights);
  }



  template <int dim>
  const Quadrature<dim> &
  DualCellQuadrature<dim>::quadrature() const
  {
    return rule;
  }



  template <int dim>
  unsigned int
  DualCellQuadrature<dim>::vertex_of_point(const unsigned int q) const
  {
    return vertex_of_points[q];
  }



  template class DualCellQuadrature<2>;
} // namespace membranes
