#include <deal.II/base/timer.h>
#include <deal.II/dofs/dof_tools.h>
#include <membranes/decoupled_system.h>
#include <tuple>

namespace membranes
{
  namespace
  {
    /** The scalar function c1 g + c2 g2 of the boundary values (g, g2). */
    template <int dim>
    std::unique_ptr<Function<dim>>
    combine_boundary_values(const ProblemData<dim> &data,
                            const double            c1,
                            const double            c2)
    {
      return std::make_unique<ScalarFunctionFromFunctionObject<dim>>(
        [&data, c1, c2](const Point<dim> &p) {
          return c1 * data.boundary_values().value(p, 0) +
                 c2 * data.boundary_values().value(p, 1);
        });
    }



    /** The cell of @p dof_handler that is the mesh cell @p cell. */
    template <int dim>
    typename DoFHandler<dim>::active_cell_iterator
    cell_of(const DoFHandler<dim>                            &dof_handler,
            const typename Triangulation<dim>::cell_iterator &cell)
    {
      return {&dof_handler.get_triangulation(),
              cell->level(),
              cell->index(),
              &dof_handler};
    }
  } // namespace



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
    , sum_boundary_values(combine_boundary_values(data, data.mu[0], data.mu[1]))
    , difference_boundary_values(combine_boundary_values(data, 1., -1.))
  {}



  template <int dim>
  void
  DecoupledSystem<dim>::setup(const DoFHandler<dim> &dof_handler,
                              const IndexSet &,
                              const IndexSet &locally_relevant_dofs,
                              const DiscreteAction<dim> &)
  {
    this->dof_handler           = &dof_handler;
    this->locally_relevant_dofs = locally_relevant_dofs;
    scalar_dof_handler.reinit(dof_handler.get_triangulation());
    scalar_dof_handler.distribute_dofs(
      this->discretization.fe->base_element(0));
    locally_owned_scalar_dofs = scalar_dof_handler.locally_owned_dofs();
    DoFTools::extract_locally_relevant_dofs(scalar_dof_handler,
                                            locally_relevant_scalar_dofs);

    // Shape function v of the scalar element and shape function
    // component_to_system_index(i, v) of the FESystem belong to the same
    // vertex of a cell.
    const FiniteElement<dim>            &fe = *this->discretization.fe;
    std::vector<types::global_dof_index> dof_indices(fe.n_dofs_per_cell());
    std::vector<types::global_dof_index> scalar_dof_indices(
      fe.base_element(0).n_dofs_per_cell());
    membrane_dofs.resize(locally_owned_scalar_dofs.n_elements());
    scalar_dof.resize(locally_relevant_dofs.n_elements());
    for (const auto &scalar_cell : scalar_dof_handler.active_cell_iterators())
      if (!scalar_cell->is_artificial())
        {
          scalar_cell->get_dof_indices(scalar_dof_indices);
          cell_of(dof_handler, scalar_cell)->get_dof_indices(dof_indices);
          for (unsigned int v = 0; v < scalar_dof_indices.size(); ++v)
            for (unsigned int i = 0; i < 2; ++i)
              {
                const auto k = scalar_dof_indices[v];
                const auto dof =
                  dof_indices[fe.component_to_system_index(i, v)];
                if (locally_owned_scalar_dofs.is_element(k))
                  membrane_dofs[locally_owned_scalar_dofs.index_within_set(k)]
                               [i] = dof;
                scalar_dof[locally_relevant_dofs.index_within_set(dof)] = k;
              }
        }

    // W = 0 on active vertices has no entries: the pattern of S, with
    // the hanging node and boundary constraints, holds the matrix of W for
    // every active set.
    make_constraints(*sum_boundary_values,
                     IndexSet(dof_handler.n_dofs()),
                     sum_constraints);
    this->reinit_linear_system(scalar_dof_handler,
                               sum_constraints,
                               locally_owned_scalar_dofs,
                               locally_relevant_scalar_dofs);
    sum.reinit(locally_owned_scalar_dofs, this->mpi_communicator);
    difference.reinit(locally_owned_scalar_dofs, this->mpi_communicator);
  }



  template <int dim>
  void
  DecoupledSystem<dim>::make_constraints(
    const Function<dim>       &boundary_values,
    const IndexSet            &active_set,
    AffineConstraints<double> &constraints) const
  {
    constraints.clear();
    constraints.reinit(locally_relevant_scalar_dofs);
    DoFTools::make_hanging_node_constraints(scalar_dof_handler, constraints);

    for (const auto dof : active_set)
      constraints.add_line(
        scalar_dof[locally_relevant_dofs.index_within_set(dof)]);

    this->add_boundary_values(scalar_dof_handler, boundary_values, constraints);
    constraints.close();
  }



  template <int dim>
  void
  DecoupledSystem<dim>::assemble_scalar_system(
    const AffineConstraints<double> &constraints,
    const double                     coefficient,
    const std::array<double, 2>     &load_weights)
  {
    const unsigned int n =
      this->discretization.fe->base_element(0).n_dofs_per_cell();
    FullMatrix<double>                   cell_matrix(n, n);
    Vector<double>                       cell_rhs(n);
    std::vector<types::global_dof_index> scalar_dof_indices(n);
    this->assemble_system(
      *dof_handler,
      constraints,
      [&](const auto &cell, const CellSystem<dim> &cell_system) {
        cell_matrix.equ(coefficient, cell_system.laplace_matrix);
        cell_rhs.equ(load_weights[0], cell_system.loads[0]);
        cell_rhs.add(load_weights[1], cell_system.loads[1]);
        cell_of(scalar_dof_handler, cell)->get_dof_indices(scalar_dof_indices);
        return std::tie(cell_matrix, cell_rhs, scalar_dof_indices);
      });
  }



  template <int dim>
  void
  DecoupledSystem<dim>::prepare(const VectorType    &solution,
                                const double         tolerance,
                                ActiveSetStatistics &statistics)
  {
    Timer        timer;
    const double mu1 = this->data.mu[0], mu2 = this->data.mu[1];
    for (unsigned int j = 0; j < membrane_dofs.size(); ++j)
      {
        const auto   k  = locally_owned_scalar_dofs.nth_index_in_set(j);
        const double u1 = solution[membrane_dofs[j][0]];
        const double u2 = solution[membrane_dofs[j][1]];
        sum[k]          = mu1 * u1 + mu2 * u2;
        difference[k]   = u1 - u2;
      }
    sum.compress(VectorOperation::insert);
    difference.compress(VectorOperation::insert);

    sum_constraints.distribute(sum);
    assemble_scalar_system(sum_constraints, 1., {{1., 1.}});
    statistics.assembly_time += timer.wall_time();

    this->solve_linear_system(sum_constraints, sum, tolerance, statistics);
  }



  template <int dim>
  void
  DecoupledSystem<dim>::solve(const DiscreteAction<dim> &,
                              const IndexSet      &active_set,
                              VectorType          &solution,
                              const double         tolerance,
                              ActiveSetStatistics &statistics)
  {
    Timer        timer;
    const double mu1 = this->data.mu[0], mu2 = this->data.mu[1];
    const double M = mu1 + mu2;
    make_constraints(*difference_boundary_values,
                     active_set,
                     difference_constraints);
    difference_constraints.distribute(difference);
    assemble_scalar_system(difference_constraints,
                           this->data.mu_bar,
                           {{mu2 / M, -mu1 / M}});
    statistics.assembly_time += timer.wall_time();

    this->solve_linear_system(difference_constraints,
                              difference,
                              tolerance,
                              statistics);

    timer.restart();
    for (unsigned int j = 0; j < membrane_dofs.size(); ++j)
      {
        const auto k = locally_owned_scalar_dofs.nth_index_in_set(j);
        solution[membrane_dofs[j][0]] = (sum[k] + mu2 * difference[k]) / M;
        solution[membrane_dofs[j][1]] = (sum[k] - mu1 * difference[k]) / M;
      }
    solution.compress(VectorOperation::insert);
    statistics.solve_time += timer.wall_time();
  }



  template class DecoupledSystem<2>;
} // namespace membranes
