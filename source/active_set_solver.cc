#include <algorithm>
#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/numerics/vector_tools.h>
#include <limits>
#include <map>
#include <membranes/active_set_solver.h>
#include <membranes/cell_system.h>

namespace membranes
{
  template <int dim>
  ActiveSetSolver<dim>::ActiveSetSolver(
    const Parameters::Solver  &parameters,
    const Discretization<dim> &discretization,
    const ProblemData<dim>    &data,
    const ConditionalOStream  &pcout,
    const MPI_Comm             mpi_communicator)
    : parameters(parameters)
    , discretization(discretization)
    , data(data)
    , pcout(pcout)
    , mpi_communicator(mpi_communicator)
    , linear_solver(parameters.linear_solver, mpi_communicator)
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
    linear_solver.reinit(dof_handler);

    // The contact constraint u1(a) = u2(a) only ever couples DoFs of
    // vertices that share a cell, so the full coupling of all DoFs of a
    // cell (condensed with the hanging node constraints) holds the matrix
    // of every active set. Boundary rows are constrained for good.
    make_constraints(action, IndexSet(dof_handler.n_dofs()));
    DynamicSparsityPattern dsp(locally_relevant_dofs);
    DoFTools::make_sparsity_pattern(dof_handler, dsp, constraints, false);
    SparsityTools::distribute_sparsity_pattern(dsp,
                                               locally_owned_dofs,
                                               mpi_communicator,
                                               locally_relevant_dofs);
    system_matrix.reinit(locally_owned_dofs,
                         locally_owned_dofs,
                         dsp,
                         mpi_communicator);
    system_rhs.reinit(locally_owned_dofs, mpi_communicator);
  }



  template <int dim>
  void
  ActiveSetSolver<dim>::make_constraints(const DiscreteAction<dim> &action,
                                         const IndexSet            &active_set)
  {
    constraints.clear();
    constraints.reinit(locally_relevant_dofs);
    DoFTools::make_hanging_node_constraints(*dof_handler, constraints);

    for (const auto &a : action.vertices())
      if (active_set.is_element(a.dof[0]))
        {
          constraints.add_line(a.dof[0]);
          constraints.add_entry(a.dof[0], a.dof[1], 1.0);
        }

    std::map<types::boundary_id, const Function<dim> *> boundary_functions;
    for (const auto id : dof_handler->get_triangulation().get_boundary_ids())
      boundary_functions[id] = &data.boundary_values();
    VectorTools::interpolate_boundary_values(*discretization.mapping,
                                             *dof_handler,
                                             boundary_functions,
                                             constraints);
    constraints.close();
  }



  template <int dim>
  void
  ActiveSetSolver<dim>::assemble_system()
  {
    system_matrix = 0;
    system_rhs    = 0;

    CellSystem<dim> cell_system(discretization, data);
    for (const auto &cell : dof_handler->active_cell_iterators())
      if (cell->is_locally_owned())
        {
          cell_system.reinit(cell);
          constraints.distribute_local_to_global(cell_system.matrix,
                                                 cell_system.rhs,
                                                 cell_system.dof_indices,
                                                 system_matrix,
                                                 system_rhs);
        }
    system_matrix.compress(VectorOperation::add);
    system_rhs.compress(VectorOperation::add);
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

    for (unsigned int iteration = 1;; ++iteration)
      {
        timer.restart();
        make_constraints(action, active_set);
        constraints.distribute(solution);
        assemble_system();
        statistics.assembly_time += timer.wall_time();

        // The forces of the last iterate set the scale of the linear
        // solver's residual: a hundredth of what the KKT test allows.
        timer.restart();
        const double linear_tolerance =
          1e-2 * parameters.tolerance * action.force_scale_l2();
        statistics.linear_iterations += linear_solver.solve(system_matrix,
                                                            solution,
                                                            system_rhs,
                                                            linear_tolerance);
        constraints.distribute(solution);

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
              << statistics.kkt_residual << ", " << linear_solver.method()
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
