#ifndef membranes_linear_solver_h
#define membranes_linear_solver_h

#include <algorithm>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/scene/parameters.h>
#include <memory>
#include <string>

namespace membranes
{
  using namespace dealii;

  /**
   * The linear solves inside the active set method: the condensed,
   * symmetric positive definite systems of one iteration.
   *
   * - `direct`: a sparse LU factorization of the matrix: UMFPACK
   *   (SparseDirectUMFPACK) on one process, MUMPS through Trilinos Amesos
   *   on several.
   * - `cg-amg`: conjugate gradients preconditioned by Trilinos ML algebraic
   *   multigrid, with the constant near-null-space modes reinit() is given:
   *   one per block of the coupled system of (u1, u2), one for s or w.
   * - `auto`: direct up to direct_solver_dof_limit unknowns on one process,
   *   cg-amg otherwise, on both cell types (benchmarks/floors.md,
   *   "`gmg_floor.sh`", for why geometric multigrid is not offered).
   *
   * CG stops at the residual norm it is given, and starts from the vector
   * it is given (the previous active set iterate, or the interpolated
   * solution of the previous mesh). It runs on any operator
   * with a vmult(): a matrix, or a deal.II LinearOperator composed from one,
   * with a preconditioner composed from the AMG hierarchy P of
   * initialize_preconditioner(). DecoupledSystem solves for S on the
   * Laplacian A of the mesh with the hierarchy of A, and for W on
   * Π (μ̄ A) Π + (I − Π) with Π P Π + (I − Π), P the hierarchy of the
   * condensed matrix of W (μ̄ included in that matrix), Π the projection
   * onto the inactive vertices; CoupledSystem solves on the scaled system
   * D K D with D⁻¹ P D⁻¹, P the hierarchy of K.
   */
  class LinearSolver
  {
  public:
    using VectorType = TrilinosWrappers::MPI::Vector;
    using MatrixType = TrilinosWrappers::SparseMatrix;

    /**
     * The Amesos package of the direct solver on several processes: MUMPS,
     * a multifrontal LU factorization with pivoting that runs on all
     * processes of the matrix (benchmarks/choices.md, "The direct solver on
     * one process", for UMFPACK on one).
     */
    static constexpr const char *direct_solver_package = "Amesos_Mumps";

    /**
     * Largest problem that `auto` hands to the direct solver
     * (benchmarks/solvers.md, "`solver_crossover.py`").
     */
    static constexpr types::global_dof_index direct_solver_dof_limit = 1000;

    LinearSolver(const Parameters::LinearSolverType type,
                 const MPI_Comm                     mpi_communicator);

    /**
     * Choose the method for a problem of @p n_unknowns unknowns; forget the
     * AMG. @p constant_modes (by locally owned unknown, one vector per
     * mode) are the near null space that the AMG hierarchy is built for.
     */
    void
    reinit(const types::global_dof_index         n_unknowns,
           const std::vector<std::vector<bool>> &constant_modes);

    /** Whether reinit() chose the direct solver. */
    bool
    is_direct() const;

    /**
     * Build the AMG hierarchy of @p matrix, kept (and referring to
     * @p matrix) until the next reinit() or clear().
     */
    void
    initialize_preconditioner(const MatrixType &matrix);

    /** Whether initialize_preconditioner() has built a hierarchy. */
    bool
    has_preconditioner() const;

    /** The AMG hierarchy of initialize_preconditioner(). */
    const TrilinosWrappers::PreconditionAMG &
    preconditioner() const;

    /**
     * Solve `matrix x = rhs` by the LU factorization of @p matrix: by
     * UMFPACK on a deal.II copy of @p matrix on one process, by MUMPS on
     * several.
     */
    void
    solve_direct(const MatrixType &matrix,
                 VectorType       &x,
                 const VectorType &rhs) const;

    /**
     * Solve `op x = rhs` by CG preconditioned by @p preconditioner, starting
     * from @p x, to a residual norm of at most @p tolerance (but never below
     * 1e-14 ‖rhs‖). Returns the number of CG iterations.
     */
    template <typename OperatorType, typename PreconditionerType>
    unsigned int
    solve_cg(const OperatorType       &op,
             const PreconditionerType &preconditioner,
             VectorType               &x,
             const VectorType         &rhs,
             const double              tolerance) const
    {
      const double rhs_norm = rhs.l2_norm();
      if (rhs_norm == 0)
        {
          x = 0;
          return 0;
        }
      SolverControl control(10000, std::max(tolerance, 1e-14 * rhs_norm));
      SolverCG<VectorType> cg(control);
      cg.solve(op, x, rhs, preconditioner);
      return control.last_step();
    }

    /** Free the AMG hierarchy, when the last solve of a mesh is done. */
    void
    clear();

    /**
     * What the last reinit() chose: "UMFPACK" or "MUMPS" (the direct
     * solver on one or on several processes) or "cg-amg".
     */
    std::string
    method() const;

  private:
    const Parameters::LinearSolverType type;
    const MPI_Comm                     mpi_communicator;

    bool                           use_direct;
    std::vector<std::vector<bool>> constant_modes;

    /** The AMG hierarchy, if built. */
    std::unique_ptr<TrilinosWrappers::PreconditionAMG> amg;
  };



} // namespace membranes

#endif
