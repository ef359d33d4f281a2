#ifndef membranes_dual_cell_quadrature_h
#define membranes_dual_cell_quadrature_h

#include <array>
#include <deal.II/base/point.h>
#include <deal.II/base/quadrature.h>
#include <deal.II/base/tensor.h>
#include <deal.II/grid/reference_cell.h>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The dual mesh of §4.2 of the paper on one reference cell, and a
   * quadrature on its pieces.
   *
   * For a vertex a of K, K ∩ D_a is the quadrilateral with corners a, the
   * midpoints m_e of the two edges of K through a, and the barycentre b_K
   * of K (the vertex average on quadrilaterals). It is the union of the two
   * triangles κ = (a, m_e, b_K), the cells of the paper's sub-mesh S_h: one
   * for every edge e of K and every end a of e. This class holds these
   * reference sub-triangles and a rule on the reference triangle (a
   * QGaussSimplex rule, or any other) mapped onto each of them, with the
   * sub-triangle (and so the vertex a) of every point.
   * FEValues maps the rule to the physical cell: for triangles the pieces
   * map to the physical pieces exactly (affine map); for quadrilaterals the
   * bilinear map sends the edges a–m_e and m_e–b_K to straight segments, so
   * the union of the two mapped sub-triangles is again exactly K ∩ D_a (the
   * edge a–b_K between them is mapped to a curve).
   *
   * With it, a function that is constant on dual cells (λ_h) is integrated
   * against smooth ones without building the dual mesh explicitly: the rule
   * is exact on each sub-triangle for polynomials of the given degree in
   * reference coordinates.
   */
  template <int dim>
  class DualCellQuadrature
  {
  public:
    /**
     * A reference sub-triangle κ = (a, m_e, b_K). Its corners are listed in
     * this order; edge j is the one opposite corner j, so that edge 0
     * (m_e–b_K) lies on ∂D_a, edge 1 (a–b_K) inside D_a, both inside K,
     * and edge 2 (a–m_e) is half of the edge e of K.
     */
    struct SubTriangle
    {
      unsigned int                  vertex; ///< a, a vertex index of the cell
      unsigned int                  face;   ///< e, a face index of the cell
      std::array<Point<dim>, 3>     corners;
      double                        area;    ///< Area in reference coordinates.
      std::array<Tensor<1, dim>, 3> normals; ///< Unit outward, per edge.
    };

    /**
     * The rule on @p reference_cell (triangle or quadrilateral), exact of
     * degree @p degree on every reference sub-triangle.
     */
    DualCellQuadrature(const ReferenceCell &reference_cell,
                       const unsigned int   degree);

    /**
     * The rule on @p reference_cell with @p simplex_rule, a rule on the
     * reference triangle, mapped onto every reference sub-triangle.
     */
    DualCellQuadrature(const ReferenceCell   &reference_cell,
                       const Quadrature<dim> &simplex_rule);

    /** The points and weights on the reference cell. */
    const Quadrature<dim> &
    quadrature() const;

    /** The vertex a of the cell whose piece K ∩ D_a holds point @p q. */
    unsigned int
    vertex_of_point(const unsigned int q) const;

    /** The sub-triangle that holds point @p q. */
    unsigned int
    sub_triangle_of_point(const unsigned int q) const;

    /** The sub-triangles of the cell: two per vertex. */
    const std::vector<SubTriangle> &
    sub_triangles() const;

  private:
    std::vector<SubTriangle>  triangles;
    Quadrature<dim>           rule;
    std::vector<unsigned int> triangle_of_points;
  };
} // namespace membranes

#endif
