#include <algorithm>
#include <deal.II/base/mpi.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparse_direct.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/trilinos_solver.h>
#include <deal.II/lac/vector.h>
#include <membranes/active_set/linear_solver.h>

namespace membranes
{
  LinearSolver::LinearSolver(const Parameters::LinearSolverType type,
                             const MPI_Comm mpi_communicator)
    : type(type)
    , mpi_communicator(mpi_communicator)
    , use_direct(false)
  {}



  void
  LinearSolver::reinit(const types::global_dof_index         n_unknowns,
                       const std::vector<std::vector<bool>> &constant_modes)
  {
    const bool serial =
      (Utilities::MPI::n_mpi_processes(mpi_communicator) == 1);
    use_direct = (type == Parameters::LinearSolverType::direct) ||
                 (type == Parameters::LinearSolverType::automatic && serial &&
                  n_unknowns <= direct_solver_dof_limit);
    this->constant_modes = constant_modes;
    amg.reset();
  }



  bool
  LinearSolver::is_direct() const
  {
    return use_direct;
  }



  void
  LinearSolver::initialize_preconditioner(const MatrixType &matrix)
  {
    // Smoothed aggregation (ML's default): lower-memory settings slow CG down
    // (benchmarks/choices.md, "The settings of ML and the peak memory").
    TrilinosWrappers::PreconditionAMG::AdditionalData amg_data;
    amg_data.elliptic        = true;
    amg_data.constant_modes  = constant_modes;
    amg_data.smoother_sweeps = 2;
    amg.reset();
    amg = std::make_unique<TrilinosWrappers::PreconditionAMG>();
    amg->initialize(matrix, amg_data);
  }



  bool
  LinearSolver::has_preconditioner() const
  {
    return amg != nullptr;
  }



  const TrilinosWrappers::PreconditionAMG &
  LinearSolver::preconditioner() const
  {
    Assert(amg, ExcInternalError());
    return *amg;
  }



  void
  LinearSolver::clear()
  {
    amg.reset();
  }



  std::string
  LinearSolver::method() const
  {
    if (!use_direct)
      return "cg-amg";
    return Utilities::MPI::n_mpi_processes(mpi_communicator) == 1 ? "UMFPACK" :
                                                                    "MUMPS";
  }



  void
  LinearSolver::solve_direct(const MatrixType &matrix,
                             VectorType       &x,
                             const VectorType &rhs) const
  {
    if (Utilities::MPI::n_mpi_processes(mpi_communicator) > 1)
      {
        SolverControl                                  control;
        TrilinosWrappers::SolverDirect::AdditionalData data(
          false, direct_solver_package);
        TrilinosWrappers::SolverDirect solver(control, data);
        solver.solve(matrix, x, rhs);
        return;
      }
    // UMFPACK factorizes deal.II's SparseMatrix: the rows of the Epetra
    // matrix copied into one, not by SparseMatrix::copy_from()
    // (benchmarks/choices.md, "The direct solver on one process").
    const Epetra_CrsMatrix &epetra         = matrix.trilinos_matrix();
    const auto              for_each_entry = [&epetra](const auto &f) {
      for (int row = 0; row < epetra.NumMyRows(); ++row)
        {
          int     n_entries;
          double *values;
          int    *columns;
          epetra.ExtractMyRowView(row, n_entries, values, columns);
          for (int k = 0; k < n_entries; ++k)
            f(epetra.GRID(row), epetra.GCID(columns[k]), values[k]);
        }
    };
    std::vector<unsigned int> row_lengths(matrix.m());
    for_each_entry([&](const int row, int, double) { ++row_lengths[row]; });
    SparsityPattern sparsity(matrix.m(), matrix.n(), row_lengths);
    for_each_entry([&](const int row, const int column, double) {
      sparsity.add(row, column);
    });
    sparsity.compress();
    SparseMatrix<double> serial_matrix(sparsity);
    for_each_entry([&](const int row, const int column, const double value) {
      serial_matrix.set(row, column, value);
    });
    SparseDirectUMFPACK umfpack;
    umfpack.initialize(serial_matrix);
    Vector<double> solution(rhs);
    umfpack.solve(solution);
    x = solution;
  }
} // namespace membranes
