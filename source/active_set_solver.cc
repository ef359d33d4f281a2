#include <algorithm>
#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>
#include <limits>
#include <membranes/active_set_solver.h>
#include <membranes/coupled_system.h>
#include <membranes/decoupled_system.h>

namespace membranes
{
  namespace
  {
    /** The linear problem of one iteration, as `Solver/Method` asks. */
    template <int dim>
    std::unique_ptr<ActiveSetSystem<dim>>
    make_active_set_system(const Parameters::Solver  &parameters,
                           const Discretization<dim> &discretization,
                           const ProblemData<dim>    &data,
                           const MPI_Comm             mpi_communicator)
    {
      if (parameters.method == Parameters::SolverMethod::decoupled)
        return std::make_unique<DecoupledSystem<dim>>(parameters,
                                                      discretization,
                                                      data,
                                                      mpi_communicator);
      return std::make_unique<CoupledSystem<dim>>(parameters,
                                                  discretization,
                                                  data,
                                                  mpi_communicator);
    }
  } // namespace



  template <int dim>
  ActiveSetSolver<dim>::ActiveSetSolver(
    const Parameters::Solver  &parameters,
    const Discretization<dim> &discretization,
    const ProblemData<dim>    &data,
    const ConditionalOStream  &pcout,
    const MPI_Comm             mpi_communicator)
    : parameters(parameters)
    , data(data)
    , pcout(pcout)
    , mpi_communicator(mpi_communicator)
    , system(make_active_set_system(parameters,
                                    discretization,
                                    data,
                                    mpi_communicator))
  {}



  template <int dim>
  void
  ActiveSetSolver<dim>::setup(const DoFHandler<dim>     &dof_handler,
                              const IndexSet            &locally_owned_dofs,
                              const IndexSet            &locally_relevant_dofs,
                              const DiscreteAction<dim> &action)
  {
    this->dof_handler           = &dof_handler;
    this->locally_owned_dofs    = locally_owned_dofs;
    this->locally_relevant_dofs = locally_relevant_dofs;
    system->setup(dof_handler,
                  locally_owned_dofs,
                  locally_relevant_dofs,
                  action);
  }



  template <int dim>
  template <typename LambdaOfVertex>
  IndexSet
  ActiveSetSolver<dim>::active_set_for(const DiscreteAction<dim> &action,
                                       const VectorType     &ghosted_solution,
                                       const LambdaOfVertex &lambda) const
  {
    IndexSet    active_set(dof_handler->n_dofs());
    const auto &vertices = action.vertices();
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const auto  &a = vertices[k];
        const double w =
          ghosted_solution[a.dof[0]] - ghosted_solution[a.dof[1]];
        const double c =
          data.mu_bar * a.stiffness_diagonal / a.dual_cell_measure;
        if (lambda(k) - c * w > 0)
          active_set.add_index(a.dof[0]);
      }
    active_set.compress();
    return active_set;
  }



  template <int dim>
  IndexSet
  ActiveSetSolver<dim>::locally_relevant_active_set(
    const DiscreteAction<dim> &action,
    const IndexSet            &active_set) const
  {
    VectorType owned_flags(locally_owned_dofs, mpi_communicator);
    for (const auto dof : active_set)
      owned_flags[dof] = 1;
    owned_flags.compress(VectorOperation::insert);
    VectorType flags(locally_owned_dofs,
                     locally_relevant_dofs,
                     mpi_communicator);
    flags = owned_flags;

    IndexSet relevant_active_set(dof_handler->n_dofs());
    for (const auto &dofs : action.locally_relevant_vertices())
      if (flags[dofs[0]] > 0)
        relevant_active_set.add_index(dofs[0]);
    relevant_active_set.compress();
    return relevant_active_set;
  }



  template <int dim>
  IndexSet
  ActiveSetSolver<dim>::initial_active_set(
    const DiscreteAction<dim> &action,
    const VectorType          &ghosted_solution,
    const VectorType          &ghosted_lambda_h) const
  {
    return active_set_for(action, ghosted_solution, [&](const unsigned int k) {
      return ghosted_lambda_h[action.vertices()[k].dof[0]];
    });
  }



  template <int dim>
  double
  ActiveSetSolver<dim>::kkt_residual(const DiscreteAction<dim> &action,
                                     const VectorType &ghosted_solution,
                                     const IndexSet   &active_set) const
  {
    double      equilibrium = 0, primal = 0, dual = 0, complementarity = 0;
    const auto &vertices = action.vertices();
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const auto  &a  = vertices[k];
        const double d  = a.dual_cell_measure;
        const double r1 = action.lambda_from_membrane(0, k) * d;
        const double r2 = action.lambda_from_membrane(1, k) * d;
        if (active_set.is_element(a.dof[0]))
          equilibrium += (r1 - r2) * (r1 - r2);
        else
          equilibrium += r1 * r1 + r2 * r2;
        const double w =
          ghosted_solution[a.dof[0]] - ghosted_solution[a.dof[1]];
        const double force = action.lambda(k) * d;
        primal             = std::max(primal, -w);
        dual               = std::max(dual, -force);
        complementarity    = std::max(complementarity, std::abs(force * w));
      }
    const double u_scale = std::max(ghosted_solution.linfty_norm(),
                                    std::numeric_limits<double>::min());
    const double f_scale =
      std::max(action.force_scale(), std::numeric_limits<double>::min());
    const double f_scale_l2 =
      std::max(action.force_scale_l2(), std::numeric_limits<double>::min());

    return std::max(
      {std::sqrt(Utilities::MPI::sum(equilibrium, mpi_communicator)) /
         f_scale_l2,
       Utilities::MPI::max(primal, mpi_communicator) / u_scale,
       Utilities::MPI::max(dual, mpi_communicator) / f_scale,
       Utilities::MPI::max(complementarity, mpi_communicator) /
         (f_scale * u_scale)});
  }



  template <int dim>
  typename ActiveSetSolver<dim>::Statistics
  ActiveSetSolver<dim>::solve(DiscreteAction<dim> &action,
                              VectorType          &solution,
                              IndexSet            &active_set)
  {
    Statistics statistics;
    Timer      timer;
    VectorType ghosted_solution(locally_owned_dofs,
                                locally_relevant_dofs,
                                mpi_communicator);
    ghosted_solution = solution;
    action.compute(ghosted_solution);

    // The forces of the last iterate set the scale of the linear solver's
    // residual: a hundredth of what the KKT test allows.
    const auto linear_tolerance = [&]() {
      return 1e-2 * parameters.tolerance * action.force_scale_l2();
    };
    system->prepare(solution, linear_tolerance(), statistics);

    for (unsigned int iteration = 1;; ++iteration)
      {
        system->solve(action,
                      locally_relevant_active_set(action, active_set),
                      solution,
                      linear_tolerance(),
                      statistics);

        timer.restart();
        ghosted_solution = solution;
        action.compute(ghosted_solution);
        const IndexSet next_active_set =
          active_set_for(action, ghosted_solution, [&](const unsigned int k) {
            return action.lambda(k);
          });
        statistics.kkt_residual =
          kkt_residual(action, ghosted_solution, active_set);
        statistics.iterations = iteration;
        const bool repeated =
          Utilities::MPI::min(next_active_set == active_set ? 1 : 0,
                              mpi_communicator) == 1;
        statistics.solve_time += timer.wall_time();

        pcout << "      active set iteration " << iteration << ": "
              << Utilities::MPI::sum(active_set.n_elements(), mpi_communicator)
              << " active vertices, relative KKT residual "
              << statistics.kkt_residual << ", " << system->description()
              << std::endl;

        active_set = next_active_set;
        if (repeated && statistics.kkt_residual <= parameters.tolerance)
          return statistics;
        if (iteration == parameters.max_active_set_iterations)
          throw std::runtime_error(
            "Solver/Max active set iterations = " + std::to_string(iteration) +
            " reached without convergence (relative KKT residual " +
            std::to_string(statistics.kkt_residual) + ")");
      }
  }



  template class ActiveSetSolver<2>;
} // namespace membranes
