#include <membranes/cell_loop.h>
#include <membranes/cell_system.h>
#include <membranes/decoupled_system.h>

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
  DecoupledSystem<dim>::setup(const DiscreteProblem<dim> &problem,
                              const DoFHandler<dim>      &dof_handler,
                              const AffineConstraints<double> &,
                              const DoFHandler<dim> &scalar_dof_handler)
  {
    this->problem     = &problem;
    this->dof_handler = &dof_handler;
    const double mu1 = this->data.mu[0], mu2 = this->data.mu[1];
    problem.make_constraints(scalar_dof_handler, mu1, mu2, s_constraints);
    problem.make_constraints(scalar_dof_handler, 1, -1, w_constraints);
    this->linear_solver.reinit(scalar_dof_handler);

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
  DecoupledSystem<dim>::make_obstacle_matrix(const IndexSet &active_set)
  {
    // The constraints W_a = 0 of the active vertices (locally relevant)
    // merged with those of the mesh, condensed by distribute_local_to_global
    // as step-41 condenses its active set: the rows and columns of the
    // active vertices eliminated.
    const double              coefficient = this->data.mu_bar;
    AffineConstraints<double> constraints(
      this->problem->locally_relevant_scalar_dofs());
    for (const auto dof : active_set)
      constraints.add_line(dof / 2);
    constraints.merge(w_constraints,
                      AffineConstraints<double>::right_object_wins);
    constraints.close();

    struct CellMatrix
    {
      FullMatrix<double>                   matrix;
      std::vector<types::global_dof_index> dof_indices;
    };
    const FiniteElement<dim> &fe         = dof_handler->get_fe();
    const unsigned int        n_vertices = fe.base_element(0).n_dofs_per_cell();
    obstacle_matrix.reinit(this->problem->laplace_matrix());
    run_on_cells<CellMatrix>(
      *dof_handler,
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
        copy.dof_indices.resize(n_vertices);
        for (unsigned int v = 0; v < n_vertices; ++v)
          copy.dof_indices[v] =
            cell_system.dof_indices[fe.component_to_system_index(0, v)] / 2;
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
  DecoupledSystem<dim>::assemble(const IndexSet &active_set,
                                 VectorType     &solution)
  {
    // On the first iteration of a mesh: S and W of the initial guess.
    if (!s_solved)
      {
        const double  mu1 = this->data.mu[0], mu2 = this->data.mu[1];
        const double *u        = solution.begin();
        double *const s_values = s.begin(), *const w_values = w.begin();
        for (unsigned int p = 0; p < s.locally_owned_size(); ++p)
          {
            s_values[p] = mu1 * u[2 * p] + mu2 * u[2 * p + 1];
            w_values[p] = u[2 * p] - u[2 * p + 1];
          }
        s_constraints.distribute(s);
      }

    // The positions of the locally owned active vertices in the scalar
    // vectors (scalar DoF k = u1 DoF / 2); W = 0 there, and the right-hand
    // side too. The matrix of W is condensed anew when the direct solver
    // factorizes it or when the AMG hierarchy is built from it.
    const IndexSet &owned = s.locally_owned_elements();
    active_positions.clear();
    for (const auto dof : active_set)
      if (owned.is_element(dof / 2))
        active_positions.push_back(owned.index_within_set(dof / 2));
    rhs = w_rhs;
    for (const unsigned int p : active_positions)
      {
        rhs.begin()[p] = 0;
        w.begin()[p]   = 0;
      }
    w_constraints.distribute(w);
    if (this->linear_solver.is_direct() ||
        !this->linear_solver.has_preconditioner())
      make_obstacle_matrix(active_set);
  }



  template <int dim>
  void
  DecoupledSystem<dim>::solve_s(const double         tolerance,
                                ActiveSetStatistics &statistics)
  {
    const TrilinosWrappers::SparseMatrix &laplace_matrix =
      this->problem->laplace_matrix();
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
  DecoupledSystem<dim>::solve(VectorType             &solution,
                              const LinearTolerances &tolerances,
                              ActiveSetStatistics    &statistics)
  {
    if (!s_solved)
      solve_s(tolerances.sum, statistics);

    if (this->linear_solver.is_direct())
      this->linear_solver.solve_direct(obstacle_matrix, w, rhs);
    else
      {
        // CG on Π μ̄A Π + (I − Π), preconditioned by the hierarchy of the
        // matrix of W of the iteration that built it, restricted alike.
        const bool builds_hierarchy = !this->linear_solver.has_preconditioner();
        if (builds_hierarchy)
          this->linear_solver.initialize_preconditioner(obstacle_matrix);
        const RestrictedOperator<TrilinosWrappers::SparseMatrix> op(
          this->problem->laplace_matrix(),
          this->data.mu_bar,
          active_positions,
          rhs);
        const RestrictedOperator<TrilinosWrappers::PreconditionAMG>
                           preconditioner(this->linear_solver.preconditioner(),
                         1.,
                         active_positions,
                         rhs);
        const unsigned int iterations = this->linear_solver.solve_cg(
          op, preconditioner, w, rhs, tolerances.contact);
        statistics.linear_iterations += iterations;
        if (builds_hierarchy)
          hierarchy_iterations = iterations;
        else if (iterations > 2 * hierarchy_iterations + rebuild_slack)
          this->linear_solver.clear();
      }
    w_constraints.distribute(w);

    const double        mu1 = this->data.mu[0], mu2 = this->data.mu[1];
    const double        M        = mu1 + mu2;
    const double *const s_values = s.begin(), *const w_values = w.begin();
    double *const u = solution.begin();
    for (unsigned int p = 0; p < s.locally_owned_size(); ++p)
      {
        u[2 * p]     = (s_values[p] + mu2 * w_values[p]) / M;
        u[2 * p + 1] = (s_values[p] - mu1 * w_values[p]) / M;
      }
  }



  template <int dim>
  void
  DecoupledSystem<dim>::clear()
  {
    this->linear_solver.clear();
    obstacle_matrix.clear();
    active_positions = {};
    for (VectorType *vector : {&s_rhs, &w_rhs, &s, &w, &rhs})
      vector->clear();
    s_constraints.clear();
    w_constraints.clear();
  }



  template class DecoupledSystem<2>;
} // namespace membranes
