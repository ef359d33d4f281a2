#ifndef membranes_dual_mesh_h
#define membranes_dual_mesh_h

#include <deal.II/base/quadrature.h>
#include <deal.II/grid/reference_cell.h>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * A quadrature on one cell K that integrates separately over the pieces
   * K ∩ D_a of the dual mesh (paper §4.2).
   *
   * For a vertex a of K, K ∩ D_a is the quadrilateral with corners a, the
   * midpoints m_e of the two edges of K through a, and the barycentre b_K
   * of K (the vertex average on quadrilaterals). It is the union of the two
   * triangles (a, m_e, b_K), the cells of the paper's sub-mesh S_h. This
   * class builds the rule on the reference cell: a QGaussSimplex rule
   * mapped onto each of these reference triangles, and records for every
   * point the vertex a whose piece it lies in. FEValues then maps it to the
   * physical cell: for triangles the pieces map to the physical pieces
   * exactly (affine map); for quadrilaterals the bilinear map sends the
   * lines from edge midpoints to the centre onto straight segments, so the
   * union of the two mapped triangles is again exactly K ∩ D_a.
   *
   * With it, a function that is constant on dual cells (λ_h) is integrated
   * against smooth ones without ever building the dual mesh explicitly:
   * the rule is exact on each piece for polynomials of the given degree in
   * reference coordinates.
   */
  template <int dim>
  class DualCellQuadrature
  {
  public:
    /**
     * The rule on @p reference_cell (triangle or quadrilateral), exact of
     * degree @p degree on every reference sub-triangle.
     */
    DualCellQuadrature(const ReferenceCell &reference_cell,
                       const unsigned int   degree);

    /** The points and weights on the reference cell. */
    const Quadrature<dim> &
    quadrature() const;

    /** The vertex a of the cell whose piece K ∩ D_a holds point @p q. */
    unsigned int
    vertex_of_point(const unsigned int q) const;

  private:
    Quadrature<dim>           rule;
    std::vector<unsigned int> vertex_of_points;
  };
} // namespace membranes

#endif
