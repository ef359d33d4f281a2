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



  double
  KKTDefects::relative_residual(const double force_scale,
                                const double contact_force_scale,
                                const double displacement_scale) const
  {
    return std::max(
      {sum_equilibrium / force_scale,
       contact_equilibrium / contact_force_scale,
       std::max(0., -min_w) / displacement_scale,
       std::max(0., -min_contact_force) / contact_force_scale,
       complementarity / (contact_force_scale * displacement_scale)});
  }



  double
  displacement_scale(const TrilinosWrappers::MPI::BlockVector &solution)
  {
    return std::max(solution.linfty_norm(), std::numeric_limits<double>::min());
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
    active_vertices = IndexSet(discrete_problem.locally_owned_dofs().size());
    active_flags.assign(discrete_problem.vertices().size(), false);
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
        const auto  &a      = vertices[k];
        const double c      = contact_stiffness(a);
        const double lambda = ghosted_lambda_h[a.dof] / (c * u_scale);
        const double w      = discrete_problem.nodal_w(k, solution) / u_scale;
        const bool   degenerate =
          std::abs(lambda) <= epsilon && std::abs(w) <= epsilon;
        if (!degenerate && lambda - w > 0)
          active_vertices.add_index(a.dof);
      }
    active_vertices.compress();
    set_flags(discrete_problem);
  }



  template <int dim>
  void
  ActiveSet<dim>::set_flags(const DiscreteProblem<dim> &problem)
  {
    // Both are sorted by the DoF.
    const auto &vertices = problem.vertices();
    auto        active   = active_vertices.begin();
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        active_flags[k] =
          (active != active_vertices.end() && *active == vertices[k].dof);
        if (active_flags[k])
          ++active;
      }
  }



  template <int dim>
  const IndexSet &
  ActiveSet<dim>::locally_owned() const
  {
    return active_vertices;
  }



  template <int dim>
  types::global_dof_index
  ActiveSet<dim>::n_active_vertices() const
  {
    return Utilities::MPI::sum(active_vertices.n_elements(), mpi_communicator);
  }



  template <int dim>
  IndexSet
  ActiveSet<dim>::locally_relevant(const DiscreteProblem<dim> &problem) const
  {
    VectorType owned_flags(problem.locally_owned_dofs(), mpi_communicator);
    for (const auto dof : active_vertices)
      owned_flags[dof] = 1;
    owned_flags.compress(VectorOperation::insert);
    VectorType flags(problem.locally_owned_dofs(),
                     problem.locally_relevant_dofs(),
                     mpi_communicator);
    flags = owned_flags;

    IndexSet relevant_active_set(active_vertices.size());
    for (const auto dof : problem.locally_relevant_vertices())
      if (flags[dof] > 0)
        relevant_active_set.add_index(dof);
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
  KKTDefects
  ActiveSet<dim>::kkt_defects(const DiscreteProblem<dim> &problem,
                              const DiscreteAction<dim>  &action,
                              const BlockVectorType      &solution) const
  {
    const double max = std::numeric_limits<double>::max();
    KKTDefects   defects{0, 0, max, max, max, 0};
    const auto  &vertices = problem.vertices();
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const auto  &a             = vertices[k];
        const double d             = a.dual_cell_measure;
        const double w             = problem.nodal_w(k, solution);
        const double lambda        = action.lambda(k);
        const double contact_force = lambda * d;
        defects.sum_equilibrium =
          std::max(defects.sum_equilibrium,
                   std::abs(action.lambda_from_membrane(0, k) -
                            action.lambda_from_membrane(1, k)) *
                     d);
        if (!is_active(k))
          defects.contact_equilibrium =
            std::max(defects.contact_equilibrium, std::abs(contact_force));
        defects.min_w      = std::min(defects.min_w, w);
        defects.min_lambda = std::min(defects.min_lambda, lambda);
        defects.min_contact_force =
          std::min(defects.min_contact_force, contact_force);
        defects.complementarity =
          std::max(defects.complementarity, std::abs(contact_force * w));
      }
    for (double *maximum : {&defects.sum_equilibrium,
                            &defects.contact_equilibrium,
                            &defects.complementarity})
      *maximum = Utilities::MPI::max(*maximum, mpi_communicator);
    for (double *minimum :
         {&defects.min_w, &defects.min_lambda, &defects.min_contact_force})
      *minimum = Utilities::MPI::min(*minimum, mpi_communicator);
    return defects;
  }



  template <int dim>
  std::vector<StatusChange>
  ActiveSet<dim>::wanted_changes(const DiscreteProblem<dim> &problem,
                                 const DiscreteAction<dim>  &action,
                                 const BlockVectorType      &solution) const
  {
    const double epsilon = parameters.tolerance;
    const double u_scale = displacement_scale(solution);

    std::vector<StatusChange> changes;
    const auto               &vertices = problem.vertices();
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const auto  &a = vertices[k];
        const double violation =
          is_active(k) ? -action.lambda(k) / (contact_stiffness(a) * u_scale) :
                         -problem.nodal_w(k, solution) / u_scale;
        if (violation > epsilon)
          changes.push_back({a.dof, violation / epsilon});
      }
    return changes;
  }



  template <int dim>
  void
  ActiveSet<dim>::restart()
  {
    history.restart(active_vertices);
  }



  template <int dim>
  ActiveSetHistory::Step
  ActiveSet<dim>::update(const DiscreteProblem<dim>      &problem,
                         const std::vector<StatusChange> &changes)
  {
    const ActiveSetHistory::Step step = history.next(active_vertices, changes);
    active_vertices                   = step.active_set;
    set_flags(problem);
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
