#ifndef membranes_decoupled_system_h
#define membranes_decoupled_system_h

#include <array>
#include <deal.II/base/function.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/affine_constraints.h>
#include <membranes/active_set_system.h>
#include <membranes/matrix_rows.h>
#include <memory>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The linear problem of one active set iteration, solved on the sum and
   * the difference of the membranes (`Solver/Method = decoupled`).
   *
   * <h3>The decoupling of the discrete problem</h3>
   * Let A be the stiffness matrix of the Laplacian on the scalar P1/Q1
   * space (condensed with the hanging node constraints), F_i the load
   * vectors (∫ f_i φ), d_a = ∫ φ_a and Λ_a = λ_a of (4.5). The discrete
   * problem (3.4) with its multiplier (4.7) reads, at every a ∈ V_h,
   *
   *   μ1 (A U1)_a − F1_a = Λ_a d_a,    μ2 (A U2)_a − F2_a = −Λ_a d_a,
   *   W_a = U1_a − U2_a ≥ 0,   Λ_a ≥ 0,   W_a Λ_a = 0,
   *
   * with U1 = g_h, U2 = g2_h on ∂ω. For constant μ1, μ2 (M = μ1 + μ2,
   * μ̄ = μ1μ2/M) the sum of the two equations and μ̄ times the difference of
   * the equations divided by μ_i are
   *
   *   A S = F1 + F2,                          S = μ1 U1 + μ2 U2,
   *   μ̄ A W − (μ2 F1 − μ1 F2)/M = Λ d,        W = U1 − U2,
   *
   * S = μ1 g_h + μ2 g2_h and W = g_h − g2_h on ∂ω. The first is one linear
   * problem (−Δs = f1 + f2), the second the scalar obstacle problem
   * (−μ̄Δw − λ = (μ2 f1 − μ1 f2)/M, w ≥ 0, λ ≥ 0, wλ = 0, step-41 with
   * obstacle 0) with the same Λ and the same d_a. Conversely
   *
   *   U1 = (S + μ2 W)/M,   U2 = (S − μ1 W)/M
   *
   * turn any solution (S, W, Λ) back into one of the coupled system: the
   * decoupling is exact for the discrete problem, not only for (1.1). The
   * hanging node constraints are linear and homogeneous, so S and W obey
   * them as U1 and U2 do; the contact constraint lives, as in the coupled
   * problem, on the unconstrained interior vertices.
   *
   * <h3>What one iteration does</h3>
   * The Laplacian is not assembled again: A is the block μ1 A of the
   * operator of the mesh (MeshOperator) divided by μ1. The first solve() of
   * a mesh condenses the cell loads of the mesh into the right-hand sides
   * of S and W (the boundary values lifted by A_K and μ̄ A_K on the cells
   * at ∂ω; the hanging node constraints and the boundary values are the
   * same lines for S and for W) and solves the linear problem for S from
   * the initial guess. Every
   * solve() then imposes W_a = 0 on the active set: it writes μ̄ A into the
   * matrix of W with the rows and columns of the active vertices
   * eliminated (what condensing an AffineConstraints line without entries
   * does), the right-hand side zeroed there, in one pass over the entries
   * of the mesh's operator; it solves the obstacle problem's linear system
   * for W (inactive vertices: Λ_a = 0), and writes U1, U2 into the
   * solution of the two-component FESystem. ActiveSetSolver computes λ_a by
   * (4.5), and ActiveSet the next active set and the KKT residual, from it
   * exactly as for the coupled system: the test Λ_a − c_a W_a > 0 with
   * c_a = μ̄ ∫|∇φ_a|²/d_a is the active set test of this obstacle problem,
   * whose diagonal is μ̄ A_aa.
   *
   * Both scalar problems live on one scalar DoFHandler (the base element of
   * the FESystem, on the same mesh and mapping), whose DoFs map one to one
   * to the vertices. Each is half the size of the coupled system, and S is
   * solved only once.
   */
  template <int dim>
  class DecoupledSystem : public ActiveSetSystem<dim>
  {
  public:
    using VectorType = typename ActiveSetSystem<dim>::VectorType;

    DecoupledSystem(const Parameters::Solver  &parameters,
                    const Discretization<dim> &discretization,
                    const ProblemData<dim>    &data,
                    TimerOutput               &timer,
                    const MPI_Comm             mpi_communicator);

    /**
     * The scalar DoFHandler on the mesh of @p mesh_operator, the constraints
     * of S and of W, and one sparsity pattern for S and for W with any
     * active set.
     */
    void
    setup(const MeshOperator<dim> &mesh_operator) override;

    /**
     * W for @p active_set, and (U1, U2) from S and W into @p solution. The
     * first solve on a mesh first makes the right-hand sides and solves for
     * S (solve_sum()).
     */
    void
    solve(const IndexSet         &active_set,
          VectorType             &solution,
          const LinearTolerances &tolerances,
          ActiveSetStatistics    &statistics) override;

    /**
     * Also the scalar DoFHandler, its constraints, the matrices of W, S, W
     * and the right-hand side of W.
     */
    void
    clear() override;

  private:
    /**
     * The DoF of u_i (i = 0, 1) at the vertex of scalar DoF @p k; the
     * scalar DoF of a DoF j of (u1, u2) is j / 2.
     */
    static types::global_dof_index
    membrane_dof(const types::global_dof_index k, const unsigned int i);

    /**
     * The right-hand sides of S (into system_rhs) and of W (without the
     * contact constraints), condensed with the hanging node constraints and
     * the boundary values of each, from the loads and the operator of the
     * mesh.
     */
    void
    make_right_hand_sides();

    /**
     * @p matrix = @p coefficient · A, condensed with the hanging node
     * constraints and the boundary values, and with the rows and columns of
     * @p active_scalar_dofs (locally relevant) eliminated: their
     * off-diagonal entries zero. @p matrix has the sparsity pattern that
     * setup() made.
     */
    void
    make_operator(const double                    coefficient,
                  const IndexSet                 &active_scalar_dofs,
                  TrilinosWrappers::SparseMatrix &matrix) const;

    /**
     * S and W of the initial guess @p solution, the right-hand sides
     * (make_right_hand_sides()), then S of this mesh, from A S = F1 + F2.
     */
    void
    solve_sum(const VectorType       &solution,
              const LinearTolerances &tolerances,
              ActiveSetStatistics    &statistics);

    /** μ1 g + μ2 g2 and g − g2: the boundary values of S and of W. */
    const std::unique_ptr<Function<dim>> sum_boundary_values;
    const std::unique_ptr<Function<dim>> difference_boundary_values;

    DoFHandler<dim> scalar_dof_handler;
    IndexSet        locally_owned_scalar_dofs;
    IndexSet        locally_relevant_scalar_dofs;

    /** Hanging node constraints and the boundary values of S, of W. */
    AffineConstraints<double> sum_constraints;
    AffineConstraints<double> difference_constraints;
    /** The scalar DoFs these constrain (the same for S and W). */
    IndexSet constrained_scalar_dofs;

    /**
     * The local column of the matrices of S and W of each local column of
     * the mesh's operator (−1 where they have none).
     */
    std::vector<int> column_of_operator_column;

    /**
     * The load of W ((μ2 F1 − μ1 F2)/M, its boundary values lifted by μ̄ A),
     * condensed with the constraints of the mesh: made once per mesh.
     */
    VectorType difference_rhs;

    /**
     * The matrix of S, then that of W at the iteration whose AMG hierarchy
     * the following iterations of this mesh reuse (LinearSolver); those
     * write theirs into system_matrix.
     */
    TrilinosWrappers::SparseMatrix preconditioner_matrix;

    /** S = μ1 U1 + μ2 U2 and W = U1 − U2 (locally owned). */
    VectorType sum;
    VectorType difference;
    /** Whether S has been solved for on this mesh. */
    bool sum_solved;
  };
} // namespace membranes

#endif
