#include <deal.II/lac/linear_operator.h>
#include <membranes/active_set/decoupled_system.h>
#include <membranes/mesh/cell_loop.h>
#include <membranes/mesh/cell_system.h>

namespace membranes
{
  template <int dim>
  DecoupledSystem<dim>::DecoupledSystem(
    const Parameters::Solver  &parameters,
    const Discretization<dim> &discretization,
    const ProblemData<dim>    &data,
    const MPI_Comm             mpi_communicator)
    : ActiveSetSystem<dim>("decoupled",
                           parameters,
                           discretization,
                           data,
                           mpi_communicator)
    , s_solved(false)
    , hierarchy_iterations(0)
  {}



  template <int dim>
  void
  DecoupledSystem<dim>::setup(
    const DiscreteProblem<dim>      &problem,
    const DoFHandler<dim>           &dof_handler,
    const AffineConstraints<double> &hanging_node_constraints)
  {
    const double mu1 = this->data.mu[0], mu2 = this->data.mu[1];
    problem.make_constraints(
      dof_handler, hanging_node_constraints, mu1, mu2, s_constraints);
    problem.make_constraints(
      dof_handler, hanging_node_constraints, 1, -1, w_constraints);
    // The constants are the near null space of the Laplacian.
    this->linear_solver.reinit(
      dof_handler.n_dofs(),
      {std::vector<bool>(problem.locally_owned_dofs().n_elements(), true)});

    // The right-hand sides of S and W: the loads lifted by the boundary
    // values of each membrane combine into those lifted by the boundary
    // values of S and W, the lifting being linear in both.
    s_rhs = problem.lifted_loads(0);
    s_rhs += problem.lifted_loads(1);
    w_rhs.reinit(s_rhs);
    w_rhs.add(mu2 / (mu1 + mu2),
              problem.lifted_loads(0),
              -mu1 / (mu1 + mu2),
              problem.lifted_loads(1));
    s.reinit(s_rhs);
    w.reinit(s_rhs);
    s_solved = false;
  }



  template <int dim>
  void
  DecoupledSystem<dim>::make_obstacle_matrix(
    const DiscreteProblem<dim> &problem,
    const DoFHandler<dim>      &dof_handler,
    const IndexSet             &active_set)
  {
    // The constraints W_a = 0 of the active vertices (locally relevant)
    // merged with those of the mesh, condensed by distribute_local_to_global
    // as step-41 condenses its active set: the rows and columns of the
    // active vertices eliminated.
    const double              coefficient = this->data.mu_bar;
    AffineConstraints<double> constraints(problem.locally_relevant_dofs());
    for (const auto dof : active_set)
      constraints.add_line(dof);
    constraints.merge(w_constraints,
                      AffineConstraints<double>::right_object_wins);
    constraints.close();

    struct CellMatrix
    {
      FullMatrix<double>                   matrix;
      std::vector<types::global_dof_index> dof_indices;
    };
    obstacle_matrix.reinit(problem.laplace_matrix());
    run_on_cells<CellMatrix>(
      dof_handler,
      [&]() {
        return std::make_unique<CellSystem<dim>>(this->discretization,
                                                 this->data);
      },
      [&](const auto &cell, CellSystem<dim> &cell_system, CellMatrix &copy) {
        copy.dof_indices.clear();
        if (!cell->is_locally_owned())
          return;
        cell_system.reinit_operator(cell);
        copy.matrix = cell_system.laplace_matrix;
        copy.matrix *= coefficient;
        copy.dof_indices = cell_system.dof_indices;
      },
      [&](const CellMatrix &copy) {
        if (!copy.dof_indices.empty())
          constraints.distribute_local_to_global(copy.matrix,
                                                 copy.dof_indices,
                                                 obstacle_matrix);
      });
    obstacle_matrix.compress(VectorOperation::add);
  }



  template <int dim>
  void
  DecoupledSystem<dim>::assemble(const DiscreteProblem<dim> &problem,
                                 const DoFHandler<dim>      &dof_handler,
                                 const IndexSet             &active_set,
                                 BlockVectorType            &solution)
  {
    // On the first iteration of a mesh: S and W of the initial guess.
    if (!s_solved)
      {
        s.equ(this->data.mu[0], solution.block(0));
        s.add(this->data.mu[1], solution.block(1));
        w.equ(1., solution.block(0));
        w.add(-1., solution.block(1));
        s_constraints.distribute(s);
      }

    // Π, 1 at the inactive vertices and 0 at the active ones, and I − Π, as
    // diagonal matrices; W = 0 at the active vertices, and the right-hand
    // side too. The matrix of W is condensed anew when the direct solver
    // factorizes it or when the AMG hierarchy is built from it.
    VectorType &inactive = inactive_projection.get_vector();
    VectorType &active   = active_projection.get_vector();
    inactive.reinit(w, true);
    active.reinit(w, true);
    inactive = 1;
    active   = 0;
    for (const auto dof : active_set)
      if (inactive.in_local_range(dof))
        {
          inactive[dof] = 0;
          active[dof]   = 1;
        }
    inactive.compress(VectorOperation::insert);
    active.compress(VectorOperation::insert);
    rhs = w_rhs;
    rhs.scale(inactive);
    w.scale(inactive);
    w_constraints.distribute(w);
    if (this->linear_solver.is_direct() ||
        !this->linear_solver.has_preconditioner())
      make_obstacle_matrix(problem, dof_handler, active_set);
  }



  template <int dim>
  void
  DecoupledSystem<dim>::solve_s(const DiscreteProblem<dim> &problem,
                                const double                tolerance,
                                ActiveSetStatistics        &statistics)
  {
    const TrilinosWrappers::SparseMatrix &laplace_matrix =
      problem.laplace_matrix();
    if (this->linear_solver.is_direct())
      this->linear_solver.solve_direct(laplace_matrix, s, s_rhs);
    else
      {
        this->linear_solver.initialize_preconditioner(laplace_matrix);
        statistics.linear_iterations +=
          this->linear_solver.solve_cg(laplace_matrix,
                                       this->linear_solver.preconditioner(),
                                       s,
                                       s_rhs,
                                       tolerance);
        this->linear_solver.clear();
      }
    s_constraints.distribute(s);
    s_solved = true;
  }



  template <int dim>
  void
  DecoupledSystem<dim>::solve(const DiscreteProblem<dim> &problem,
                              BlockVectorType            &solution,
                              const LinearTolerances     &tolerances,
                              ActiveSetStatistics        &statistics)
  {
    if (!s_solved)
      solve_s(problem, tolerances.sum, statistics);

    if (this->linear_solver.is_direct())
      this->linear_solver.solve_direct(obstacle_matrix, w, rhs);
    else
      {
        // CG on Π μ̄A Π + (I − Π), preconditioned by Π P Π + (I − Π), P the
        // hierarchy of the matrix of W (μ̄ included) of the iteration that
        // built it.
        const bool builds_hierarchy = !this->linear_solver.has_preconditioner();
        if (builds_hierarchy)
          this->linear_solver.initialize_preconditioner(obstacle_matrix);
        const auto &A  = problem.laplace_matrix();
        const auto  Pi = linear_operator<VectorType>(A, inactive_projection);
        const auto  I_minus_Pi =
          linear_operator<VectorType>(A, active_projection);
        const auto op =
          Pi * (this->data.mu_bar * linear_operator<VectorType>(A)) * Pi +
          I_minus_Pi;
        const auto amg =
          linear_operator<VectorType>(A, this->linear_solver.preconditioner());
        const unsigned int iterations = this->linear_solver.solve_cg(
          op, Pi * amg * Pi + I_minus_Pi, w, rhs, tolerances.contact);
        statistics.linear_iterations += iterations;
        if (builds_hierarchy)
          hierarchy_iterations = iterations;
        else if (iterations > 2 * hierarchy_iterations + rebuild_slack)
          this->linear_solver.clear();
      }
    w_constraints.distribute(w);

    // U1 = (S + μ2 W)/M and U2 = (S − μ1 W)/M, entry by entry: S, W and
    // both blocks of the solution have the layout of the mesh's vectors.
    const double        mu1 = this->data.mu[0], mu2 = this->data.mu[1];
    const double        M        = mu1 + mu2;
    const double *const s_values = s.begin(), *const w_values = w.begin();
    double *const u1 = solution.block(0).begin();
    double *const u2 = solution.block(1).begin();
    for (unsigned int p = 0; p < s.locally_owned_size(); ++p)
      {
        u1[p] = (s_values[p] + mu2 * w_values[p]) / M;
        u2[p] = (s_values[p] - mu1 * w_values[p]) / M;
      }
  }



  template <int dim>
  void
  DecoupledSystem<dim>::clear()
  {
    this->linear_solver.clear();
    obstacle_matrix.clear();
    for (VectorType *vector : {&s_rhs,
                               &w_rhs,
                               &s,
                               &w,
                               &rhs,
                               &inactive_projection.get_vector(),
                               &active_projection.get_vector()})
      vector->clear();
    s_constraints.clear();
    w_constraints.clear();
  }



  template class DecoupledSystem<2>;
} // namespace membranes
