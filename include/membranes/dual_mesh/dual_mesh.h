#ifndef membranes_dual_mesh_h
#define membranes_dual_mesh_h

#include <array>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/mesh/discretization.h>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The dual mesh D_h of one mesh T_h (§4.2 of the paper), as far as λ_h
   * needs it: which vertices are interior, so that their dual cells D_a
   * make up ω_h, and λ_h read on the pieces K ∩ D_a of every cell.
   *
   * The dual cells themselves are never built: every cell K is cut into
   * its pieces K ∩ D_a by the DualCellQuadrature of the Discretization,
   * which knows for each of its points the vertex a of its piece. What
   * depends on the mesh is only whether a is interior (on ∂ω, D_a lies in
   * the strip ω \ ω_h, where λ_h = 0). This class finds the interior
   * vertices once per mesh, on the locally owned and ghost cells, and
   * holds them; the vector λ_h of the nodal values λ_a is held by the
   * driver (MembraneProblem) and handed to the functions below.
   *
   * The interior vertices are V_h and the hanging vertices: V_h (the
   * unconstrained ones, which carry λ_a) is taken from them by
   * DiscreteProblem. λ_h on the pieces of a hanging vertex is the
   * constraint-weighted mean of the λ_a of its parents, which the vector
   * λ_h holds at that vertex (DiscreteAction::lambda_h()).
   */
  template <int dim>
  class DualMesh
  {
  public:
    using VectorType   = TrilinosWrappers::MPI::Vector;
    using CellIterator = typename DoFHandler<dim>::active_cell_iterator;

    explicit DualMesh(const Discretization<dim> &discretization);

    /** Find the interior vertices of the cells of @p dof_handler. */
    void
    reinit(const DoFHandler<dim> &dof_handler);

    /**
     * The DoFs of the interior vertices of the locally owned and ghost
     * cells, in increasing order.
     */
    const std::vector<types::global_dof_index> &
    interior_vertices() const;

    /**
     * Whether vertex @p v of the locally relevant @p cell is interior, by
     * the vertex's index in the mesh: no search (the loops over the cells).
     */
    bool
    is_interior_vertex(const CellIterator &cell, const unsigned int v) const
    {
      return interior_vertex_flags[cell->vertex_index(v)];
    }

    /**
     * λ_h (@p lambda_h, ghosted, as DiscreteAction::lambda_h() returns it)
     * on the pieces K ∩ D_a of vertex @p v of @p cell: zero if a is on ∂ω.
     */
    double
    lambda_h_value(const CellIterator &cell,
                   const unsigned int  v,
                   const VectorType   &lambda_h) const
    {
      return is_interior_vertex(cell, v) ?
               lambda_h[cell->vertex_dof_index(v, 0)] :
               0.;
    }

    /**
     * λ_h at the points of the DualCellQuadrature on @p cell; with
     * @p in_omega_h, also whether each point lies in ω_h (not in the strip
     * along ∂ω).
     */
    void
    lambda_h_values(const CellIterator  &cell,
                    const VectorType    &lambda_h,
                    std::vector<double> &values,
                    std::vector<bool>   *in_omega_h = nullptr) const
    {
      lambda_h_values(discretization.dual_cell_quadrature,
                      cell,
                      lambda_h,
                      values,
                      in_omega_h);
    }

    /** The same at the points of another rule @p quadrature on the pieces. */
    void
    lambda_h_values(const DualCellQuadrature<dim> &quadrature,
                    const CellIterator            &cell,
                    const VectorType              &lambda_h,
                    std::vector<double>           &values,
                    std::vector<bool>             *in_omega_h = nullptr) const;

  private:
    const Discretization<dim> &discretization;

    std::vector<types::global_dof_index> interior_dofs;
    /** is_interior_vertex() by the index of the vertex in the mesh. */
    std::vector<char> interior_vertex_flags;
  };



  /**
   * What a loop over cells reads on a cell at the points of the dual-cell
   * quadrature: FEValues with @p update_flags, the nodal values of each
   * membrane (read into one buffer each: the functions of FEValues that take
   * the global vector allocate an aligned vector on every call, which on a
   * million cells fragments the heap), and λ_h with the points that lie in
   * ω_h. The error norms and the estimators hold one per thread, for the
   * duration of one loop.
   */
  template <int dim>
  struct DualCellValues
  {
    DualCellValues(const Discretization<dim>           &discretization,
                   const DualMesh<dim>                 &dual_mesh,
                   const TrilinosWrappers::MPI::Vector &lambda_h,
                   const UpdateFlags                    update_flags)
      : DualCellValues(discretization,
                       discretization.dual_cell_quadrature,
                       dual_mesh,
                       lambda_h,
                       update_flags)
    {}

    /** The same at the points of another rule @p quadrature on the pieces. */
    DualCellValues(const Discretization<dim>           &discretization,
                   const DualCellQuadrature<dim>       &quadrature,
                   const DualMesh<dim>                 &dual_mesh,
                   const TrilinosWrappers::MPI::Vector &lambda_h,
                   const UpdateFlags                    update_flags)
      : fe_values(*discretization.mapping,
                  *discretization.fe,
                  quadrature.quadrature(),
                  update_flags)
      , quadrature(quadrature)
      , dual_mesh(dual_mesh)
      , nodal_lambda_h(lambda_h)
    {
      for (auto &values : local_dofs)
        values.resize(discretization.fe->n_dofs_per_cell());
    }

    /**
     * Reinit on @p cell, with the nodal values of the two blocks of
     * @p solution there.
     */
    void
    reinit(const typename DoFHandler<dim>::active_cell_iterator &cell,
           const TrilinosWrappers::MPI::BlockVector             &solution)
    {
      fe_values.reinit(cell);
      for (unsigned int i = 0; i < 2; ++i)
        cell->get_dof_values(solution.block(i),
                             local_dofs[i].begin(),
                             local_dofs[i].end());
      dual_mesh.lambda_h_values(
        quadrature, cell, nodal_lambda_h, lambda_h, &in_omega_h);
    }

    FEValues<dim> fe_values;
    /** The nodal values of u_ih on the cell, i = 0, 1. */
    std::array<std::vector<double>, 2>   local_dofs;
    std::vector<double>                  lambda_h;
    std::vector<bool>                    in_omega_h;
    const DualCellQuadrature<dim>       &quadrature;
    const DualMesh<dim>                 &dual_mesh;
    const TrilinosWrappers::MPI::Vector &nodal_lambda_h;
  };
} // namespace membranes

#endif
