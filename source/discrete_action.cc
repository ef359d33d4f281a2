#include <algorithm>
#include <deal.II/base/mpi.h>
#include <deal.II/fe/fe_values.h>
#include <membranes/discrete_action.h>

namespace membranes
{
  template <int dim>
  DiscreteAction<dim>::DiscreteAction(const Discretization<dim> &discretization,
                                      const ProblemData<dim>    &data)
    : discretization(discretization)
    , data(data)
    , dual_cell_quadrature(discretization.fe->reference_cell(), 2)
    , lambda_h_vector(nullptr)
    , max_force(0)
    , max_contact_force(0)
  {}



  template <int dim>
  void
  DiscreteAction<dim>::reinit(const MeshOperator<dim> &mesh_operator)
  {
    mesh = &mesh_operator;
    stiffness_product.reinit(mesh_operator.locally_owned_dofs(),
                             mesh_operator.get_mpi_communicator());
  }



  template <int dim>
  void
  DiscreteAction<dim>::compute(const VectorType &solution)
  {
    // The two terms of (4.5) at every DoF: μ_i ∫ ∇u_ih·∇φ as the product of
    // the operator with the nodal values (those of hanging nodes follow
    // from their parents, whose columns hold the condensed couplings), and
    // the loads ∫ f_i φ of this mesh.
    mesh->stiffness_matrix().vmult(stiffness_product, solution);

    // The size of the terms that (4.5) balances at a: the stiffness term
    // μ_i ∫ ∇u_ih·∇φ_a is a sum whose largest part is the diagonal one,
    // μ_i ∫|∇φ_a|² |u_ih(a)|; on fine meshes it cancels down to O(h²) and
    // its rounding error is relative to that diagonal part. Likewise for
    // the terms of the obstacle problem for w, whose combination
    // (μ2 · membrane 1 + μ1 · membrane 2)/(μ1 + μ2) carries the rounding
    // error of forces of tension μ̄.
    // The vectors of the locally owned DoFs, read at local_positions.
    const double *const products = stiffness_product.begin();
    const double *const loads    = mesh->load_vector().begin();
    const double *const values   = solution.begin();
    const auto         &vertices = mesh->vertices();
    const double        mu1 = data.mu[0], mu2 = data.mu[1], M = mu1 + mu2;
    double              local_max = 0, local_contact_max = 0;
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const Vertex &a        = vertices[k];
        const auto   &position = mesh->local_positions()[k];
        for (unsigned int i = 0; i < 2; ++i)
          local_max = std::max({local_max,
                                std::abs(products[position[i]]),
                                std::abs(loads[position[i]]),
                                data.mu[i] * a.stiffness_diagonal *
                                  std::abs(values[position[i]])});
        local_contact_max = std::max(
          {local_contact_max,
           std::abs(mu2 * products[position[0]] - mu1 * products[position[1]]) /
             M,
           std::abs(mu2 * loads[position[0]] - mu1 * loads[position[1]]) / M,
           data.mu_bar * a.stiffness_diagonal *
             std::max(std::abs(values[position[0]]),
                      std::abs(values[position[1]]))});
      }
    const MPI_Comm mpi_communicator = mesh->get_mpi_communicator();
    max_force = Utilities::MPI::max(local_max, mpi_communicator);
    max_contact_force =
      Utilities::MPI::max(local_contact_max, mpi_communicator);
  }



  template <int dim>
  std::pair<double, double>
  DiscreteAction<dim>::load_mean_and_oscillation(
    const typename DoFHandler<dim>::active_cell_iterator &cell,
    const unsigned int                                    i) const
  {
    return mesh->load_mean_and_oscillation(cell, i);
  }



  template <int dim>
  const std::vector<typename DiscreteAction<dim>::Vertex> &
  DiscreteAction<dim>::vertices() const
  {
    return mesh->vertices();
  }



  template <int dim>
  void
  DiscreteAction<dim>::fill_nodal_vector(VectorType &lambda_h) const
  {
    lambda_h = 0;
    for (unsigned int k = 0; k < vertices().size(); ++k)
      for (const auto dof : vertices()[k].dof)
        lambda_h[dof] = lambda(k);
    lambda_h.compress(VectorOperation::insert);
  }



  template <int dim>
  double
  DiscreteAction<dim>::lambda_from_membrane(const unsigned int i,
                                            const unsigned int k) const
  {
    const double sign = (i == 0 ? 1. : -1.);
    return sign * (stiffness_term(i, k) - load_term(i, k)) /
           vertices()[k].dual_cell_measure;
  }



  template <int dim>
  double
  DiscreteAction<dim>::stiffness_term(const unsigned int i,
                                      const unsigned int k) const
  {
    return stiffness_product.begin()[mesh->local_positions()[k][i]];
  }



  template <int dim>
  double
  DiscreteAction<dim>::load_term(const unsigned int i,
                                 const unsigned int k) const
  {
    return mesh->load_vector().begin()[mesh->local_positions()[k][i]];
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



  template <int dim>
  void
  DiscreteAction<dim>::set_lambda_h(const VectorType &lambda_h)
  {
    lambda_h_vector = &lambda_h;
  }



  template <int dim>
  const DualCellQuadrature<dim> &
  DiscreteAction<dim>::dual_quadrature() const
  {
    return dual_cell_quadrature;
  }



  template <int dim>
  double
  DiscreteAction<dim>::lambda_h_value(
    const typename DoFHandler<dim>::active_cell_iterator &cell,
    const unsigned int                                    v) const
  {
    return lambda_h_at_vertex(cell->vertex_dof_index(v, 0));
  }



  template <int dim>
  double
  DiscreteAction<dim>::lambda_h_at_vertex(const types::global_dof_index a) const
  {
    return mesh->is_interior_vertex(a) ? (*lambda_h_vector)[a] : 0.;
  }



  template <int dim>
  void
  DiscreteAction<dim>::lambda_h_values(
    const typename DoFHandler<dim>::active_cell_iterator &cell,
    std::vector<double>                                  &values,
    std::vector<bool>                                    *in_omega_h) const
  {
    // λ_h is constant on the pieces of each vertex: look it up once per
    // vertex, not once per point.
    std::array<double, GeometryInfo<dim>::vertices_per_cell> vertex_values;
    std::array<bool, GeometryInfo<dim>::vertices_per_cell>   vertex_in_omega_h;
    for (const unsigned int v : cell->vertex_indices())
      {
        vertex_values[v] = lambda_h_value(cell, v);
        vertex_in_omega_h[v] =
          mesh->is_interior_vertex(cell->vertex_dof_index(v, 0));
      }
    values.resize(dual_cell_quadrature.quadrature().size());
    if (in_omega_h)
      in_omega_h->resize(values.size());
    for (unsigned int q = 0; q < values.size(); ++q)
      {
        const unsigned int v = dual_cell_quadrature.vertex_of_point(q);
        values[q]            = vertex_values[v];
        if (in_omega_h)
          (*in_omega_h)[q] = vertex_in_omega_h[v];
      }
  }



  template <int dim>
  void
  DiscreteAction<dim>::nodal_lambda_values(const FEValues<dim> &fe_values,
                                           std::vector<double> &values) const
  {
    values.resize(fe_values.n_quadrature_points);
    fe_values[FEValuesExtractors::Scalar(0)].get_function_values(
      *lambda_h_vector, values);
  }



  template class DiscreteAction<2>;
} // namespace membranes
