#ifndef membranes_decoupled_system_h
#define membranes_decoupled_system_h

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/diagonal_matrix.h>
#include <membranes/active_set/active_set_system.h>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The linear problem of one active set iteration, solved on the s and
   * the w of the membranes (`Solver/Method = decoupled`).
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
   * μ̄ = μ1μ2/M) the s of the two equations and μ̄ times the w of
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
   * Both scalar problems have the matrix A of the mesh (DiscreteProblem:
   * condensed with the hanging node constraints and the boundary values,
   * which are the same lines for S and for W), and their right-hand sides
   * are combinations of the lifted loads of the mesh, F_1 + F_2 for S and
   * (μ2 F_1 − μ1 F_2)/M for W. The first solve() of a mesh solves
   * A S = F_1 + F_2 from the initial guess. Every set_active_set() imposes
   * W_a = 0 on the active set, and every solve() solves the obstacle
   * problem's linear system for W (inactive vertices: Λ_a = 0) from the
   * W of the iterate and writes U1, U2 into the two blocks of the
   * solution. Both solves start with the constrained entries zero, as the
   * solution of the condensed system has them (step-55 does the same), and
   * the constraints of each membrane give U1 and U2 their values there.
   * ActiveSetSolver computes λ_a by (4.5), ActiveSet the next active set
   * and KKTDefects the KKT residual, from it exactly as for the coupled
   * system:
   * the test Λ_a − c_a W_a > 0 with c_a = μ̄ ∫|∇φ_a|²/d_a is the active set
   * test of this obstacle problem, whose diagonal is μ̄ A_aa.
   *
   * <h3>The active set: an operator, and a matrix for the preconditioner</h3>
   * The matrix of W of an iteration is μ̄ A with the rows and columns of the
   * active vertices eliminated (the constraints W_a = 0 condensed). CG does
   * not need it as a matrix: it applies it as the operator
   * Π (μ̄ A) Π + (I − Π), Π the projection that sets the entries of the
   * active vertices to zero, a deal.II LinearOperator composed of the
   * matrix A of the mesh and the diagonal matrices Π and I − Π. The AMG
   * hierarchy does need a matrix, and the right one: the hierarchy of A
   * itself, seen through Π, preconditions the operator poorly, because the
   * restriction of A⁻¹ to the inactive vertices is not the inverse of the
   * restriction of A. So
   * the first iteration of a mesh (and one whose CG iterations exceed twice
   * those of the one that built the hierarchy, plus rebuild_slack)
   * makes the matrix of W, the condensation of step-41 done on the
   * condensed matrix A of the mesh (make_obstacle_matrix()), and builds the
   * hierarchy P from it, μ̄ included; CG is
   * preconditioned by Π P Π + (I − Π), and the following iterations, whose
   * active sets differ from it near the free boundary only, reuse P. The
   * direct solver factorizes the matrix of W of every iteration. One matrix
   * per problem and mesh: A (for S, λ_h and the operator of W) and the
   * matrix of W; with cg-amg, the hierarchies of both: that of A for S,
   * freed after the solve of S, and that of the matrix of W.
   *
   * Both scalar problems live on the DoFHandler of the mesh, whose DoFs map
   * one to one to the vertices: S, W and the blocks U1, U2 of the solution
   * are vectors of the same layout, and each is a linear combination of the
   * others. Each problem is half the size of the coupled system, and S is
   * solved only once.
   */
  template <int dim>
  class DecoupledSystem : public ActiveSetSystem<dim>
  {
  public:
    using VectorType      = typename ActiveSetSystem<dim>::VectorType;
    using BlockVectorType = typename ActiveSetSystem<dim>::BlockVectorType;

    DecoupledSystem(const Parameters::Solver &parameters,
                    const ProblemData<dim>   &data,
                    const MPI_Comm            mpi_communicator);

    /** The vectors S and W on the mesh of @p problem. */
    void
    setup(const DiscreteProblem<dim> &problem,
          const DoFHandler<dim>      &dof_handler) override;

    /**
     * The projection Π of @p active_set and, when the solve needs it, the
     * matrix of W.
     */
    void
    set_active_set(const DiscreteProblem<dim> &problem,
                   const IndexSet             &active_set) override;

    /**
     * W, and (U1, U2) from S and W into @p solution. The first solve on a
     * mesh first solves for S (solve_s()).
     */
    void
    solve(const DiscreteProblem<dim> &problem,
          BlockVectorType            &solution,
          const LinearTolerances     &tolerances,
          ActiveSetStatistics        &statistics) override;

    /** The constraints, vectors and the AMG hierarchy of this mesh. */
    void
    clear() override;

  private:
    /** CG iterations a reused hierarchy may need beyond twice its first. */
    static constexpr unsigned int rebuild_slack = 5;

    /**
     * obstacle_matrix = μ̄ A with the constraints W_a = 0 of @p active_set
     * (DoFs of the locally relevant active vertices) condensed as
     * AffineConstraints condenses them in a cell loop: their rows and
     * columns eliminated, μ̄ ∫|∇φ_a|² on the diagonal.
     */
    void
    make_obstacle_matrix(const DiscreteProblem<dim> &problem,
                         const IndexSet             &active_set);

    /**
     * S of this mesh, from A S = F_1 + F_2 and the initial guess
     * @p solution, to the residual @p tolerance.
     */
    void
    solve_s(const DiscreteProblem<dim> &problem,
            const BlockVectorType      &solution,
            const double                tolerance,
            ActiveSetStatistics        &statistics);

    /**
     * S = μ1 U1 + μ2 U2 of this mesh (locally owned), solved for once, and
     * the W = U1 − U2 of the iteration's solve, from which solve() writes
     * the blocks of the solution (their values at the constrained DoFs are
     * zero: the solution has its own constraints).
     */
    VectorType s;
    VectorType w;
    /**
     * Π and I − Π of the active set of the last set_active_set() (1 at the
     * inactive, resp. active, vertices).
     */
    DiagonalMatrix<VectorType> inactive_projection, active_projection;
    /** Whether S has been solved for on this mesh. */
    bool s_solved;

    /**
     * The matrix of W, μ̄ A with the rows and columns of the active vertices
     * eliminated, for the active set of the iteration that built the AMG
     * hierarchy that the later iterations of the mesh reuse (the hierarchy
     * refers to it), or of the current iteration for the direct solver.
     */
    TrilinosWrappers::SparseMatrix obstacle_matrix;
    /** CG iterations of the solve that built the hierarchy. */
    unsigned int hierarchy_iterations;
  };
} // namespace membranes

#endif
