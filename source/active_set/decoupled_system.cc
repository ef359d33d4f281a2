#include <deal.II/lac/linear_operator.h>
#include <membranes/active_set/decoupled_system.h>

namespace membranes
{
  template <int dim>
  DecoupledSystem<dim>::DecoupledSystem(const Parameters::Solver &parameters,
                                        const ProblemData<dim>   &data,
                                        const MPI_Comm mpi_communicator)
    : ActiveSetSystem<dim>("decoupled", parameters, data, mpi_communicator)
    , s_solved(false)
    , hierarchy_iterations(0)
  {}



  template <int dim>
  void
  DecoupledSystem<dim>::setup(const DiscreteProblem<dim> &problem,
                              const DoFHandler<dim> &)
  {
    // The constants are the near null space of the Laplacian.
    this->linear_solver.reinit(
      problem.laplace_matrix().m(),
      {std::vector<bool>(problem.locally_owned_dofs().n_elements(), true)});
    s.reinit(problem.loads(0));
    w.reinit(problem.loads(0));
    s_solved = false;
  }



  template <int dim>
  void
  DecoupledSystem<dim>::make_obstacle_matrix(
    const DiscreteProblem<dim> &problem,
    const IndexSet             &active_set)
  {
    // μ̄ A with the rows and columns of the active vertices eliminated, as
    // AffineConstraints condenses the lines W_a = 0 in a cell loop (step-41):
    // zero off the diagonal, and on it the sum μ̄ Σ_K A_K(a, a) = μ̄ ∫|∇φ_a|²
    // of the cell matrices. A is condensed with the hanging node and
    // boundary constraints already, so that eliminating the active rows
    // and columns from it gives that matrix without a cell matrix.
    const double mu_bar = this->data.mu_bar;
    obstacle_matrix.copy_from(problem.laplace_matrix());
    obstacle_matrix *= mu_bar;
    const auto eliminate =
      [mu_bar](const typename ActiveSetSystem<dim>::MatrixRow &row) {
        for (int e = 0; e < row.n_entries; ++e)
          if (row.active || row.active_column(e))
            row.values[e] =
              (row.column(e) == row.dof) ? mu_bar * row.stiffness_diagonal : 0;
      };
    this->for_each_row(problem, obstacle_matrix, active_set, eliminate);
  }



  template <int dim>
  void
  DecoupledSystem<dim>::set_active_set(const DiscreteProblem<dim> &problem,
                                       const IndexSet             &active_set)
  {
    // Π, 1 at the inactive vertices and 0 at the active ones, and I − Π, as
    // diagonal matrices. The matrix of W is made anew when the direct solver
    // factorizes it or when the AMG hierarchy is built from it.
    VectorType &inactive = inactive_projection.get_vector();
    VectorType &active   = active_projection.get_vector();
    inactive.reinit(problem.loads(0), true);
    active.reinit(problem.loads(0), true);
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
    if (this->linear_solver.is_direct() ||
        !this->linear_solver.has_preconditioner())
      make_obstacle_matrix(problem, active_set);
  }



  template <int dim>
  void
  DecoupledSystem<dim>::solve_s(const DiscreteProblem<dim> &problem,
                                const BlockVectorType      &solution,
                                const double                tolerance,
                                ActiveSetStatistics        &statistics)
  {
    // A S = F_1 + F_2 with the lifted loads, from S = μ1 U1 + μ2 U2 of the
    // initial guess, its constrained entries zero as the solution's are.
    VectorType rhs(problem.lifted_loads(0));
    rhs += problem.lifted_loads(1);
    s.equ(this->data.mu[0], solution.block(0));
    s.add(this->data.mu[1], solution.block(1));
    problem.constraints(0).set_zero(s);
    const TrilinosWrappers::SparseMatrix &laplace_matrix =
      problem.laplace_matrix();
    if (this->linear_solver.is_direct())
      this->linear_solver.solve_direct(laplace_matrix, s, rhs);
    else
      {
        this->linear_solver.initialize_preconditioner(laplace_matrix);
        statistics.linear_iterations +=
          this->linear_solver.solve_cg(laplace_matrix,
                                       this->linear_solver.preconditioner(),
                                       s,
                                       rhs,
                                       tolerance);
        this->linear_solver.clear();
      }
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
      solve_s(problem, solution, tolerances.sum, statistics);

    // The obstacle problem for W: from W = U1 − U2 of the iterate, zero at
    // the active vertices and at the constrained DoFs, with the right-hand
    // side (μ2 F_1 − μ1 F_2)/M of the lifted loads, zero at the active
    // vertices (the lifting being linear in the boundary values of both
    // membranes, it is that by the boundary values g − g2 of W).
    const double mu1 = this->data.mu[0], mu2 = this->data.mu[1];
    const double M = mu1 + mu2;
    VectorType   rhs(problem.lifted_loads(0));
    rhs.sadd(mu2 / M, -mu1 / M, problem.lifted_loads(1));
    rhs.scale(inactive_projection.get_vector());
    w.equ(1., solution.block(0));
    w.add(-1., solution.block(1));
    w.scale(inactive_projection.get_vector());
    problem.constraints(0).set_zero(w);
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

    // U1 = (S + μ2 W)/M and U2 = (S − μ1 W)/M at the unconstrained DoFs,
    // entry by entry (S, W and both blocks of the solution have the layout
    // of the mesh's vectors), and the constraints of each membrane.
    const double *const s_values = s.begin(), *const w_values = w.begin();
    double *const u1 = solution.block(0).begin();
    double *const u2 = solution.block(1).begin();
    for (unsigned int p = 0; p < s.locally_owned_size(); ++p)
      {
        u1[p] = (s_values[p] + mu2 * w_values[p]) / M;
        u2[p] = (s_values[p] - mu1 * w_values[p]) / M;
      }
    for (unsigned int i = 0; i < 2; ++i)
      problem.constraints(i).distribute(solution.block(i));
  }



  template <int dim>
  void
  DecoupledSystem<dim>::clear()
  {
    this->linear_solver.clear();
    obstacle_matrix.clear();
    for (VectorType *vector : {&s,
                               &w,
                               &inactive_projection.get_vector(),
                               &active_projection.get_vector()})
      vector->clear();
  }



  template class DecoupledSystem<2>;
} // namespace membranes
