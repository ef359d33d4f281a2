#include <deal.II/base/quadrature_lib.h>
#include <membranes/flux/flux_sub_triangles.h>

namespace membranes
{
  namespace
  {
    /**
     * The curl of the edge bubble 4 λ_p λ_q of edge @p l of the reference
     * sub-triangle with @p corners (p, q the ends of the edge, λ the
     * barycentric coordinates) at the reference point @p x.
     */
    template <int dim>
    Tensor<1, dim>
    reference_rotation(const std::array<Point<dim>, 3> &corners,
                       const unsigned int               l,
                       const Point<dim>                &x)
    {
      // λ_j is the linear function that is 1 at the corner c_j and 0 on the
      // line through the other two, r·(x − c_{j+1}) / r·(c_j − c_{j+1}) with
      // r normal to c_{j+2} − c_{j+1}; 4 λ_p λ_q has the gradient
      // 4 (λ_p ∇λ_q + λ_q ∇λ_p), and the curl is (∂_y, −∂_x).
      const auto barycentric = [&](const unsigned int j) {
        const Tensor<1, dim> d = corners[(j + 2) % 3] - corners[(j + 1) % 3];
        const double         scale =
          cross_product_2d(d) * (corners[j] - corners[(j + 1) % 3]);
        return std::make_pair(cross_product_2d(d) * (x - corners[(j + 1) % 3]) /
                                scale,
                              Tensor<1, dim>(cross_product_2d(d) / scale));
      };
      const auto [lambda_p, grad_p] = barycentric((l + 1) % 3);
      const auto [lambda_q, grad_q] = barycentric((l + 2) % 3);
      return cross_product_2d(4 * (lambda_p * grad_q + lambda_q * grad_p));
    }
  } // namespace



  template <int dim>
  SubTrianglePoints<dim>::SubTrianglePoints(const DualCellQuadrature<dim> &dual,
                                            const bool with_corners)
    : n_volume(dual.quadrature().size())
    , n_triangles(dual.sub_triangles().size())
  {
    std::vector<Point<dim>> points  = dual.quadrature().get_points();
    std::vector<double>     weights = dual.quadrature().get_weights();
    const QGauss<1>         gauss(n_edge_points);
    for (const auto &triangle : dual.sub_triangles())
      for (unsigned int j = 0; j < 3; ++j)
        {
          const Point<dim> &p = triangle.corners[(j + 1) % 3];
          const Point<dim> &q = triangle.corners[(j + 2) % 3];
          for (unsigned int k = 0; k < n_edge_points; ++k)
            {
              points.push_back(p + gauss.point(k)[0] * (q - p));
              weights.push_back(gauss.weight(k) * (q - p).norm());
            }
        }
    for (const auto &triangle : dual.sub_triangles())
      for (unsigned int j = 0; j < (with_corners ? 3 : 0); ++j)
        {
          points.push_back(triangle.corners[j]);
          weights.push_back(0);
        }
    quadrature = Quadrature<dim>(points, weights);
  }



  template <int dim>
  SubTriangleBasis<dim>::SubTriangleBasis(const DualCellQuadrature<dim> &dual,
                                          const FiniteElement<dim>      &fe)
    : dual(dual)
    , reconstruction_points(dual, false)
  {
    // The hat functions of the cell's vertices at the Gauss points of the
    // edges of the sub-triangles (reference values): that of vertex v is
    // shape function v of the P1/Q1 element.
    const SubTrianglePoints<dim> &points = reconstruction_points;
    for (unsigned int s = 0; s < n_sub_triangles(); ++s)
      for (unsigned int e = 0; e < 3; ++e)
        for (unsigned int k = 0; k < points.n_edge_points; ++k)
          for (unsigned int v = 0; v < GeometryInfo<dim>::vertices_per_cell;
               ++v)
            edge_shape_values.push_back(
              v < fe.reference_cell().n_vertices() ?
                fe.shape_value(
                  v, points.quadrature.point(points.edge_point(s, e, k))) :
                0.);

    // The Raviart–Thomas basis and the rotations of each sub-triangle at its
    // points of the dual quadrature.
    for (unsigned int q = 0; q < points.n_volume; ++q)
      {
        const unsigned int            s        = dual.sub_triangle_of_point(q);
        const Point<dim>             &x        = points.quadrature.point(q);
        const auto                   &triangle = dual.sub_triangles()[s];
        std::array<Tensor<1, dim>, 3> psi;
        for (unsigned int k = 0; k < 3; ++k)
          psi[k] = (x - triangle.corners[k]) / (2 * triangle.area);
        flux_basis_at_points.push_back(psi);
        rotation_basis_at_points.push_back(
          {{reference_rotation(triangle.corners, 0, x),
            reference_rotation(triangle.corners, 1, x)}});
      }

    // Around b_K, sub-triangle (a, m_e, b_K) meets (a', m_e, b_K), a' the
    // other end of e, across edge 0, and (a, m_e', b_K), e' the other edge
    // through a, across edge 1.
    const auto &triangles = dual.sub_triangles();
    ring_order.push_back(0);
    while (ring_order.size() < triangles.size())
      {
        const auto &last = triangles[ring_order.back()];
        for (unsigned int t = 0; t < triangles.size(); ++t)
          if (ring_order.size() % 2 == 1 ?
                (triangles[t].face == last.face &&
                 triangles[t].vertex != last.vertex) :
                (triangles[t].vertex == last.vertex &&
                 triangles[t].face != last.face))
            {
              ring_order.push_back(t);
              break;
            }
      }
  }



  template <int dim>
  Tensor<1, dim>
  SubTriangleBasis<dim>::reference_flux(const unsigned int           s,
                                        const std::array<double, 3> &fluxes,
                                        const Point<dim>            &x) const
  {
    const auto    &triangle = dual.sub_triangles()[s];
    Tensor<1, dim> t;
    for (unsigned int j = 0; j < 3; ++j)
      t += fluxes[j] * (x - triangle.corners[j]) / (2 * triangle.area);
    return t;
  }



  template struct SubTrianglePoints<2>;
  template class SubTriangleBasis<2>;
} // namespace membranes
