#include <algorithm>
#include <deal.II/base/mpi.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/trilinos_solver.h>
#include <membranes/linear_solver.h>

namespace membranes
{
  template <int dim>
  LinearSolver<dim>::LinearSolver(const Parameters::LinearSolverType type,
                                  const MPI_Comm mpi_communicator)
    : type(type)
    , mpi_communicator(mpi_communicator)
    , use_direct(false)
    , first_iterations(0)
  {}



  template <int dim>
  void
  LinearSolver<dim>::reinit(const DoFHandler<dim> &dof_handler)
  {
    const bool serial =
      (Utilities::MPI::n_mpi_processes(mpi_communicator) == 1);
    use_direct = (type == Parameters::LinearSolverType::direct) ||
                 (type == Parameters::LinearSolverType::automatic && serial &&
                  dof_handler.n_dofs() <= direct_solver_dof_limit);
    if (!use_direct)
      DoFTools::extract_constant_modes(dof_handler,
                                       ComponentMask(),
                                       constant_modes);
    amg.reset();
  }



  template <int dim>
  unsigned int
  LinearSolver<dim>::solve(const MatrixType &matrix,
                           VectorType       &x,
                           const VectorType &rhs,
                           const double      tolerance,
                           const MatrixType *mesh_matrix)
  {
    if (use_direct)
      {
        solve_direct(matrix, x, rhs);
        return 0;
      }
    return solve_cg_amg(matrix, x, rhs, tolerance, mesh_matrix);
  }



  template <int dim>
  bool
  LinearSolver<dim>::has_mesh_preconditioner() const
  {
    return amg != nullptr;
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
                                  const VectorType &rhs)
  {
    SolverControl                                  control;
    TrilinosWrappers::SolverDirect::AdditionalData data(false,
                                                        direct_solver_package);
    TrilinosWrappers::SolverDirect                 solver(control, data);
    solver.solve(matrix, x, rhs);
  }



  template <int dim>
  unsigned int
  LinearSolver<dim>::solve_cg_amg(const MatrixType &matrix,
                                  VectorType       &x,
                                  const VectorType &rhs,
                                  const double      tolerance,
                                  const MatrixType *mesh_matrix)
  {
    const double rhs_norm = rhs.l2_norm();
    if (rhs_norm == 0)
      {
        x = 0;
        return 0;
      }
    const bool build = !amg || !mesh_matrix;
    if (build)
      {
        TrilinosWrappers::PreconditionAMG::AdditionalData amg_data;
        amg_data.elliptic        = true;
        amg_data.constant_modes  = constant_modes;
        amg_data.smoother_sweeps = 2;
        amg = std::make_unique<TrilinosWrappers::PreconditionAMG>();
        amg->initialize(mesh_matrix ? *mesh_matrix : matrix, amg_data);
      }

    SolverControl        control(10000, std::max(tolerance, 1e-14 * rhs_norm));
    SolverCG<VectorType> cg(control);
    cg.solve(matrix, x, rhs, *amg);
    const unsigned int iterations = control.last_step();
    if (build)
      first_iterations = iterations;
    if (!mesh_matrix || iterations > 2 * first_iterations + rebuild_slack)
      amg.reset();
    return iterations;
  }



  template class LinearSolver<2>;
} // namespace membranes
