#include <algorithm>
#include <membranes/active_set/active_set_prediction.h>

namespace membranes
{
  template <int dim>
  ActiveSetPrediction<dim>::ActiveSetPrediction(
    const Parameters::Solver &parameters,
    const ProblemData<dim>   &data)
    : parameters(parameters)
    , data(data)
    , predicted_action(data)
  {}



  template <int dim>
  void
  ActiveSetPrediction<dim>::reinit(const DiscreteProblem<dim> &problem)
  {
    predicted_action.reinit(problem);
    const double        mu1 = data.mu[0], mu2 = data.mu[1], M = mu1 + mu2;
    const double *const lifted_1  = problem.lifted_loads(0).begin();
    const double *const lifted_2  = problem.lifted_loads(1).begin();
    const auto         &vertices  = problem.vertices();
    const auto         &positions = problem.local_positions();
    w_load.resize(vertices.size());
    sweep_step.resize(vertices.size());
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const unsigned int p = positions[k];
        w_load[k]            = (mu2 * lifted_1[p] - mu1 * lifted_2[p]) / M;
        sweep_step[k] = 2 / (data.mu_bar * vertices[k].stiffness_row_l1_norm);
      }
  }



  template <int dim>
  std::vector<StatusChange>
  ActiveSetPrediction<dim>::changes(
    const DiscreteProblem<dim>      &problem,
    const ActiveSet<dim>            &active_set,
    const BlockVectorType           &solution,
    const std::vector<StatusChange> &plain_changes)
  {
    const double mu1 = data.mu[0], mu2 = data.mu[1], M = mu1 + mu2;
    const double epsilon   = parameters.tolerance;
    const double u_scale   = displacement_scale(solution);
    const auto  &vertices  = problem.vertices();
    const auto  &positions = problem.local_positions();

    // Projected Jacobi on W with S = μ1 U1 + μ2 U2 fixed: W_a moves to
    // max(0, W_a − r_a / (μ̄ ‖A_a‖₁ / 2)), r_a = λ_a d_a the force of the
    // obstacle problem at a and ‖A_a‖₁ the l1 norm of its row of the
    // condensed Laplacian. With S fixed, r_a = μ̄ (A W)_a − b_a, b the
    // lifted loads of W, (μ2 L_1 − μ1 L_2)/M (DecoupledSystem; w_load and
    // sweep_step from reinit()): one product with A on the scalar W per
    // sweep, on contiguous local arrays. The
    // predicted iterate is U1 = (S + μ2 W)/M, U2 = (S − μ1 W)/M.
    VectorType w(solution.block(0));
    w -= solution.block(1);
    VectorType          stiffness_w(w);
    double *const       w_values = w.begin();
    const double *const product  = stiffness_w.begin();
    for (unsigned int sweep = 0; sweep < n_prediction_sweeps; ++sweep)
      {
        problem.laplace_matrix().vmult(stiffness_w, w);
        for (unsigned int k = 0; k < vertices.size(); ++k)
          {
            const unsigned int p = positions[k];
            const double       r = data.mu_bar * product[p] - w_load[k];
            w_values[p] = std::max(0., w_values[p] - r * sweep_step[k]);
          }
      }
    BlockVectorType iterate;
    iterate.reinit(solution, true);
    for (unsigned int i = 0; i < 2; ++i)
      {
        iterate.block(i).equ(mu1 / M, solution.block(0));
        iterate.block(i).add(mu2 / M, solution.block(1));
        iterate.block(i).add(i == 0 ? mu2 / M : -mu1 / M, w);
      }
    predicted_action.compute(problem, iterate);

    // The test Λ_a − c_a W_a > 0 on the predicted iterate, with the band of
    // indifference; the plain test where the predicted one is in the band.
    std::vector<StatusChange> changes;
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const auto  &a = vertices[k];
        const double violation =
          active_set.violation(problem,
                               k,
                               predicted_action.lambda(k),
                               problem.nodal_w(k, iterate),
                               u_scale);
        if (violation > epsilon)
          changes.push_back({a.dof, violation / epsilon});
        else if (std::abs(violation) <= epsilon)
          {
            // The prediction is indifferent here: the plain test decides.
            const auto plain =
              std::lower_bound(plain_changes.begin(),
                               plain_changes.end(),
                               a.dof,
                               [](const StatusChange           &change,
                                  const types::global_dof_index dof) {
                                 return change.dof < dof;
                               });
            if (plain != plain_changes.end() && plain->dof == a.dof)
              changes.push_back(*plain);
          }
      }
    return changes;
  }



  template <int dim>
  std::array<double, 2>
  ActiveSetPrediction<dim>::force_scales() const
  {
    return {
      {predicted_action.force_scale(), predicted_action.contact_force_scale()}};
  }



  template class ActiveSetPrediction<2>;
} // namespace membranes
