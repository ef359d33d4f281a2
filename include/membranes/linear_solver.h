#ifndef membranes_linear_solver_h
#define membranes_linear_solver_h

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/parameters.h>
#include <memory>
#include <string>

namespace membranes
{
  using namespace dealii;

  /**
   * The linear solves inside the active set method: the condensed,
   * symmetric positive definite system of one iteration.
   *
   * - `direct`: the sparse LU factorization of Trilinos Amesos
   *   (TrilinosWrappers::SolverDirect with direct_solver_package) of the
   *   distributed matrix itself, on any number of processes.
   * - `cg-amg`: conjugate gradients preconditioned by Trilinos ML algebraic
   *   multigrid, with one constant near-null-space mode per component of
   *   the DoFHandler (per membrane for (u1, u2), one for s or w).
   * - `auto`: direct up to direct_solver_dof_limit DoFs on one process,
   *   cg-amg otherwise.
   *
   * CG stops at the residual norm it is given (the active set method
   * relates it to the size of the forces, not to the right-hand side, whose
   * rows of constrained boundary DoFs can dwarf the interior ones on fine
   * meshes), and starts from the vector it is given (the previous active set
   * iterate, or the interpolated solution of the previous mesh), so later
   * iterations of the active set method are cheap.
   *
   * The AMG hierarchy is built for each solve, or, if the caller gives a
   * mesh matrix, once per mesh from that matrix, which the caller keeps
   * unchanged until the next reinit() (the hierarchy refers to it). The
   * obstacle problem for w is such a case: its matrices differ from the
   * operator of the mesh only in the eliminated rows and columns of the
   * active vertices, so one hierarchy preconditions all of them. While the
   * CG iterations of a solve stay within twice those of the solve that
   * built the hierarchy (plus rebuild_slack), it is kept; a solve that
   * needs more has it rebuilt for the next one.
   */
  template <int dim>
  class LinearSolver
  {
  public:
    using VectorType = TrilinosWrappers::MPI::Vector;
    using MatrixType = TrilinosWrappers::SparseMatrix;

    /**
     * The Amesos package of the direct solver: MUMPS, a multifrontal LU
     * factorization with pivoting that runs on all processes of the
     * matrix (Amesos_Klu, always available, gathers the matrix on one
     * process and is less accurate on these systems).
     */
    static constexpr const char *direct_solver_package = "Amesos_Mumps";

    /** Largest problem that `auto` hands to the direct solver. */
    static constexpr types::global_dof_index direct_solver_dof_limit = 10000;

    /** CG iterations a reused hierarchy may need beyond twice its first. */
    static constexpr unsigned int rebuild_slack = 5;

    LinearSolver(const Parameters::LinearSolverType type,
                 const MPI_Comm                     mpi_communicator);

    /** Choose the method for the current problem size; forget the AMG. */
    void
    reinit(const DoFHandler<dim> &dof_handler);

    /**
     * Solve `matrix x = rhs`, starting from @p x, to a residual norm of at
     * most @p tolerance (CG; but never below 1e-14 ‖rhs‖), preconditioned
     * by the AMG hierarchy of @p mesh_matrix if given, of @p matrix
     * otherwise. Returns the number of CG iterations (0 for the direct
     * solver).
     */
    unsigned int
    solve(const MatrixType &matrix,
          VectorType       &x,
          const VectorType &rhs,
          const double      tolerance,
          const MatrixType *mesh_matrix);

    /**
     * Whether the AMG hierarchy of the last mesh matrix given to solve() is
     * kept for the next solve (always false for the direct solver).
     */
    bool
    has_mesh_preconditioner() const;

    /** Free the AMG hierarchy, when the last solve of a mesh is done. */
    void
    clear();

    /** "direct" or "cg-amg": what the last reinit() chose. */
    std::string
    method() const;

  private:
    void
    solve_direct(const MatrixType &matrix,
                 VectorType       &x,
                 const VectorType &rhs);

    unsigned int
    solve_cg_amg(const MatrixType &matrix,
                 VectorType       &x,
                 const VectorType &rhs,
                 const double      tolerance,
                 const MatrixType *mesh_matrix);

    const Parameters::LinearSolverType type;
    const MPI_Comm                     mpi_communicator;

    bool                           use_direct;
    std::vector<std::vector<bool>> constant_modes;

    /** The AMG hierarchy of the mesh matrix, if built. */
    std::unique_ptr<TrilinosWrappers::PreconditionAMG> amg;
    /** CG iterations of the solve that built it. */
    unsigned int first_iterations;
  };
} // namespace membranes

#endif
