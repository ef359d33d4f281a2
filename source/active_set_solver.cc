#include <algorithm>
#include <array>
#include <cmath>
#include <deal.II/base/mpi.h>
#include <iomanip>
#include <limits>
#include <membranes/active_set_solver.h>
#include <membranes/coupled_system.h>
#include <membranes/decoupled_system.h>
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
     * coupled one, S is solved once per mesh, and its operator is assembled
     * once per mesh.
     */
    template <int dim>
    std::unique_ptr<ActiveSetSystem<dim>>
    make_active_set_system(const Parameters::Solver  &parameters,
                           const Discretization<dim> &discretization,
                           const ProblemData<dim>    &data,
                           TimerOutput               &timer,
                           const MPI_Comm             mpi_communicator)
    {
      if (parameters.method == Parameters::SolverMethod::coupled)
        return std::make_unique<CoupledSystem<dim>>(
          parameters, discretization, data, timer, mpi_communicator);
      return std::make_unique<DecoupledSystem<dim>>(
        parameters, discretization, data, timer, mpi_communicator);
    }

    /** @p set with the status of the vertices @p dofs changed. */
    IndexSet
    toggled(const IndexSet                             &set,
            const std::vector<types::global_dof_index> &dofs)
    {
      IndexSet changed(set.size());
      for (const auto dof : dofs)
        changed.add_index(dof);
      changed.compress();
      IndexSet result = set;
      result.add_indices(changed);
      result.subtract_set(set & changed);
      return result;
    }
  } // namespace



  ActiveSetHistory::ActiveSetHistory(const MPI_Comm mpi_communicator)
    : mpi_communicator(mpi_communicator)
    , n_cycles(0)
    , least_index_rule(false)
  {}



  void
  ActiveSetHistory::restart(const IndexSet &initial_active_set)
  {
    visited          = {initial_active_set};
    n_cycles         = 0;
    least_index_rule = false;
  }



  std::optional<unsigned int>
  ActiveSetHistory::find(const IndexSet &set) const
  {
    for (unsigned int i = 0; i < visited.size(); ++i)
      if (Utilities::MPI::min(visited[i] == set ? 1 : 0, mpi_communicator) == 1)
        return i;
    return std::nullopt;
  }



  ActiveSetHistory::Step
  ActiveSetHistory::next(const IndexSet                  &active_set,
                         const std::vector<StatusChange> &changes)
  {
    std::vector<types::global_dof_index> local_dofs;
    for (const auto &change : changes)
      local_dofs.push_back(change.dof);
    std::sort(local_dofs.begin(), local_dofs.end());

    Step step;
    step.wanted =
      Utilities::MPI::sum<types::global_dof_index>(changes.size(),
                                                   mpi_communicator);
    step.changed          = step.wanted;
    step.active_set       = toggled(active_set, local_dofs);
    step.least_index_rule = least_index_rule;
    if (step.wanted > 0 && !least_index_rule)
      step.cycle_to = find(step.active_set);

    if (step.wanted > 0 && (step.cycle_to || least_index_rule))
      {
        // All wanted changes of all processes, by decreasing violation
        // (ties by DoF index, so that every process sorts alike).
        std::vector<std::pair<double, types::global_dof_index>> ranked;
        for (const auto &process_changes :
             Utilities::MPI::all_gather(mpi_communicator, changes))
          for (const auto &change : process_changes)
            ranked.emplace_back(-change.violation, change.dof);
        std::sort(ranked.begin(), ranked.end());

        // Change only the first @p n of them (this process: its own).
        const auto change_first = [&](const types::global_dof_index n) {
          std::vector<types::global_dof_index> dofs;
          for (types::global_dof_index i = 0; i < n; ++i)
            if (std::binary_search(local_dofs.begin(),
                                   local_dofs.end(),
                                   ranked[i].second))
              dofs.push_back(ranked[i].second);
          step.changed    = n;
          step.active_set = toggled(active_set, dofs);
        };

        for (bool repeats = !least_index_rule; repeats;)
          {
            ++n_cycles;
            const types::global_dof_index share =
              (step.wanted + (types::global_dof_index(1) << n_cycles) - 1) >>
              n_cycles;
            least_index_rule = (share <= 1);
            if (least_index_rule)
              break;
            change_first(share);
            repeats = find(step.active_set).has_value();
          }
        if (least_index_rule)
          {
            std::sort(ranked.begin(), ranked.end(), [](auto &x, auto &y) {
              return x.second < y.second;
            });
            change_first(1);
            step.least_index_rule = true;
          }
      }
    visited.push_back(step.active_set);
    return step;
  }



  unsigned int
  ActiveSetHistory::cycles() const
  {
    return n_cycles;
  }



  template <int dim>
  ActiveSetSolver<dim>::ActiveSetSolver(
    const Parameters::Solver  &parameters,
    const Discretization<dim> &discretization,
    const ProblemData<dim>    &data,
    const ConditionalOStream  &pcout,
    TimerOutput               &timer,
    const MPI_Comm             mpi_communicator)
    : parameters(parameters)
    , data(data)
    , pcout(pcout)
    , timer(timer)
    , mpi_communicator(mpi_communicator)
    , system(make_active_set_system(parameters,
                                    discretization,
                                    data,
                                    timer,
                                    mpi_communicator))
    , history(mpi_communicator)
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

    // The constants of balanced stopping: C_F of the bounding box of the
    // mesh, c_M of the lumped mass, and d_min.
    std::array<double, dim> lower, upper;
    lower.fill(std::numeric_limits<double>::max());
    upper.fill(-std::numeric_limits<double>::max());
    const auto &triangulation = dof_handler.get_triangulation();
    for (unsigned int v = 0; v < triangulation.n_vertices(); ++v)
      if (triangulation.get_used_vertices()[v])
        for (unsigned int d = 0; d < dim; ++d)
          {
            lower[d] = std::min(lower[d], triangulation.get_vertices()[v][d]);
            upper[d] = std::max(upper[d], triangulation.get_vertices()[v][d]);
          }
    double inverse_squares = 0;
    for (unsigned int d = 0; d < dim; ++d)
      inverse_squares +=
        std::pow(Utilities::MPI::max(upper[d], mpi_communicator) -
                   Utilities::MPI::min(lower[d], mpi_communicator),
                 -2);
    const double lumped_mass_constant =
      dof_handler.get_fe().reference_cell().is_simplex() ? 2 : 3;
    dual_norm_constant =
      lumped_mass_constant / (numbers::PI * std::sqrt(inverse_squares));
    double min_measure = std::numeric_limits<double>::max();
    for (const auto &a : action.vertices())
      min_measure = std::min(min_measure, a.dual_cell_measure);
    min_dual_cell_measure = Utilities::MPI::min(min_measure, mpi_communicator);
  }



  template <int dim>
  typename ActiveSetSolver<dim>::Scales
  ActiveSetSolver<dim>::scales(const DiscreteAction<dim> &action,
                               const VectorType &ghosted_solution) const
  {
    const double tiny = std::numeric_limits<double>::min();
    return {std::max(action.force_scale(), tiny),
            std::max(action.contact_force_scale(), tiny),
            std::max(ghosted_solution.linfty_norm(), tiny)};
  }



  template <int dim>
  std::vector<StatusChange>
  ActiveSetSolver<dim>::wanted_changes(const DiscreteAction<dim> &action,
                                       const VectorType &ghosted_solution,
                                       const IndexSet   &active_set) const
  {
    const double epsilon = parameters.tolerance;
    const double u_scale = scales(action, ghosted_solution).displacement;

    std::vector<StatusChange> changes;
    const auto               &vertices = action.vertices();
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const auto  &a = vertices[k];
        const double c =
          data.mu_bar * a.stiffness_diagonal / a.dual_cell_measure;
        const double violation =
          active_set.is_element(a.dof[0]) ?
            -action.lambda(k) / (c * u_scale) :
            -(ghosted_solution[a.dof[0]] - ghosted_solution[a.dof[1]]) /
              u_scale;
        if (violation > epsilon)
          changes.push_back({a.dof[0], violation / epsilon});
      }
    return changes;
  }



  template <int dim>
  std::vector<StatusChange>
  ActiveSetSolver<dim>::predicted_changes(
    DiscreteAction<dim>             &action,
    const VectorType                &solution,
    const IndexSet                  &active_set,
    const std::vector<StatusChange> &plain_changes) const
  {
    const double mu1 = data.mu[0], mu2 = data.mu[1], M = mu1 + mu2;
    const double epsilon = parameters.tolerance;
    const double u_scale =
      std::max(solution.linfty_norm(), std::numeric_limits<double>::min());
    const auto &vertices = action.vertices();

    // Projected Jacobi on W with S = μ1 U1 + μ2 U2 fixed: W_a moves to
    // max(0, W_a − r_a / (μ̄ ‖A_a‖₁ / 2)), r_a = λ_a d_a the force of the
    // obstacle problem at a and ‖A_a‖₁ the l1 norm of its row of the
    // condensed Laplacian; U1 moves by μ2/M and U2 by −μ1/M of the step.
    // The sweeps read and write the entries of the vertices (all locally
    // owned) in the local storage of the iterate, found once: the same
    // arithmetic as through operator[], without a search per access.
    VectorType                      iterate = solution;
    const auto                     &map     = iterate.trilinos_vector().Map();
    std::vector<std::array<int, 2>> local(vertices.size());
    for (unsigned int k = 0; k < vertices.size(); ++k)
      for (unsigned int i = 0; i < 2; ++i)
        local[k][i] = map.LID(static_cast<long long>(vertices[k].dof[i]));
    double *const values = iterate.trilinos_vector()[0];
    for (unsigned int sweep = 0; sweep < n_prediction_sweeps; ++sweep)
      {
        action.compute(iterate);
        for (unsigned int k = 0; k < vertices.size(); ++k)
          {
            const auto  &a = vertices[k];
            const double w = values[local[k][0]] - values[local[k][1]];
            const double r = action.lambda(k) * a.dual_cell_measure;
            const double step =
              std::max(0.,
                       w - 2 * r / (data.mu_bar * a.stiffness_row_l1_norm)) -
              w;
            values[local[k][0]] += mu2 / M * step;
            values[local[k][1]] -= mu1 / M * step;
          }
      }
    action.compute(iterate);

    // The test Λ_a − c_a W_a > 0 on the predicted iterate, with the band of
    // indifference; the plain test where the predicted one is in the band.
    std::vector<StatusChange> changes;
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const auto  &a = vertices[k];
        const double c =
          data.mu_bar * a.stiffness_diagonal / a.dual_cell_measure;
        const double test =
          (action.lambda(k) - c * (values[local[k][0]] - values[local[k][1]])) /
          (c * u_scale);
        const double violation = active_set.is_element(a.dof[0]) ? -test : test;
        if (violation > epsilon)
          changes.push_back({a.dof[0], violation / epsilon});
        else if (std::abs(test) <= epsilon)
          {
            // The prediction is indifferent here: the plain test decides.
            const auto plain =
              std::lower_bound(plain_changes.begin(),
                               plain_changes.end(),
                               a.dof[0],
                               [](const StatusChange           &change,
                                  const types::global_dof_index dof) {
                                 return change.dof < dof;
                               });
            if (plain != plain_changes.end() && plain->dof == a.dof[0])
              changes.push_back(*plain);
          }
      }
    return changes;
  }



  template <int dim>
  std::vector<StatusChange>
  ActiveSetSolver<dim>::next_changes(
    DiscreteAction<dim>             &action,
    const VectorType                &solution,
    const IndexSet                  &active_set,
    const std::vector<StatusChange> &changes) const
  {
    if (history.cycles() > 0)
      return changes;
    std::vector<StatusChange> predicted =
      predicted_changes(action, solution, active_set, changes);
    if (Utilities::MPI::sum(predicted.size(), mpi_communicator) == 0)
      return changes;
    return predicted;
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
    const double epsilon = parameters.tolerance;
    const double u_scale = std::max(ghosted_solution.linfty_norm(),
                                    std::numeric_limits<double>::min());

    IndexSet    active_set(dof_handler->n_dofs());
    const auto &vertices = action.vertices();
    for (const auto &a : vertices)
      {
        const double c =
          data.mu_bar * a.stiffness_diagonal / a.dual_cell_measure;
        const double lambda = ghosted_lambda_h[a.dof[0]] / (c * u_scale);
        const double w =
          (ghosted_solution[a.dof[0]] - ghosted_solution[a.dof[1]]) / u_scale;
        const bool degenerate =
          std::abs(lambda) <= epsilon && std::abs(w) <= epsilon;
        if (!degenerate && lambda - w > 0)
          active_set.add_index(a.dof[0]);
      }
    active_set.compress();
    return active_set;
  }



  template <int dim>
  double
  ActiveSetSolver<dim>::equilibrium_square(
    const DiscreteAction<dim>   &action,
    const unsigned int           k,
    const IndexSet              &active_set,
    const std::array<double, 3> &weights) const
  {
    const auto  &a  = action.vertices()[k];
    const double d  = a.dual_cell_measure;
    const double r1 = action.lambda_from_membrane(0, k) * d;
    const double r2 = action.lambda_from_membrane(1, k) * d;
    if (active_set.is_element(a.dof[0]))
      return weights[2] * (r1 - r2) * (r1 - r2);
    return weights[0] * r1 * r1 + weights[1] * r2 * r2;
  }



  template <int dim>
  double
  ActiveSetSolver<dim>::kkt_residual(const DiscreteAction<dim> &action,
                                     const VectorType &ghosted_solution,
                                     const IndexSet   &active_set) const
  {
    double sum_equilibrium = 0, contact_equilibrium = 0, primal = 0, dual = 0,
           complementarity = 0;
    const auto &vertices   = action.vertices();
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const auto  &a = vertices[k];
        const double d = a.dual_cell_measure;
        const double w =
          ghosted_solution[a.dof[0]] - ghosted_solution[a.dof[1]];
        const double contact_force = action.lambda(k) * d;
        sum_equilibrium            = std::max(sum_equilibrium,
                                   std::abs(action.lambda_from_membrane(0, k) -
                                            action.lambda_from_membrane(1, k)) *
                                     d);
        if (!active_set.is_element(a.dof[0]))
          contact_equilibrium =
            std::max(contact_equilibrium, std::abs(contact_force));
        primal = std::max(primal, -w);
        dual   = std::max(dual, -contact_force);
        complementarity =
          std::max(complementarity, std::abs(contact_force * w));
      }
    const Scales scale = scales(action, ghosted_solution);
    const auto   max   = [&](const double local) {
      return Utilities::MPI::max(local, mpi_communicator);
    };
    return std::max(
      {max(sum_equilibrium) / scale.force,
       max(contact_equilibrium) / scale.contact_force,
       max(primal) / scale.displacement,
       max(dual) / scale.contact_force,
       max(complementarity) / (scale.contact_force * scale.displacement)});
  }



  template <int dim>
  double
  ActiveSetSolver<dim>::linearization_estimate(
    const DiscreteAction<dim> &action,
    const VectorType          &ghosted_solution,
    const IndexSet            &active_set) const
  {
    double      energy   = 0;
    const auto &vertices = action.vertices();
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const auto  &a    = vertices[k];
        const double norm = a.stiffness_row_l1_norm;
        const double step =
          active_set.is_element(a.dof[0]) ?
            2 * std::max(-action.lambda(k), 0.) * a.dual_cell_measure /
              (data.mu_bar * norm) :
            std::max(ghosted_solution[a.dof[1]] - ghosted_solution[a.dof[0]],
                     0.);
        energy += data.mu_bar * norm * step * step;
      }
    return std::sqrt(Utilities::MPI::sum(energy, mpi_communicator));
  }



  template <int dim>
  double
  ActiveSetSolver<dim>::algebraic_estimate(const DiscreteAction<dim> &action,
                                           const IndexSet &active_set) const
  {
    const double mu1 = data.mu[0], mu2 = data.mu[1];
    double       sum      = 0;
    const auto  &vertices = action.vertices();
    for (unsigned int k = 0; k < vertices.size(); ++k)
      sum += equilibrium_square(action,
                                k,
                                active_set,
                                {{1 / mu1, 1 / mu2, 1 / (mu1 + mu2)}}) /
             vertices[k].dual_cell_measure;
    return dual_norm_constant *
           std::sqrt(Utilities::MPI::sum(sum, mpi_communicator));
  }



  template <int dim>
  typename ActiveSetSolver<dim>::Statistics
  ActiveSetSolver<dim>::solve(DiscreteAction<dim> &action,
                              VectorType          &solution,
                              IndexSet            &active_set,
                              const double         expected_error)
  {
    Statistics statistics;
    VectorType ghosted_solution(locally_owned_dofs,
                                locally_relevant_dofs,
                                mpi_communicator);
    {
      TimerOutput::Scope scope(timer, "solve");
      ghosted_solution = solution;
      action.compute(solution);
    }

    // The linear solves stop at the residuals that the KKT test allows,
    // on the force scales of the last iterate: a bound on the Euclidean
    // norm bounds every nodal residual, so an iterate on the right active
    // set meets the equilibrium, dual feasibility and complementarity
    // parts of the test (kkt_residual()) by construction. Once the active
    // set has settled but the test is not met, the residuals are made
    // `settled_tightening` times smaller. Balanced stopping allows an
    // algebraic error of γ η̃ / 2 in the energy norm.
    const bool balanced =
      parameters.stopping == Parameters::Stopping::balanced &&
      expected_error > 0;
    const double balance    = parameters.balance_fraction * expected_error;
    double       tightening = 1;
    const auto   linear_tolerances = [&]() {
      const double     allowed = parameters.tolerance / tightening;
      LinearTolerances tolerances{allowed * action.force_scale(),
                                  allowed * action.contact_force_scale()};
      if (balanced)
        {
          const double balanced_tolerance =
            balance / 2 * std::sqrt(data.mu_bar * min_dual_cell_measure) /
            dual_norm_constant;
          tolerances.sum     = std::max(tolerances.sum, balanced_tolerance);
          tolerances.contact = std::max(tolerances.contact, balanced_tolerance);
        }
      return tolerances;
    };
    system->prepare(solution, linear_tolerances(), statistics);

    history.restart(active_set);
    // The residual of the last iteration in which the active set did not
    // change: it has to decrease while the linear solves refine it.
    double settled_residual = std::numeric_limits<double>::infinity();
    for (unsigned int iteration = 1;; ++iteration)
      {
        const unsigned int linear_iterations = statistics.linear_iterations;
        system->solve(action,
                      locally_relevant_active_set(action, active_set),
                      solution,
                      linear_tolerances(),
                      statistics);

        TimerOutput::Scope scope(timer, "solve");
        ghosted_solution = solution;
        action.compute(solution);
        const std::vector<StatusChange> changes =
          wanted_changes(action, ghosted_solution, active_set);
        const auto n_changes =
          Utilities::MPI::sum<types::global_dof_index>(changes.size(),
                                                       mpi_communicator);
        statistics.kkt_residual =
          kkt_residual(action, ghosted_solution, active_set);
        statistics.iterations = iteration;
        if (balanced)
          {
            statistics.linearization_estimate =
              linearization_estimate(action, ghosted_solution, active_set);
            statistics.algebraic_estimate =
              algebraic_estimate(action, active_set);
          }

        pcout << "      active set iteration " << iteration << ": "
              << Utilities::MPI::sum(active_set.n_elements(), mpi_communicator)
              << " active vertices, " << n_changes
              << " to change, relative KKT residual " << statistics.kkt_residual
              << ", " << system->description() << " ("
              << statistics.linear_iterations - linear_iterations
              << " iterations)" << std::endl;
        if (balanced)
          pcout << "      balanced stopping: linearization "
                << *statistics.linearization_estimate << " + algebraic "
                << *statistics.algebraic_estimate << " vs gamma * expected "
                << balance << std::endl;
        if (balanced && (n_changes == 0 || *statistics.linearization_estimate +
                                               *statistics.algebraic_estimate <=
                                             balance))
          break;

        const std::string reached =
          "relative KKT residual " + format(statistics.kkt_residual) +
          " (Solver/Tolerance = " + format(parameters.tolerance) + ")";
        if (n_changes == 0)
          {
            if (statistics.kkt_residual <= parameters.tolerance)
              break;
            if (statistics.kkt_residual >= settled_residual)
              throw ActiveSetNotConverged(
                "the active set method stalls after " +
                std::to_string(iteration) +
                " iterations: the active set has settled, but the " + reached +
                " does not decrease any more (the accuracy of " +
                "the linear solver, " + system->description() + ", limits it)");
            // Solve again on the same active set, more accurately.
            settled_residual = statistics.kkt_residual;
            tightening *= settled_tightening;
            pcout << "      the active set has settled: solve again with "
                  << settled_tightening << " times smaller residuals"
                  << std::endl;
          }
        else
          settled_residual = std::numeric_limits<double>::infinity();

        if (iteration == parameters.max_active_set_iterations)
          throw ActiveSetNotConverged(
            "Solver/Max active set iterations = " + std::to_string(iteration) +
            " reached without convergence: " + reached + ", " +
            std::to_string(n_changes) + " vertices still to change");

        if (n_changes > 0)
          {
            const auto step =
              history.next(active_set,
                           next_changes(action, solution, active_set, changes));
            if (step.cycle_to)
              pcout << "      cycle: iteration " << iteration + 1
                    << " would repeat the active set of iteration "
                    << *step.cycle_to + 1 << "; " << step.changed << " of "
                    << step.wanted << " vertices change"
                    << (step.least_index_rule ?
                          " (Murty's least-index rule from now on)" :
                          " (the largest violations)")
                    << std::endl;
            active_set = step.active_set;
          }
      }
    // The matrices and the AMG hierarchy of this mesh are not needed any
    // more.
    system->clear();
    return statistics;
  }



  template class ActiveSetSolver<2>;
} // namespace membranes
