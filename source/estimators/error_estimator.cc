#include <array>
#include <cmath>
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/fe/fe_interface_values.h>
#include <deal.II/fe/fe_values.h>
#include <membranes/estimators/error_estimator.h>
#include <membranes/flux/flux_equilibration.h>
#include <membranes/mesh/cell_loop.h>

namespace membranes
{
  template <int dim>
  ErrorEstimator<dim>::ErrorEstimator(const Discretization<dim> &discretization,
                                      const ProblemData<dim>    &data)
    : discretization(discretization)
    , data(data)
  {}



  template <int dim>
  double
  ErrorEstimator<dim>::residual_estimate(
    const DoFHandler<dim>      &dof_handler,
    const BlockVectorType      &ghosted_solution,
    const DiscreteProblem<dim> &problem,
    const DualMesh<dim>        &dual_mesh,
    const VectorType           &lambda_h,
    Vector<double>             &indicators,
    const MPI_Comm              mpi_communicator) const
  {
    indicators.reinit(dof_handler.get_triangulation().n_active_cells());
    add_cell_terms(
      dof_handler, ghosted_solution, problem, dual_mesh, lambda_h, indicators);
    add_jump_terms(dof_handler, ghosted_solution, indicators);

    double local_sum = 0;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        local_sum += indicators[cell->active_cell_index()];
      else
        indicators[cell->active_cell_index()] = 0;
    return std::sqrt(Utilities::MPI::sum(local_sum, mpi_communicator));
  }



  /**
   * What one thread needs on a cell: u_ih, ∇u_ih, Δu_ih (zero unless
   * computed), σ_ih, div σ_ih and λ̃_h at the quadrature points of the
   * pieces K ∩ D_a.
   */
  template <int dim>
  struct ErrorEstimator<dim>::CellScratch
  {
    CellScratch(const Discretization<dim> &discretization,
                const DualMesh<dim>       &dual_mesh,
                const VectorType          &lambda_h,
                const UpdateFlags          flags)
      : values(discretization, dual_mesh, lambda_h, flags)
    {
      for (unsigned int i = 0; i < 2; ++i)
        {
          u[i].resize(values.fe_values.n_quadrature_points);
          grad_u[i].resize(values.fe_values.n_quadrature_points);
          laplacian[i].assign(values.fe_values.n_quadrature_points, 0.0);
        }
    }

    DualCellValues<dim>                        values;
    std::array<std::vector<double>, 2>         u, laplacian;
    std::array<std::vector<Tensor<1, dim>>, 2> grad_u;
    std::vector<Tensor<1, dim>>                flux;
    std::vector<double>                        divergence, lambda;
  };



  template <int dim>
  void
  ErrorEstimator<dim>::add_cell_terms(const DoFHandler<dim> &dof_handler,
                                      const BlockVectorType &ghosted_solution,
                                      const DiscreteProblem<dim> &problem,
                                      const DualMesh<dim>        &dual_mesh,
                                      const VectorType           &lambda_h,
                                      Vector<double> &indicators) const
  {
    // λ_h and u_h on the pieces K ∩ D_a. The Laplacian of u_ih vanishes on
    // triangles (P1) and on axis-parallel rectangles (Q1: a bilinear
    // function has no ∂²/∂x², ∂²/∂y²), not on other quadrilaterals.
    const bool with_laplacians =
      !discretization.fe->reference_cell().is_simplex() &&
      !discretization.rectangles();
    const std::array<double, 2> sign{{1., -1.}};

    // Each cell adds to its own indicator only: nothing to copy.
    struct NoCopy
    {};
    run_on_cells<NoCopy>(
      dof_handler,
      [&]() {
        return std::make_unique<CellScratch>(discretization,
                                             dual_mesh,
                                             lambda_h,
                                             update_values | update_JxW_values |
                                               (with_laplacians ?
                                                  update_hessians :
                                                  update_default));
      },
      [&](const auto &cell, CellScratch &scratch, NoCopy &) {
        if (!cell->is_locally_owned())
          return;
        scratch.values.reinit(cell, ghosted_solution);
        const FEValues<dim>       &fe_values = scratch.values.fe_values;
        const std::vector<double> &lambda    = scratch.values.lambda_h;

        const double                     h_K     = cell->diameter();
        double                           eta2    = 0;
        double                           contact = 0;
        const FEValuesExtractors::Scalar scalar(0);
        for (unsigned int i = 0; i < 2; ++i)
          {
            fe_values[scalar].get_function_values_from_local_dof_values(
              scratch.values.local_dofs[i], scratch.u[i]);
            if (with_laplacians)
              fe_values[scalar].get_function_laplacians_from_local_dof_values(
                scratch.values.local_dofs[i], scratch.laplacian[i]);

            // f_ih = f̄_iK and ‖f_i − f_ih‖²_K, on the quadrature of the
            // assembly.
            const auto [f_mean, oscillation] =
              problem.load_mean_and_oscillation(cell, i);

            double residual = 0;
            for (const unsigned int q : fe_values.quadrature_point_indices())
              residual += std::pow(f_mean + sign[i] * lambda[q] +
                                     data.mu[i] * scratch.laplacian[i][q],
                                   2) *
                          fe_values.JxW(q);
            eta2 += (h_K * h_K * residual +
                     std::pow(h_K / numbers::PI, 2) * oscillation) /
                    data.mu[i];
          }
        for (const unsigned int q : fe_values.quadrature_point_indices())
          contact +=
            lambda[q] * (scratch.u[0][q] - scratch.u[1][q]) * fe_values.JxW(q);
        indicators[cell->active_cell_index()] +=
          eta2 + 2 * std::max(contact, 0.);
      },
      [](const NoCopy &) {});
  }



  /**
   * What one thread needs on an edge between quadrilaterals: the two traces
   * of the gradient of each membrane on the edge, with matching points,
   * from the nodal values of the cell (side 0) and of its neighbour
   * (side 1).
   */
  template <int dim>
  struct ErrorEstimator<dim>::JumpScratch
  {
    JumpScratch(const Discretization<dim> &discretization)
    {
      const FiniteElement<dim> &fe = *discretization.fe;
      for (auto &membrane_values : local_dofs)
        for (auto &values : membrane_values)
          values.resize(fe.n_dofs_per_cell());
      if (!fe.reference_cell().is_simplex())
        interface_values =
          std::make_unique<FEInterfaceValues<dim>>(*discretization.mapping,
                                                   fe,
                                                   QGauss<dim - 1>(2),
                                                   update_gradients |
                                                     update_JxW_values |
                                                     update_normal_vectors);
    }

    std::unique_ptr<FEInterfaceValues<dim>> interface_values;
    /** traces[i][side]: ∇u_ih at the points of the edge. */
    std::array<std::array<std::vector<Tensor<1, dim>>, 2>, 2> traces;
    /** local_dofs[i][side]: the nodal values of u_ih on that cell. */
    std::array<std::array<std::vector<double>, 2>, 2> local_dofs;
  };



  template <int dim>
  void
  ErrorEstimator<dim>::add_jump_terms(const DoFHandler<dim> &dof_handler,
                                      const BlockVectorType &ghosted_solution,
                                      Vector<double>        &indicators) const
  {
    const bool simplex = discretization.fe->reference_cell().is_simplex();
    const std::vector<std::array<Tensor<1, dim>, 2>> cell_gradients =
      simplex ? p1_gradients(dof_handler, ghosted_solution) :
                std::vector<std::array<Tensor<1, dim>, 2>>();

    // Every interior edge once, from its finer side (or from the cell with
    // the smaller index between cells of the same level); half of the
    // term goes to each of the two cells, in the copier. (This is what
    // MeshWorker::mesh_loop with assemble_own_interior_faces_once does.
    // On P1 the jumps of the constant gradients of the cells, computed once
    // per cell by p1_gradients(), need no FEInterfaceValues, which is
    // slower there (benchmarks/choices.md, "The face terms of the residual
    // estimator");
    // and on triangles with hanging nodes deal.II 9.4 stops in
    // QProjector::DataSetDescriptor::subface, which knows quadrilaterals
    // only.) Ghost cells take
    // part, so that an edge between an owned and a ghost cell counts
    // whichever side computes it (ghost cells' indicators are dropped
    // later).
    struct EdgeTerm
    {
      unsigned int cell, neighbor;
      double       term;
    };
    using EdgeTerms = std::vector<EdgeTerm>;
    run_on_cells<EdgeTerms>(
      dof_handler,
      [&]() { return std::make_unique<JumpScratch>(discretization); },
      [&](const CellIterator &cell, JumpScratch &scratch, EdgeTerms &terms) {
        terms.clear();
        if (cell->is_artificial())
          return;
        for (const unsigned int f : cell->face_indices())
          {
            if (cell->at_boundary(f))
              continue;
            const auto &neighbor = cell->neighbor(f);
            if (neighbor->has_children() || neighbor->is_artificial() ||
                (!cell->neighbor_is_coarser(f) &&
                 neighbor->active_cell_index() < cell->active_cell_index()))
              continue;
            const auto integrals =
              simplex ? p1_jump_integrals(cell, f, cell_gradients) :
                        q1_jump_integrals(cell, f, ghosted_solution, scratch);
            terms.push_back(
              {cell->active_cell_index(),
               neighbor->active_cell_index(),
               0.5 * cell->face(f)->measure() *
                 (integrals[0] / data.mu[0] + integrals[1] / data.mu[1])});
          }
      },
      [&](const EdgeTerms &terms) {
        for (const auto &[cell, neighbor, term] : terms)
          {
            indicators[cell] += term;
            indicators[neighbor] += term;
          }
      });
  }



  template <int dim>
  std::vector<std::array<Tensor<1, dim>, 2>>
  ErrorEstimator<dim>::p1_gradients(
    const DoFHandler<dim> &dof_handler,
    const BlockVectorType &ghosted_solution) const
  {
    std::vector<std::array<Tensor<1, dim>, 2>> cell_gradients(
      dof_handler.get_triangulation().n_active_cells());
    FEValues<dim>               fe_values(*discretization.mapping,
                            *discretization.fe,
                            QGaussSimplex<dim>(1),
                            update_gradients);
    std::vector<Tensor<1, dim>> gradient(1);
    std::vector<double> local_dofs(discretization.fe->n_dofs_per_cell());
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (!cell->is_artificial())
        {
          fe_values.reinit(cell);
          for (unsigned int i = 0; i < 2; ++i)
            {
              cell->get_dof_values(ghosted_solution.block(i),
                                   local_dofs.begin(),
                                   local_dofs.end());
              fe_values[FEValuesExtractors::Scalar(0)]
                .get_function_gradients_from_local_dof_values(local_dofs,
                                                              gradient);
              cell_gradients[cell->active_cell_index()][i] = gradient[0];
            }
        }
    return cell_gradients;
  }



  template <int dim>
  std::array<double, 2>
  ErrorEstimator<dim>::p1_jump_integrals(
    const CellIterator                               &cell,
    const unsigned int                                f,
    const std::vector<std::array<Tensor<1, dim>, 2>> &cell_gradients) const
  {
    const auto           face    = cell->face(f);
    const Tensor<1, dim> tangent = face->vertex(1) - face->vertex(0);
    Tensor<1, dim>       normal  = cross_product_2d(tangent);
    const double         length  = tangent.norm();
    normal /= length;
    if (normal * (face->center() - cell->center()) < 0)
      normal *= -1;
    const auto           &neighbor = cell->neighbor(f);
    std::array<double, 2> integrals;
    for (unsigned int i = 0; i < 2; ++i)
      integrals[i] =
        std::pow(data.mu[i] *
                   (cell_gradients[cell->active_cell_index()][i] -
                    cell_gradients[neighbor->active_cell_index()][i]) *
                   normal,
                 2) *
        length;
    return integrals;
  }



  template <int dim>
  std::array<double, 2>
  ErrorEstimator<dim>::q1_jump_integrals(
    const CellIterator    &cell,
    const unsigned int     f,
    const BlockVectorType &ghosted_solution,
    JumpScratch           &scratch) const
  {
    FEInterfaceValues<dim> &interface_values = *scratch.interface_values;
    const auto             &neighbor         = cell->neighbor(f);
    if (cell->neighbor_is_coarser(f))
      {
        const auto [nf, nsf] = cell->neighbor_of_coarser_neighbor(f);
        interface_values.reinit(
          cell, f, numbers::invalid_unsigned_int, neighbor, nf, nsf);
      }
    else
      interface_values.reinit(cell,
                              f,
                              numbers::invalid_unsigned_int,
                              neighbor,
                              cell->neighbor_of_neighbor(f),
                              numbers::invalid_unsigned_int);
    const unsigned int    n_q = interface_values.n_quadrature_points;
    std::array<double, 2> integrals{};
    for (unsigned int i = 0; i < 2; ++i)
      {
        auto &traces     = scratch.traces[i];
        auto &local_dofs = scratch.local_dofs[i];
        cell->get_dof_values(ghosted_solution.block(i),
                             local_dofs[0].begin(),
                             local_dofs[0].end());
        neighbor->get_dof_values(ghosted_solution.block(i),
                                 local_dofs[1].begin(),
                                 local_dofs[1].end());
        for (unsigned int side = 0; side < 2; ++side)
          {
            traces[side].resize(n_q);
            interface_values
              .get_fe_face_values(side)[FEValuesExtractors::Scalar(0)]
              .get_function_gradients_from_local_dof_values(local_dofs[side],
                                                            traces[side]);
          }
        for (unsigned int q = 0; q < n_q; ++q)
          integrals[i] += std::pow(data.mu[i] * (traces[0][q] - traces[1][q]) *
                                     interface_values.normal(q),
                                   2) *
                          interface_values.JxW(q);
      }
    return integrals;
  }



  template <int dim>
  FluxRecord
  ErrorEstimator<dim>::flux_estimate(
    const DoFHandler<dim>        &dof_handler,
    const BlockVectorType        &ghosted_solution,
    const DualMesh<dim>          &dual_mesh,
    const VectorType             &lambda_h,
    const FluxEquilibration<dim> &flux_equilibration,
    Vector<double>               &indicators,
    const MPI_Comm                mpi_communicator) const
  {
    indicators.reinit(dof_handler.get_triangulation().n_active_cells());
    const std::array<double, 2> sign{{1., -1.}};
    FluxTerms                   sums;
    run_on_cells<FluxTerms>(
      dof_handler,
      [&]() {
        return std::make_unique<CellScratch>(discretization,
                                             dual_mesh,
                                             lambda_h,
                                             update_values | update_gradients |
                                               update_jacobians |
                                               update_JxW_values);
      },
      [&](const CellIterator &cell, CellScratch &scratch, FluxTerms &terms) {
        terms = FluxTerms();
        if (!cell->is_locally_owned())
          return;
        scratch.values.reinit(cell, ghosted_solution);
        const FEValues<dim> &fe_values = scratch.values.fe_values;
        // λ̃_h = Σ_a λ_a φ_a, the P1/Q1 function of the nodal values of λ_h.
        scratch.lambda.resize(fe_values.n_quadrature_points);
        fe_values.get_function_values(scratch.values.nodal_lambda_h,
                                      scratch.lambda);
        const double                     h_K = cell->diameter();
        const FEValuesExtractors::Scalar scalar(0);
        for (unsigned int i = 0; i < 2; ++i)
          {
            fe_values[scalar].get_function_values_from_local_dof_values(
              scratch.values.local_dofs[i], scratch.u[i]);
            fe_values[scalar].get_function_gradients_from_local_dof_values(
              scratch.values.local_dofs[i], scratch.grad_u[i]);
            flux_equilibration.flux_values(
              cell, i, fe_values, scratch.flux, scratch.divergence);
            const auto load =
              flux_equilibration.get_reconstruction().load_values(cell, i);
            for (const unsigned int q : fe_values.quadrature_point_indices())
              {
                terms.flux[i] +=
                  (data.mu[i] * scratch.grad_u[i][q] + scratch.flux[q])
                    .norm_square() *
                  fe_values.JxW(q);
                terms.residual[i] +=
                  std::pow(load[q] + sign[i] * scratch.lambda[q] -
                             scratch.divergence[q],
                           2) *
                  fe_values.JxW(q);
              }
            terms.flux[i] /= data.mu[i];
            terms.residual[i] *= std::pow(h_K / numbers::PI, 2) / data.mu[i];
          }
        double contact = 0;
        for (const unsigned int q : fe_values.quadrature_point_indices())
          contact += scratch.lambda[q] * (scratch.u[0][q] - scratch.u[1][q]) *
                     fe_values.JxW(q);
        terms.contact                         = std::max(contact, 0.);
        indicators[cell->active_cell_index()] = terms.eta_squared();
      },
      [&](const FluxTerms &terms) { sums += terms; });

    Utilities::MPI::sum<double>(sums.flux, mpi_communicator, sums.flux);
    Utilities::MPI::sum<double>(sums.residual, mpi_communicator, sums.residual);
    sums.contact = Utilities::MPI::sum(sums.contact, mpi_communicator);

    FluxRecord estimate;
    estimate.estimator   = std::sqrt(sums.eta_squared());
    estimate.flux        = std::sqrt(sums.flux[0] + sums.flux[1]);
    estimate.oscillation = std::sqrt(sums.residual[0] + sums.residual[1]);
    estimate.contact     = std::sqrt(2 * sums.contact);
    estimate.boundary =
      boundary_data_part(dof_handler, ghosted_solution, mpi_communicator);
    return estimate;
  }



  template <int dim>
  double
  ErrorEstimator<dim>::boundary_data_part(
    const DoFHandler<dim> &dof_handler,
    const BlockVectorType &ghosted_solution,
    const MPI_Comm         mpi_communicator) const
  {
    // An edge is a line on triangles too: QGaussSimplex<1> is QGauss<1>.
    const QGauss<dim - 1> quadrature(3);
    FEFaceValues<dim>     face_values(*discretization.mapping,
                                  *discretization.fe,
                                  quadrature,
                                  update_values | update_quadrature_points |
                                    update_JxW_values);

    std::array<std::vector<double>, 2> u;
    for (auto &values : u)
      values.resize(quadrature.size());
    std::vector<Vector<double>> g(quadrature.size(), Vector<double>(2));
    double                      sum = 0;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned() && cell->at_boundary())
        for (const unsigned int f : cell->face_indices())
          if (cell->at_boundary(f))
            {
              face_values.reinit(cell, f);
              for (unsigned int i = 0; i < 2; ++i)
                face_values.get_function_values(ghosted_solution.block(i),
                                                u[i]);
              data.boundary_values().vector_value_list(
                face_values.get_quadrature_points(), g);
              double integral = 0;
              for (const unsigned int q :
                   face_values.quadrature_point_indices())
                for (unsigned int i = 0; i < 2; ++i)
                  integral += data.mu[i] * std::pow(g[q][i] - u[i][q], 2) *
                              face_values.JxW(q);
              sum += integral / cell->face(f)->measure();
            }
    return std::sqrt(Utilities::MPI::sum(sum, mpi_communicator));
  }



  template class ErrorEstimator<2>;
} // namespace membranes
