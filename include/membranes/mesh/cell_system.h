#ifndef membranes_cell_system_h
#define membranes_cell_system_h

#include <array>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/vector.h>
#include <membranes/mesh/discretization.h>
#include <membranes/scene/problem_data.h>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The contributions of one cell K to the reduced problem (3.4), for the
   * hat functions φ_v of the scalar element (P1 or Q1; v numbers the
   * vertices of K):
   *
   *   A_K(v, w)  = ∫_K ∇φ_v·∇φ_w   (the Laplacian),
   *   F_iK(v)    = ∫_K f_i φ_v      (the load of membrane i),
   *   m_K(v)     = ∫_K φ_v          (the lumped mass, whose sums are d_a).
   *
   * The membranes do not couple in (3.4): the cell matrix of membrane i is
   * μ_i A_K. DiscreteProblem assembles the Laplacian and the loads of the
   * mesh from these, once per mesh, and every system of the active set
   * method builds on that Laplacian and those loads: all see the same
   * bilinear form and the same quadrature of the loads.
   */
  template <int dim>
  class CellSystem
  {
  public:
    CellSystem(const Discretization<dim> &discretization,
               const ProblemData<dim>    &data);

    /** Compute every matrix and vector below on @p cell. */
    void
    reinit(const typename DoFHandler<dim>::active_cell_iterator &cell);

    /** A_K. */
    FullMatrix<double> laplace_matrix;
    /** F_1K and F_2K. */
    std::array<Vector<double>, 2> loads;
    /**
     * The mean f̄_iK = ∫_K f_i / |K| and the oscillation ∫_K (f_i − f̄_iK)²
     * of each load, with the quadrature of F_iK (set by reinit()): the data
     * terms of the residual estimator, from the same evaluations.
     */
    std::array<double, 2> load_mean, load_oscillation;

    /** m_K. */
    Vector<double> lumped_mass;
    /** The DoFs of the vertices of K. */
    std::vector<types::global_dof_index> dof_indices;

  private:
    const ProblemData<dim>               &data;
    FEValues<dim>                         fe_values;
    typename ProblemData<dim>::LoadValues load_values;
  };
} // namespace membranes

#endif
