#ifndef membranes_linear_solver_h
#define membranes_linear_solver_h

#include <algorithm>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
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
   * symmetric positive definite systems of one iteration.
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
   * iterations of the active set method are cheap. It runs on any operator
   * with a vmult(): a matrix, or the matrix seen through RestrictedOperator
   * or ScaledOperator, with the AMG hierarchy of initialize_preconditioner()
   * seen the same way.
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

    LinearSolver(const Parameters::LinearSolverType type,
                 const MPI_Comm                     mpi_communicator);

    /** Choose the method for the current problem size; forget the AMG. */
    void
    reinit(const DoFHandler<dim> &dof_handler);

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

    /** Solve `matrix x = rhs` by the LU factorization of @p matrix. */
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

    /** "direct" or "cg-amg": what the last reinit() chose. */
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



  /**
   * The operator Π (c B) Π + (I − Π) of an operator B (a matrix, or its AMG
   * hierarchy), where Π sets the entries at a set of locally owned
   * positions to zero: B restricted to the other entries, the identity on
   * these. With B = A and the positions of the active vertices it is the
   * matrix of the obstacle problem of one active set iteration with its
   * constraints W_a = 0 condensed (DecoupledSystem), applied without a
   * matrix of its own; with B the AMG hierarchy of A and c = 1/μ̄ it is its
   * preconditioner. A vector with zeros at the positions is mapped to one
   * with zeros there, so CG started there stays there.
   */
  template <typename OperatorType>
  class RestrictedOperator
  {
  public:
    using VectorType = TrilinosWrappers::MPI::Vector;

    RestrictedOperator(const OperatorType              &op,
                       const double                     coefficient,
                       const std::vector<unsigned int> &positions,
                       const VectorType                &layout)
      : op(op)
      , coefficient(coefficient)
      , positions(positions)
      , restricted(layout)
    {}

    void
    vmult(VectorType &dst, const VectorType &src) const
    {
      restricted = src;
      for (const unsigned int p : positions)
        restricted.begin()[p] = 0;
      op.vmult(dst, restricted);
      dst *= coefficient;
      for (const unsigned int p : positions)
        dst.begin()[p] = src.begin()[p];
    }

  private:
    const OperatorType              &op;
    const double                     coefficient;
    const std::vector<unsigned int> &positions;
    mutable VectorType               restricted;
  };



  /**
   * The operator D B D of an operator B and a diagonal D (a vector of the
   * locally owned entries): the symmetric scaling of a system K x = b to
   * D K D y = D b, x = D y, whose residual D(b − K x) is the one measured
   * (CoupledSystem); with B the AMG hierarchy of K and D⁻¹ it is the
   * preconditioner of the scaled system.
   */
  template <typename OperatorType>
  class ScaledOperator
  {
  public:
    using VectorType = TrilinosWrappers::MPI::Vector;

    ScaledOperator(const OperatorType &op, const VectorType &scaling)
      : op(op)
      , scaling(scaling)
      , scaled(scaling)
    {}

    void
    vmult(VectorType &dst, const VectorType &src) const
    {
      scaled = src;
      scaled.scale(scaling);
      op.vmult(dst, scaled);
      dst.scale(scaling);
    }

  private:
    const OperatorType &op;
    const VectorType   &scaling;
    mutable VectorType  scaled;
  };
} // namespace membranes

#endif
