#include <cmath>
#include <deal.II/base/quadrature_lib.h>
#include <membranes/dual_mesh/dual_cell_quadrature.h>

namespace membranes
{
  template <int dim>
  DualCellQuadrature<dim>::DualCellQuadrature(
    const ReferenceCell &reference_cell,
    const unsigned int   degree)
    : DualCellQuadrature(reference_cell, QGaussSimplex<dim>((degree + 2) / 2))
  {}



  template <int dim>
  DualCellQuadrature<dim>::DualCellQuadrature(
    const ReferenceCell   &reference_cell,
    const Quadrature<dim> &simplex_rule)
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
    for (const unsigned int e : reference_cell.face_indices())
      for (unsigned int end = 0; end < 2; ++end)
        {
          const unsigned int a =
            reference_cell.face_to_cell_vertices(e, end, 1);
          const unsigned int other =
            reference_cell.face_to_cell_vertices(e, 1 - end, 1);
          SubTriangle triangle;
          triangle.vertex  = a;
          triangle.face    = e;
          triangle.corners = {
            {vertices[a], (vertices[a] + vertices[other]) / 2, barycentre}};
          const Tensor<1, dim> edge_1 = triangle.corners[1] - vertices[a];
          const Tensor<1, dim> edge_2 = triangle.corners[2] - vertices[a];
          triangle.area =
            std::abs(edge_1[0] * edge_2[1] - edge_1[1] * edge_2[0]) / 2;
          for (unsigned int j = 0; j < 3; ++j)
            {
              const Point<dim> &p      = triangle.corners[(j + 1) % 3];
              const Point<dim> &q      = triangle.corners[(j + 2) % 3];
              Tensor<1, dim>    normal = cross_product_2d(q - p);
              normal /= normal.norm();
              if (normal * (p - triangle.corners[j]) < 0)
                normal *= -1;
              triangle.normals[j] = normal;
            }
          triangles.push_back(triangle);
        }

    std::vector<Point<dim>> points;
    std::vector<double>     weights;
    for (unsigned int s = 0; s < triangles.size(); ++s)
      {
        const auto &corners = triangles[s].corners;
        for (unsigned int q = 0; q < simplex_rule.size(); ++q)
          {
            const Point<dim> &xi = simplex_rule.point(q);
            points.push_back(corners[0] + xi[0] * (corners[1] - corners[0]) +
                             xi[1] * (corners[2] - corners[0]));
            weights.push_back(simplex_rule.weight(q) * 2 * triangles[s].area);
            triangle_of_points.push_back(s);
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
    return triangles[triangle_of_points[q]].vertex;
  }



  template <int dim>
  unsigned int
  DualCellQuadrature<dim>::sub_triangle_of_point(const unsigned int q) const
  {
    return triangle_of_points[q];
  }



  template <int dim>
  const std::vector<typename DualCellQuadrature<dim>::SubTriangle> &
  DualCellQuadrature<dim>::sub_triangles() const
  {
    return triangles;
  }



  template class DualCellQuadrature<2>;
} // namespace membranes
