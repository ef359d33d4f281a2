#ifndef membranes_flux_sub_triangles_h
#define membranes_flux_sub_triangles_h

#include <array>
#include <deal.II/base/quadrature.h>
#include <deal.II/base/tensor.h>
#include <deal.II/fe/fe.h>
#include <membranes/dual_mesh/dual_cell_quadrature.h>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The points at which one cell's flux reconstruction needs u_ih and the
   * mapping, in reference coordinates: first the points of the dual
   * quadrature (for the inner products of the minimization), then two Gauss
   * points on every edge of every sub-triangle (for the fluxes (4.13)),
   * then, @p with_corners, the corners of every sub-triangle (for the
   * output).
   */
  template <int dim>
  struct SubTrianglePoints
  {
    static constexpr unsigned int n_edge_points = 2;

    SubTrianglePoints(const DualCellQuadrature<dim> &dual,
                      const bool                     with_corners);

    /** Gauss point @p k of edge @p j of sub-triangle @p s. */
    unsigned int
    edge_point(const unsigned int s,
               const unsigned int j,
               const unsigned int k) const
    {
      return n_volume + (3 * s + j) * n_edge_points + k;
    }

    /** Corner @p j of sub-triangle @p s. */
    unsigned int
    corner_point(const unsigned int s, const unsigned int j) const
    {
      return n_volume + 3 * n_edge_points * n_triangles + 3 * s + j;
    }

    const unsigned int n_volume;
    const unsigned int n_triangles;
    Quadrature<dim>    quadrature;
  };



  /**
   * The sub-triangles κ = (a, m_e, b_K) of the reference cell, on which the
   * dual mesh D_h of §4.2 of the paper and the sub-mesh S_h are built, and
   * the basis of the lowest order Raviart–Thomas space Z_h of (4.12) on
   * them, in which the fluxes t_ih of (4.13) and σ_ih are written.
   *
   * On a reference sub-triangle with corners p_0, p_1, p_2 the basis
   * function of unit outward flux through the edge opposite p_j is
   * ψ̂_j = (x − p_j) / (2 |κ̂|); on the cell it is mapped by the
   * contravariant Piola transform ψ = DF ψ̂ / |det DF| of the cell's map,
   * which keeps normal fluxes through mapped edges. The curls β_l of the
   * quadratic edge bubbles 4 λ_p λ_q of the edges l = 0, 1 of κ (those
   * through b_K) are fields without divergence and without normal flux
   * through ∂K, mapped the same way (see
   * FluxEquilibration::relax_cell_rotations()).
   *
   * The sub-triangles of a cell form a ring around b_K: ring()[j] and
   * ring()[j+1] share edge 0 (m_e–b_K) of ring()[j] for even j, edge 1
   * (a–b_K) for odd j; the last closes the ring.
   */
  template <int dim>
  class SubTriangleBasis
  {
  public:
    /**
     * The basis on the sub-triangles of @p dual for the scalar P1/Q1
     * element @p fe (Discretization::fe), whose shape function v is the hat
     * function of vertex v.
     */
    SubTriangleBasis(const DualCellQuadrature<dim> &dual,
                     const FiniteElement<dim>      &fe);

    /** The quadrature on the pieces of the dual cells it was built on. */
    const DualCellQuadrature<dim> &
    dual_quadrature() const
    {
      return dual;
    }

    /** The sub-triangles of the reference cell. */
    const std::vector<typename DualCellQuadrature<dim>::SubTriangle> &
    sub_triangles() const
    {
      return dual.sub_triangles();
    }

    /** The number of sub-triangles of a cell. */
    unsigned int
    n_sub_triangles() const
    {
      return dual.sub_triangles().size();
    }

    /** The sub-triangles in the order of the ring around b_K. */
    const std::vector<unsigned int> &
    ring() const
    {
      return ring_order;
    }

    /**
     * The reference field t̂ = Σ_j fluxes[j] ψ̂_j of sub-triangle @p s at
     * the reference point @p x.
     */
    Tensor<1, dim>
    reference_flux(const unsigned int           s,
                   const std::array<double, 3> &fluxes,
                   const Point<dim>            &x) const;

    /** The points of the dual quadrature and on the edges. */
    const SubTrianglePoints<dim> &
    points() const
    {
      return reconstruction_points;
    }

    /** ψ̂_0, ψ̂_1, ψ̂_2 at point @p q of the dual quadrature. */
    const std::array<Tensor<1, dim>, 3> &
    flux_basis(const unsigned int q) const
    {
      return flux_basis_at_points[q];
    }

    /** β̂_0, β̂_1 at point @p q of the dual quadrature. */
    const std::array<Tensor<1, dim>, 2> &
    rotation_basis(const unsigned int q) const
    {
      return rotation_basis_at_points[q];
    }

    /**
     * The hat function of vertex @p v of the cell at Gauss point @p k of
     * edge @p e of sub-triangle @p s (zero for v beyond the vertices of a
     * triangle).
     */
    double
    edge_shape_value(const unsigned int s,
                     const unsigned int e,
                     const unsigned int k,
                     const unsigned int v) const
    {
      return edge_shape_values
        [((s * 3 + e) * SubTrianglePoints<dim>::n_edge_points + k) *
           GeometryInfo<dim>::vertices_per_cell +
         v];
    }

  private:
    const DualCellQuadrature<dim> &dual;
    const SubTrianglePoints<dim>   reconstruction_points;

    std::vector<unsigned int>                  ring_order;
    std::vector<std::array<Tensor<1, dim>, 3>> flux_basis_at_points;
    std::vector<std::array<Tensor<1, dim>, 2>> rotation_basis_at_points;
    std::vector<double>                        edge_shape_values;
  };
} // namespace membranes

#endif
