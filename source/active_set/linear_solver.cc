#include <algorithm>
#include <deal.II/base/mpi.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/trilinos_solver.h>
#include <membranes/active_set/linear_solver.h>

namespace membranes
{
  template <int dim>
  LinearSolver<dim>::LinearSolver(const Parameters::LinearSolverType type,
                                  const MPI_Comm mpi_communicator)
    : type(type)
    , mpi_communicator(mpi_communicator)
    , use_direct(false)
  {}



  template <int dim>
  void
  LinearSolver<dim>::reinit(
    const types::global_dof_index         n_unknowns,
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



  template <int dim>
  bool
  LinearSolver<dim>::is_direct() const
  {
    return use_direct;
  }



  template <int dim>
  void
  LinearSolver<dim>::initialize_preconditioner(const MatrixType &matrix)
  {
    // Smoothed aggregation (ML's default): lower-memory settings slow CG down
    // (benchmarks/README.md, "The settings of ML and the peak memory").
    TrilinosWrappers::PreconditionAMG::AdditionalData amg_data;
    amg_data.elliptic        = true;
    amg_data.constant_modes  = constant_modes;
    amg_data.smoother_sweeps = 2;
    amg.reset();
    amg = std::make_unique<TrilinosWrappers::PreconditionAMG>();
    amg->initialize(matrix, amg_data);
  }



  template <int dim>
  bool
  LinearSolver<dim>::has_preconditioner() const
  {
    return amg != nullptr;
  }



  template <int dim>
  const TrilinosWrappers::PreconditionAMG &
  LinearSolver<dim>::preconditioner() const
  {
    Assert(amg, ExcInternalError());
    return *amg;
  }



  template <int dim>
  void
  LinearSolver<dim>::clear()
  {
    amg.reset();
  }



  template <int dim>
  std::string
  LinearSolver<dim>::method() const
  {
    return use_direct ? "direct" : "cg-amg";
  }



  template <int dim>
  void
  LinearSolver<dim>::solve_direct(const MatrixType &matrix,
                                  VectorType       &x,
                                  const VectorType &rhs) const
  {
    SolverControl                                  control;
    TrilinosWrappers::SolverDirect::AdditionalData data(false,
                                                        direct_solver_package);
    TrilinosWrappers::SolverDirect                 solver(control, data);
    solver.solve(matrix, x, rhs);
  }



  template class LinearSolver<2>;
} // namespace membranes
