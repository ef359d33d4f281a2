#include <algorithm>
#include <deal.II/base/mpi.h>
#include <membranes/dual_mesh/discrete_action.h>

namespace membranes
{
  template <int dim>
  DiscreteAction<dim>::DiscreteAction(const ProblemData<dim> &data)
    : data(data)
    , max_force(0)
    , max_contact_force(0)
  {}



  template <int dim>
  void
  DiscreteAction<dim>::reinit(const DiscreteProblem<dim> &problem)
  {
    for (auto &vector : stiffness_terms)
      vector.reinit(problem.locally_owned_dofs(),
                    problem.get_mpi_communicator());
  }



  template <int dim>
  void
  DiscreteAction<dim>::compute(const DiscreteProblem<dim> &problem,
                               const BlockVectorType      &solution)
  {
    Assert(!solution.has_ghost_elements(),
           ExcMessage("DiscreteAction::compute() reads the locally owned "
                      "DoFs of the solution by position (see "
                      "DiscreteProblem::local_positions())."));
    // The stiffness term of (4.5) at every DoF, μ_i ∫ ∇u_ih·∇φ: μ_i times
    // the product of A with the nodal values U_i of membrane i, block i of
    // the solution (those of hanging nodes follow from their parents, whose
    // columns hold the condensed couplings), plus the columns of ∂ω: the
    // loads minus the lifted loads, μ_i Σ_{b ∈ ∂ω} A_ab g_i(b).
    for (unsigned int i = 0; i < 2; ++i)
      {
        problem.laplace_matrix().vmult(stiffness_terms[i], solution.block(i));
        stiffness_terms[i] *= data.mu[i];
        stiffness_terms[i].add(1.,
                               problem.loads(i),
                               -1.,
                               problem.lifted_loads(i));
      }

    // The size of the terms that (4.5) balances at a: the stiffness term
    // μ_i ∫ ∇u_ih·∇φ_a is a sum whose largest part is the diagonal one,
    // μ_i ∫|∇φ_a|² |u_ih(a)|; on fine meshes it cancels down to O(h²) and
    // its rounding error is relative to that diagonal part. Likewise for
    // the terms of the obstacle problem for w, whose combination
    // (μ2 · membrane 1 + μ1 · membrane 2)/(μ1 + μ2) carries the rounding
    // error of forces of tension μ̄.
    // In the same pass, λ_a of both formulas, which the active set method
    // reads many times per iteration.
    const auto  &vertices  = problem.vertices();
    const auto  &positions = problem.local_positions();
    const double mu1 = data.mu[0], mu2 = data.mu[1], M = mu1 + mu2;
    double       local_max = 0, local_contact_max = 0;
    std::array<const double *, 2> values, terms, load_values;
    for (unsigned int i = 0; i < 2; ++i)
      {
        values[i]      = solution.block(i).begin();
        terms[i]       = stiffness_terms[i].begin();
        load_values[i] = problem.loads(i).begin();
      }
    membrane_lambdas.resize(vertices.size());
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const Vertex         &a = vertices[k];
        const unsigned int    p = positions[k];
        std::array<double, 2> stiffness, loads;
        for (unsigned int i = 0; i < 2; ++i)
          {
            stiffness[i] = terms[i][p];
            loads[i]     = load_values[i][p];
          }
        for (unsigned int i = 0; i < 2; ++i)
          membrane_lambdas[k][i] = (i == 0 ? 1. : -1.) *
                                   (stiffness[i] - loads[i]) /
                                   a.dual_cell_measure;
        for (unsigned int i = 0; i < 2; ++i)
          local_max = std::max(
            {local_max,
             std::abs(stiffness[i]),
             std::abs(loads[i]),
             data.mu[i] * a.stiffness_diagonal * std::abs(values[i][p])});
        local_contact_max = std::max(
          {local_contact_max,
           std::abs(mu2 * stiffness[0] - mu1 * stiffness[1]) / M,
           std::abs(mu2 * loads[0] - mu1 * loads[1]) / M,
           data.mu_bar * a.stiffness_diagonal *
             std::max(std::abs(values[0][p]), std::abs(values[1][p]))});
      }
    const MPI_Comm mpi_communicator = problem.get_mpi_communicator();
    max_force = Utilities::MPI::max(local_max, mpi_communicator);
    max_contact_force =
      Utilities::MPI::max(local_contact_max, mpi_communicator);
  }



  template <int dim>
  typename DiscreteAction<dim>::VectorType
  DiscreteAction<dim>::lambda_h(
    const DiscreteProblem<dim>      &problem,
    const AffineConstraints<double> &hanging_node_constraints) const
  {
    const auto &vertices = problem.vertices();
    VectorType  nodal_values(problem.locally_owned_dofs(),
                            problem.get_mpi_communicator());
    for (unsigned int k = 0; k < vertices.size(); ++k)
      nodal_values[vertices[k].dof] = lambda(k);
    nodal_values.compress(VectorOperation::insert);
    hanging_node_constraints.distribute(nodal_values);
    VectorType ghosted(problem.locally_owned_dofs(),
                       problem.locally_relevant_dofs(),
                       problem.get_mpi_communicator());
    ghosted = nodal_values;
    return ghosted;
  }



  template <int dim>
  double
  DiscreteAction<dim>::lambda_from_membrane(const unsigned int i,
                                            const unsigned int k) const
  {
    return membrane_lambdas[k][i];
  }



  template <int dim>
  double
  DiscreteAction<dim>::stiffness_term(const DiscreteProblem<dim> &problem,
                                      const unsigned int          i,
                                      const unsigned int          k) const
  {
    return stiffness_terms[i].begin()[problem.local_positions()[k]];
  }



  template <int dim>
  double
  DiscreteAction<dim>::load_term(const DiscreteProblem<dim> &problem,
                                 const unsigned int          i,
                                 const unsigned int          k) const
  {
    return problem.loads(i).begin()[problem.local_positions()[k]];
  }



  template <int dim>
  double
  DiscreteAction<dim>::lambda(const unsigned int k) const
  {
    return (data.mu[1] * lambda_from_membrane(0, k) +
            data.mu[0] * lambda_from_membrane(1, k)) /
           (data.mu[0] + data.mu[1]);
  }



  template <int dim>
  double
  DiscreteAction<dim>::force_scale() const
  {
    return max_force;
  }



  template <int dim>
  double
  DiscreteAction<dim>::contact_force_scale() const
  {
    return max_contact_force;
  }



  template class DiscreteAction<2>;
} // namespace membranes
