#ifndef membranes_coupled_system_h
#define membranes_coupled_system_h

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/affine_constraints.h>
#include <membranes/active_set_system.h>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The linear problem of one active set iteration on the coupled pair
   * (u1h, u2h), as deal.II's step-41 does it for one field.
   *
   * On active vertices the contact constraint u1(a) = u2(a) is a line of an
   * AffineConstraints object, merged with the hanging-node constraints and
   * the boundary values u1 = g_h, u2 = g2_h (built once per mesh).
   * Condensing the constraint adds the equations of u1 and u2 at a, so the
   * solution of each iteration satisfies Prop. 12 (λ from either membrane)
   * by construction; on inactive vertices both equations hold, i.e.
   * λ_a = 0. The Laplacian is not assembled again: the condensed system of
   * an iteration is made in one pass over the entries of the operator of
   * the mesh (MeshOperator) and of its loads, condensed once per mesh with
   * the hanging node constraints and boundary values; per iteration only
   * the contact lines of the active set are condensed, as AffineConstraints
   * would condense them in an assembly.
   *
   * The rows of the two membranes are forces of tensions μ1 and μ2, and of
   * μ1 + μ2 where the contact constraint adds them: for tension ratios far
   * from 1 they differ by orders of magnitude, and a Euclidean residual
   * bound would leave the rows of the softer membrane unresolved. The
   * system is therefore solved with the symmetric scaling by the tensions
   * described in solve(), which measures its residual as the two problems
   * of DecoupledSystem measure theirs (LinearTolerances).
   */
  template <int dim>
  class CoupledSystem : public ActiveSetSystem<dim>
  {
  public:
    using VectorType = typename ActiveSetSystem<dim>::VectorType;

    CoupledSystem(const Parameters::Solver  &parameters,
                  const Discretization<dim> &discretization,
                  const ProblemData<dim>    &data,
                  TimerOutput               &timer,
                  const MPI_Comm             mpi_communicator);

    /**
     * The hanging node and boundary constraints, sparsity pattern and matrix
     * for the mesh of @p mesh_operator; the pattern has room for any active
     * set.
     */
    void
    setup(const MeshOperator<dim> &mesh_operator) override;

    void
    solve(const IndexSet         &active_set,
          VectorType             &solution,
          const LinearTolerances &tolerances,
          ActiveSetStatistics    &statistics) override;

    /** Also the tensions of the DoFs and the constraints. */
    void
    clear() override;

  private:
    /**
     * The diagonal m_j^{-1/2} of the scaling of the system of @p active_set
     * (locally owned entries; see solve()).
     */
    VectorType
    tension_scaling(const IndexSet &active_set) const;

    /** mesh_rhs, from the loads of the mesh's cells. */
    void
    make_mesh_rhs();

    /**
     * The system matrix and right-hand side of @p active_set, condensed
     * with the constraints of the mesh and the contact lines and scaled
     * symmetrically by @p scaling: in each locally owned unconstrained row
     * i the rows of the mesh's operator of i and, if i is the u2 DoF of an
     * active vertex, of its u1 DoF, the columns of u1 DoFs of active
     * vertices moved to their u2 DoFs, and the same rows of mesh_rhs; a
     * constrained row (boundary, hanging, or u1 of an active vertex) keeps
     * only the diagonal Σ_K μ_i A_K(i, i), and zero on the right.
     */
    void
    make_system(const IndexSet &active_set, const VectorType &scaling);

    /** Hanging node and boundary constraints of the mesh. */
    AffineConstraints<double> mesh_constraints;
    /** The same with the contact lines of the current active set. */
    AffineConstraints<double> constraints;
    /** μ_i at each locally owned DoF of membrane i. */
    VectorType tension;
    /**
     * The loads condensed with mesh_constraints (boundary values lifted),
     * zero in constrained rows: made once per mesh.
     */
    VectorType mesh_rhs;
    /**
     * For each local column of the mesh's operator, the local column of the
     * system matrix (−1 if none).
     */
    std::vector<int> column_of_operator_column;
  };
} // namespace membranes

#endif
