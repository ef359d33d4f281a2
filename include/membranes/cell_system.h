#ifndef membranes_cell_system_h
#define membranes_cell_system_h

#include <array>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/vector.h>
#include <membranes/discretization.h>
#include <membranes/problem_data.h>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The contributions of one cell K to the reduced problem (3.4), for the
   * shape functions φ_i of the FESystem (component c(i) = 0 for u1, 1 for
   * u2):
   *
   *   A_K(i, j) = μ_c ∫_K ∇φ_i·∇φ_j  if c(i) = c(j), 0 otherwise,
   *   F_K(i)    = ∫_K f_c φ_i,
   *   M_K(i)    = ∫_K φ_i  (the lumped mass, whose sums are d_a = ∫ φ_a).
   *
   * The active set solver assembles the system from them, and the discrete
   * action evaluates the residual of (4.5) as A_K U_K − F_K with them, so
   * both see the same bilinear form and the same quadrature of the loads.
   */
  template <int dim>
  class CellSystem
  {
  public:
    CellSystem(const Discretization<dim> &discretization,
               const ProblemData<dim>    &data);

    /** Compute matrix, rhs, lumped_mass and dof_indices on @p cell. */
    void
    reinit(const typename DoFHandler<dim>::active_cell_iterator &cell);

    FullMatrix<double>                   matrix;
    Vector<double>                       rhs;
    Vector<double>                       lumped_mass;
    std::vector<types::global_dof_index> dof_indices;

    /** The membrane (0 or 1) of local shape function @p i. */
    unsigned int
    membrane_of(const unsigned int i) const;

  private:
    const ProblemData<dim>            &data;
    FEValues<dim>                      fe_values;
    std::vector<unsigned int>          membrane;
    std::array<std::vector<double>, 2> loads;
  };
} // namespace membranes

#endif
