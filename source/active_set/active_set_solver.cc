#include <algorithm>
#include <array>
#include <cmath>
#include <deal.II/base/mpi.h>
#include <deal.II/grid/grid_tools.h>
#include <iomanip>
#include <limits>
#include <membranes/active_set/active_set_solver.h>
#include <membranes/active_set/coupled_system.h>
#include <membranes/active_set/decoupled_system.h>
#include <sstream>

namespace membranes
{
  namespace
  {
    /** @p value with 3 significant digits, e.g. "1.23e-08". */
    std::string
    format(const double value)
    {
      std::ostringstream text;
      text << std::setprecision(3) << value;
      return text.str();
    }



    /**
     * The linear problem of one iteration, as `Solver/Method` asks; `auto`
     * is the decoupled one, faster on every scene measured
     * (benchmarks/solver_cost.sh): its systems are half the size of the
     * coupled one, S is solved once per mesh, and its operators are taken
     * from the mesh's matrix (DiscreteProblem) without a new assembly.
     */
    template <int dim>
    std::unique_ptr<ActiveSetSystem<dim>>
    make_active_set_system(const Parameters::Solver &parameters,
                           const ProblemData<dim>   &data,
                           const MPI_Comm            mpi_communicator)
    {
      if (parameters.method == Parameters::SolverMethod::coupled)
        return std::make_unique<CoupledSystem<dim>>(parameters,
                                                    data,
                                                    mpi_communicator);
      return std::make_unique<DecoupledSystem<dim>>(parameters,
                                                    data,
                                                    mpi_communicator);
    }
  } // namespace



  template <int dim>
  ActiveSetSolver<dim>::ActiveSetSolver(const Parameters::Solver &parameters,
                                        const ProblemData<dim>   &data,
                                        const ConditionalOStream &pcout,
                                        TimerOutput              &timer,
                                        const MPI_Comm mpi_communicator)
    : parameters(parameters)
    , data(data)
    , pcout(pcout)
    , timer(timer)
    , mpi_communicator(mpi_communicator)
    , prediction(parameters, data)
    , system(make_active_set_system(parameters, data, mpi_communicator))
  {}



  template <int dim>
  ActiveSetSolver<dim>::~ActiveSetSolver() = default;



  template <int dim>
  void
  ActiveSetSolver<dim>::setup(const DiscreteProblem<dim> &discrete_problem,
                              const DoFHandler<dim>      &dof_handler)
  {
    prediction.reinit(discrete_problem);
    system->setup(discrete_problem, dof_handler);

    // The constants of balanced stopping: C_F of the bounding box of the
    // mesh, c_M of the lumped mass, and d_min.
    const BoundingBox<dim> box =
      GridTools::compute_bounding_box(dof_handler.get_triangulation());
    double inverse_squares = 0;
    for (unsigned int d = 0; d < dim; ++d)
      inverse_squares +=
        std::pow(Utilities::MPI::max(box.get_boundary_points().second[d],
                                     mpi_communicator) -
                   Utilities::MPI::min(box.get_boundary_points().first[d],
                                       mpi_communicator),
                 -2);
    const double lumped_mass_constant =
      dof_handler.get_fe().reference_cell().is_simplex() ? 2 : 3;
    dual_norm_constant =
      lumped_mass_constant / (numbers::PI * std::sqrt(inverse_squares));
    double min_measure = std::numeric_limits<double>::max();
    for (const auto &a : discrete_problem.vertices())
      min_measure = std::min(min_measure, a.dual_cell_measure);
    min_dual_cell_measure = Utilities::MPI::min(min_measure, mpi_communicator);
  }



  template <int dim>
  LinearTolerances
  ActiveSetSolver<dim>::linear_tolerances(const StoppingState &stopping) const
  {
    const double     allowed = parameters.tolerance / stopping.tightening;
    LinearTolerances tolerances{allowed * stopping.force_scales[0],
                                allowed * stopping.force_scales[1]};
    if (stopping.balanced)
      {
        const double balanced_tolerance =
          stopping.balance / 2 *
          std::sqrt(data.mu_bar * min_dual_cell_measure) / dual_norm_constant;
        tolerances.sum     = std::max(tolerances.sum, balanced_tolerance);
        tolerances.contact = std::max(tolerances.contact, balanced_tolerance);
      }
    return tolerances;
  }



  template <int dim>
  void
  ActiveSetSolver<dim>::evaluate(const DiscreteProblem<dim> &problem,
                                 const DiscreteAction<dim>  &action,
                                 const VectorType           &solution,
                                 const ActiveSet<dim>       &active_set,
                                 const StoppingState        &stopping,
                                 Statistics                 &statistics) const
  {
    const double tiny       = std::numeric_limits<double>::min();
    statistics.kkt_defects  = KKTDefects(problem, action, active_set, solution);
    statistics.kkt_residual = statistics.kkt_defects.relative_residual(
      std::max(action.force_scale(), tiny),
      std::max(action.contact_force_scale(), tiny),
      displacement_scale(solution));
    if (stopping.balanced)
      {
        statistics.linearization_estimate =
          linearization_estimate(problem, action, solution, active_set);
        statistics.algebraic_estimate =
          algebraic_estimate(problem, action, active_set);
      }
  }



  template <int dim>
  bool
  ActiveSetSolver<dim>::stops(const Statistics             &statistics,
                              const types::global_dof_index n_changes,
                              StoppingState                &stopping) const
  {
    if (stopping.balanced &&
        (n_changes == 0 ||
         *statistics.linearization_estimate + *statistics.algebraic_estimate <=
           stopping.balance))
      return true;

    const std::string reached =
      "relative KKT residual " + format(statistics.kkt_residual) +
      " (Solver/Tolerance = " + format(parameters.tolerance) + ")";
    if (n_changes == 0)
      {
        if (statistics.kkt_residual <= parameters.tolerance)
          return true;
        if (statistics.kkt_residual >= stopping.settled_residual)
          throw ActiveSetNotConverged(
            "the active set method stalls after " +
            std::to_string(statistics.iterations) +
            " iterations: the active set has settled, but the " + reached +
            " does not decrease any more (the accuracy of " +
            "the linear solver, " + system->description() + ", limits it)");
        // Solve again on the same active set, more accurately.
        stopping.settled_residual = statistics.kkt_residual;
        stopping.tightening *= settled_tightening;
        pcout << "      the active set has settled: solve again with "
              << settled_tightening << " times smaller residuals" << std::endl;
      }
    else
      stopping.settled_residual = std::numeric_limits<double>::infinity();

    if (statistics.iterations == parameters.max_active_set_iterations)
      throw ActiveSetNotConverged("Solver/Max active set iterations = " +
                                  std::to_string(statistics.iterations) +
                                  " reached without convergence: " + reached +
                                  ", " + std::to_string(n_changes) +
                                  " vertices still to change");
    return false;
  }



  template <int dim>
  void
  ActiveSetSolver<dim>::print_iteration(const Statistics     &statistics,
                                        const ActiveSet<dim> &active_set,
                                        const types::global_dof_index n_changes,
                                        const unsigned int   linear_iterations,
                                        const StoppingState &stopping) const
  {
    pcout << "      active set iteration " << statistics.iterations << ": "
          << active_set.n_active_vertices() << " active vertices, " << n_changes
          << " to change, relative KKT residual " << statistics.kkt_residual
          << ", " << system->description() << " ("
          << statistics.linear_iterations - linear_iterations << " iterations)"
          << std::endl;
    if (stopping.balanced)
      pcout << "      balanced stopping: linearization "
            << *statistics.linearization_estimate << " + algebraic "
            << *statistics.algebraic_estimate << " vs gamma * expected "
            << stopping.balance << std::endl;
  }



  template <int dim>
  typename ActiveSetSolver<dim>::StoppingState
  ActiveSetSolver<dim>::start(const double expected_error) const
  {
    return {parameters.stopping == Parameters::Stopping::balanced &&
              expected_error > 0,
            parameters.balance_fraction * expected_error,
            1,
            std::numeric_limits<double>::infinity(),
            {}};
  }



  template <int dim>
  void
  ActiveSetSolver<dim>::compute_action(const DiscreteProblem<dim> &problem,
                                       DiscreteAction<dim>        &action,
                                       const VectorType           &solution,
                                       StoppingState &stopping) const
  {
    action.compute(problem, solution);
    stopping.force_scales = {
      {action.force_scale(), action.contact_force_scale()}};
  }



  template <int dim>
  void
  ActiveSetSolver<dim>::update(const DiscreteProblem<dim>      &problem,
                               ActiveSet<dim>                  &active_set,
                               const VectorType                &solution,
                               const std::vector<StatusChange> &changes,
                               const unsigned int               iteration,
                               StoppingState                   &stopping)
  {
    // The changes that the test wants on the predicted iterate, unless a
    // cycle has been detected on this mesh or the prediction wants none.
    const std::vector<StatusChange> *next = &changes;
    std::vector<StatusChange>        predicted;
    if (active_set.cycles() == 0)
      {
        predicted = prediction.changes(problem, active_set, solution, changes);
        stopping.force_scales = prediction.force_scales();
        if (Utilities::MPI::sum(predicted.size(), mpi_communicator) > 0)
          next = &predicted;
      }
    const auto update = active_set.update(problem, *next);
    if (update.cycle_to)
      pcout << "      cycle: iteration " << iteration + 1
            << " would repeat the active set of iteration "
            << *update.cycle_to + 1 << "; " << update.changed << " of "
            << update.wanted << " vertices change"
            << (update.least_index_rule ?
                  " (Murty's least-index rule from now on)" :
                  " (the largest violations)")
            << std::endl;
  }



  template <int dim>
  double
  ActiveSetSolver<dim>::equilibrium_square(
    const DiscreteProblem<dim>  &problem,
    const DiscreteAction<dim>   &action,
    const unsigned int           k,
    const ActiveSet<dim>        &active_set,
    const std::array<double, 3> &weights) const
  {
    const auto  &a  = problem.vertices()[k];
    const double d  = a.dual_cell_measure;
    const double r1 = action.lambda_from_membrane(0, k) * d;
    const double r2 = action.lambda_from_membrane(1, k) * d;
    if (active_set.is_active(k))
      return weights[2] * (r1 - r2) * (r1 - r2);
    return weights[0] * r1 * r1 + weights[1] * r2 * r2;
  }



  template <int dim>
  double
  ActiveSetSolver<dim>::linearization_estimate(
    const DiscreteProblem<dim> &problem,
    const DiscreteAction<dim>  &action,
    const VectorType           &solution,
    const ActiveSet<dim>       &active_set) const
  {
    double      energy   = 0;
    const auto &vertices = problem.vertices();
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const auto  &a    = vertices[k];
        const double norm = a.stiffness_row_l1_norm;
        const double step = active_set.is_active(k) ?
                              2 * std::max(-action.lambda(k), 0.) *
                                a.dual_cell_measure / (data.mu_bar * norm) :
                              std::max(-problem.nodal_w(k, solution), 0.);
        energy += data.mu_bar * norm * step * step;
      }
    return std::sqrt(Utilities::MPI::sum(energy, mpi_communicator));
  }



  template <int dim>
  double
  ActiveSetSolver<dim>::algebraic_estimate(
    const DiscreteProblem<dim> &problem,
    const DiscreteAction<dim>  &action,
    const ActiveSet<dim>       &active_set) const
  {
    const double mu1 = data.mu[0], mu2 = data.mu[1];
    double       sum      = 0;
    const auto  &vertices = problem.vertices();
    for (unsigned int k = 0; k < vertices.size(); ++k)
      sum += equilibrium_square(problem,
                                action,
                                k,
                                active_set,
                                {{1 / mu1, 1 / mu2, 1 / (mu1 + mu2)}}) /
             vertices[k].dual_cell_measure;
    return dual_norm_constant *
           std::sqrt(Utilities::MPI::sum(sum, mpi_communicator));
  }



  template <int dim>
  typename ActiveSetSolver<dim>::Statistics
  ActiveSetSolver<dim>::solve(const DiscreteProblem<dim> &problem,
                              DiscreteAction<dim>        &action,
                              VectorType                 &solution,
                              ActiveSet<dim>             &active_set,
                              const double                expected_error)
  {
    Statistics    statistics;
    StoppingState stopping = start(expected_error);
    active_set.restart(problem);
    for (statistics.iterations = 1;; ++statistics.iterations)
      {
        const unsigned int linear_iterations = statistics.linear_iterations;
        {
          TimerOutput::Scope scope(timer, "assembly");
          system->set_active_set(problem, active_set.locally_relevant(problem));
        }
        TimerOutput::Scope scope(timer, "solve");
        // The forces of the initial guess set the tolerances of the first
        // linear solve.
        if (statistics.iterations == 1)
          compute_action(problem, action, solution, stopping);
        system->solve(problem,
                      solution,
                      linear_tolerances(stopping),
                      statistics);
        compute_action(problem, action, solution, stopping);
        const auto changes =
          active_set.wanted_changes(problem, action, solution);
        const auto n_changes =
          Utilities::MPI::sum<types::global_dof_index>(changes.size(),
                                                       mpi_communicator);
        evaluate(problem, action, solution, active_set, stopping, statistics);
        print_iteration(
          statistics, active_set, n_changes, linear_iterations, stopping);
        if (stops(statistics, n_changes, stopping))
          break;
        if (n_changes > 0)
          update(problem,
                 active_set,
                 solution,
                 changes,
                 statistics.iterations,
                 stopping);
      }
    // The matrices and the AMG hierarchy of this mesh are not needed any more.
    system->clear();
    return statistics;
  }



  template class ActiveSetSolver<2>;
} // namespace membranes
