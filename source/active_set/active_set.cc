#include <algorithm>
#include <array>
#include <cmath>
#include <deal.II/base/mpi.h>
#include <deal.II/lac/trilinos_vector.h>
#include <limits>
#include <membranes/active_set/active_set.h>

namespace membranes
{
  ActiveSetHistory::ActiveSetHistory(const MPI_Comm mpi_communicator)
    : mpi_communicator(mpi_communicator)
    , n_cycles(0)
    , least_index_rule(false)
  {}



  void
  ActiveSetHistory::restart(const IndexSet &initial_active_set)
  {
    visited          = {fingerprint(initial_active_set)};
    n_cycles         = 0;
    least_index_rule = false;
  }



  std::uint64_t
  ActiveSetHistory::fingerprint(const IndexSet &set) const
  {
    // splitmix64's finalizer: a 64-bit hash of each DoF, summed modulo 2^64
    // (unsigned arithmetic), so that the sum depends on the set only.
    std::uint64_t sum = 0;
    for (const auto dof : set)
      {
        std::uint64_t x = dof + 0x9e3779b97f4a7c15ull;
        x               = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
        x               = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
        sum += x ^ (x >> 31);
      }
    return Utilities::MPI::sum(sum, mpi_communicator);
  }



  std::optional<unsigned int>
  ActiveSetHistory::find(const IndexSet &set) const
  {
    const auto position =
      std::find(visited.begin(), visited.end(), fingerprint(set));
    if (position == visited.end())
      return std::nullopt;
    return position - visited.begin();
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
    visited.push_back(fingerprint(step.active_set));
    return step;
  }



  unsigned int
  ActiveSetHistory::cycles() const
  {
    return n_cycles;
  }



  IndexSet
  ActiveSetHistory::toggled(const IndexSet                             &set,
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



  template <int dim>
  ActiveSet<dim>::ActiveSet(const Parameters::Solver &parameters,
                            const ProblemData<dim>   &data,
                            const MPI_Comm            mpi_communicator)
    : parameters(parameters)
    , data(data)
    , mpi_communicator(mpi_communicator)
    , history(mpi_communicator)
  {}



  template <int dim>
  void
  ActiveSet<dim>::reinit(const DiscreteProblem<dim> &discrete_problem)
  {
    active_flags.assign(discrete_problem.vertices().size(), false);
    partitioner = std::make_shared<Utilities::MPI::Partitioner>(
      discrete_problem.locally_owned_dofs(),
      discrete_problem.locally_relevant_dofs(),
      mpi_communicator);
  }



  template <int dim>
  void
  ActiveSet<dim>::reinit(const DiscreteProblem<dim> &discrete_problem,
                         const BlockVectorType      &solution,
                         const VectorType           &ghosted_lambda_h)
  {
    reinit(discrete_problem);
    const double epsilon  = parameters.tolerance;
    const double u_scale  = displacement_scale(solution);
    const auto  &vertices = discrete_problem.vertices();
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const double lambda = ghosted_lambda_h[vertices[k].dof];
        const double w      = discrete_problem.nodal_w(k, solution);
        const bool   degenerate =
          std::abs(lambda / (contact_stiffness(vertices[k]) * u_scale)) <=
            epsilon &&
          std::abs(w / u_scale) <= epsilon;
        active_flags[k] =
          !degenerate && violation(discrete_problem, k, lambda, w, u_scale) > 0;
      }
  }



  template <int dim>
  IndexSet
  ActiveSet<dim>::locally_owned(const DiscreteProblem<dim> &problem) const
  {
    std::vector<types::global_dof_index> dofs;
    for (unsigned int k = 0; k < active_flags.size(); ++k)
      if (active_flags[k])
        dofs.push_back(problem.vertices()[k].dof);
    IndexSet set(problem.locally_owned_dofs().size());
    set.add_indices(dofs.begin(), dofs.end());
    set.compress();
    return set;
  }



  template <int dim>
  types::global_dof_index
  ActiveSet<dim>::n_active_vertices() const
  {
    return Utilities::MPI::sum<types::global_dof_index>(
      std::count(active_flags.begin(), active_flags.end(), true),
      mpi_communicator);
  }



  template <int dim>
  IndexSet
  ActiveSet<dim>::locally_relevant(const DiscreteProblem<dim> &problem) const
  {
    // The owners' flags at the ghost DoFs, through the partitioner of the
    // mesh.
    std::vector<double> owned(partitioner->locally_owned_size(), 0.),
      ghosts(partitioner->n_ghost_indices()),
      buffer(partitioner->n_import_indices());
    const auto &positions = problem.local_positions();
    for (unsigned int k = 0; k < active_flags.size(); ++k)
      owned[positions[k]] = active_flags[k];
    std::vector<MPI_Request> requests;
    partitioner->export_to_ghosted_array_start<double>(0,
                                                       make_array_view(
                                                         std::as_const(owned)),
                                                       make_array_view(buffer),
                                                       make_array_view(ghosts),
                                                       requests);
    partitioner->export_to_ghosted_array_finish<double>(make_array_view(ghosts),
                                                        requests);

    IndexSet relevant_active_set(problem.locally_owned_dofs().size());
    for (const auto dof : problem.locally_relevant_vertices())
      {
        const unsigned int p = partitioner->global_to_local(dof);
        if ((p < owned.size() ? owned[p] : ghosts[p - owned.size()]) > 0)
          relevant_active_set.add_index(dof);
      }
    relevant_active_set.compress();
    return relevant_active_set;
  }



  template <int dim>
  double
  ActiveSet<dim>::contact_stiffness(const Vertex &a) const
  {
    return data.mu_bar * a.stiffness_diagonal / a.dual_cell_measure;
  }



  template <int dim>
  std::vector<StatusChange>
  ActiveSet<dim>::wanted_changes(const DiscreteProblem<dim> &problem,
                                 const DiscreteAction<dim>  &action,
                                 const BlockVectorType      &solution) const
  {
    const double epsilon = parameters.tolerance;
    const double u_scale = displacement_scale(solution);

    // After a solve W_a = 0 on A and λ_a = 0 off A (up to the residual of
    // the linear solver): the test reads λ_a on A and W_a off A.
    std::vector<StatusChange> changes;
    const auto               &vertices = problem.vertices();
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const double v =
          is_active(k) ?
            violation(problem, k, action.lambda(k), 0, u_scale) :
            violation(problem, k, 0, problem.nodal_w(k, solution), u_scale);
        if (v > epsilon)
          changes.push_back({vertices[k].dof, v / epsilon});
      }
    return changes;
  }



  template <int dim>
  double
  ActiveSet<dim>::violation(const DiscreteProblem<dim> &problem,
                            const unsigned int          k,
                            const double                lambda,
                            const double                w,
                            const double                u_scale) const
  {
    const double c    = contact_stiffness(problem.vertices()[k]);
    const double test = (lambda - c * w) / (c * u_scale);
    return is_active(k) ? -test : test;
  }



  template <int dim>
  void
  ActiveSet<dim>::restart(const DiscreteProblem<dim> &problem)
  {
    history.restart(locally_owned(problem));
  }



  template <int dim>
  ActiveSetHistory::Step
  ActiveSet<dim>::update(const DiscreteProblem<dim>      &problem,
                         const std::vector<StatusChange> &changes)
  {
    const ActiveSetHistory::Step step =
      history.next(locally_owned(problem), changes);
    // step.active_set and the vertices are both sorted by the DoF.
    const auto &vertices = problem.vertices();
    auto        active   = step.active_set.begin();
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        active_flags[k] =
          (active != step.active_set.end() && *active == vertices[k].dof);
        if (active_flags[k])
          ++active;
      }
    return step;
  }



  template <int dim>
  unsigned int
  ActiveSet<dim>::cycles() const
  {
    return history.cycles();
  }



  template class ActiveSet<2>;
} // namespace membranes
