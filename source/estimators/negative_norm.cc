#include <algorithm>
#include <array>
#include <cmath>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/distributed/tria_base.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/vector_memory.h>
#include <membranes/estimators/error_norms.h>
#include <membranes/estimators/negative_norm.h>
#include <membranes/estimators/riesz_multigrid.h>
#include <membranes/mesh/cell_loop.h>

namespace membranes
{
  namespace
  {
    /** What one thread of the assembly of the density works with. */
    template <int dim>
    struct DensityScratch
    {
      DensityScratch(const Mapping<dim>       &mapping,
                     const FiniteElement<dim> &fe,
                     const Quadrature<dim>    &density_quadrature,
                     const Quadrature<dim>    &jump_quadrature)
        : density_values(mapping,
                         fe,
                         density_quadrature,
                         update_values | update_quadrature_points |
                           update_JxW_values)
        , jump_values(mapping,
                      fe,
                      jump_quadrature,
                      update_values | update_quadrature_points |
                        update_JxW_values)
      {}
      FEValues<dim>       density_values, jump_values;
      std::vector<double> rho;
    };



    /**
     * The constraints of a space of @p dof_handler: zero on ∂ω and the
     * hanging nodes of its own DoFs.
     */
    template <int dim>
    AffineConstraints<double>
    riesz_constraints(const DoFHandler<dim> &dof_handler)
    {
      const Triangulation<dim> &triangulation = dof_handler.get_triangulation();
      IndexSet                  relevant;
      DoFTools::extract_locally_relevant_dofs(dof_handler, relevant);
      // On a parallel::shared::Triangulation the ghost cells' faces with
      // hanging nodes can have artificial children, whose DoFs the hanging
      // node constraints of degree 2 constrain too: there the constraints
      // take every DoF (the mesh is on every process anyway).
      const bool distributed =
        dynamic_cast<const parallel::DistributedTriangulationBase<dim> *>(
          &triangulation) != nullptr;
      AffineConstraints<double> constraints(
        distributed ? relevant : complete_index_set(dof_handler.n_dofs()));
      DoFTools::make_hanging_node_constraints(dof_handler, constraints);
      for (const auto id : triangulation.get_boundary_ids())
        DoFTools::make_zero_boundary_constraints(dof_handler, id, constraints);
      constraints.close();
      return constraints;
    }
  } // namespace



  template <int dim>
  NegativeNorm<dim>::NegativeNorm(const Discretization<dim> &discretization,
                                  const unsigned int         degree,
                                  const unsigned int         jump_subdivisions)
    : discretization(discretization)
    , fe(discretization.cell_type == Parameters::CellType::triangle ?
           std::unique_ptr<FiniteElement<dim>>(new FE_SimplexP<dim>(degree)) :
           std::make_unique<FE_Q<dim>>(degree))
    , cell_quadrature(
        fe->reference_cell().template get_gauss_type_quadrature<dim>(degree +
                                                                     1))
    , density_quadrature(fe->reference_cell(), 2)
    , jump_quadrature(fe->reference_cell(),
                      QIteratedSimplex<dim>(QGaussSimplex<dim>(2),
                                            1u << jump_subdivisions))
  {}



  template <int dim>
  void
  NegativeNorm<dim>::assemble_density(
    const DoFHandler<dim>           &dof_handler,
    const AffineConstraints<double> &constraints,
    const Density                   &rho,
    const double                     jump,
    VectorType                      &rhs) const
  {
    // ∫ ρ φ_i on the pieces of the dual cells, by the composite rule where
    // ρ jumps.
    struct Copy
    {
      Vector<double>                       cell_rhs;
      std::vector<types::global_dof_index> dof_indices;
    };
    const unsigned int n_dofs = fe->n_dofs_per_cell();
    run_on_cells<Copy>(
      dof_handler,
      [&]() {
        return std::make_unique<DensityScratch<dim>>(
          *discretization.mapping,
          *fe,
          density_quadrature.quadrature(),
          jump_quadrature.quadrature());
      },
      [&](const auto &cell, DensityScratch<dim> &scratch, Copy &copy) {
        copy.dof_indices.clear();
        if (!cell->is_locally_owned())
          return;
        copy.cell_rhs.reinit(n_dofs);
        copy.dof_indices.resize(n_dofs);
        cell->get_dof_indices(copy.dof_indices);

        scratch.density_values.reinit(cell);
        rho(cell,
            density_quadrature,
            scratch.density_values.get_quadrature_points(),
            scratch.rho);
        const auto [min, max] =
          std::minmax_element(scratch.rho.begin(), scratch.rho.end());
        const bool           jumps = *max - *min > jump;
        const FEValues<dim> &density_values =
          jumps ? scratch.jump_values : scratch.density_values;
        if (jumps)
          {
            scratch.jump_values.reinit(cell);
            rho(cell,
                jump_quadrature,
                scratch.jump_values.get_quadrature_points(),
                scratch.rho);
          }
        for (const unsigned int q : density_values.quadrature_point_indices())
          {
            const double rho_JxW = scratch.rho[q] * density_values.JxW(q);
            for (unsigned int i = 0; i < n_dofs; ++i)
              copy.cell_rhs(i) += rho_JxW * density_values.shape_value(i, q);
          }
      },
      [&](const Copy &copy) {
        if (!copy.dof_indices.empty())
          constraints.distribute_local_to_global(copy.cell_rhs,
                                                 copy.dof_indices,
                                                 rhs);
      });
    rhs.compress(VectorOperation::add);
  }



  template <int dim>
  double
  NegativeNorm<dim>::norm(const DoFHandler<dim> &linear_dof_handler,
                          const TrilinosWrappers::SparseMatrix &linear_matrix,
                          const Density                        &rho,
                          const double                          jump) const
  {
    // The coarse level, zero on ∂ω, and the AMG of its matrix, first: the
    // transient memory of the AMG setup is the peak of this phase, and
    // nothing of degree p exists yet.
    const Triangulation<dim> &triangulation =
      linear_dof_handler.get_triangulation();
    const AffineConstraints<double> linear_constraints =
      riesz_constraints(linear_dof_handler);
    TrilinosWrappers::PreconditionAMG                 linear_preconditioner;
    TrilinosWrappers::PreconditionAMG::AdditionalData amg_data;
    amg_data.elliptic = true;
    linear_preconditioner.initialize(linear_matrix, amg_data);

    // The space of z_h, of degree p, zero on ∂ω. Its operator is
    // matrix-free: neither its matrix nor an algebraic hierarchy of it is
    // formed.
    DoFHandler<dim> dof_handler(triangulation);
    dof_handler.distribute_dofs(*fe);
    const AffineConstraints<double> constraints =
      riesz_constraints(dof_handler);

    const RieszOperator<dim> riesz(*discretization.mapping,
                                   dof_handler,
                                   constraints,
                                   cell_quadrature);
    VectorType               rhs;
    riesz.initialize_dof_vector(rhs);
    assemble_density(dof_handler, constraints, rho, jump, rhs);

    const RieszMultigrid<dim> preconditioner(riesz,
                                             dof_handler,
                                             constraints,
                                             linear_dof_handler,
                                             linear_constraints,
                                             linear_preconditioner);

    // (A + M) Z = F by CG. ‖z_h‖²_{H¹} = max_Y 2 F·Y − Y·(A + M)Y,
    // attained at Y = Z: the value at the CG iterate Y errs by
    // ‖Z − Y‖²_{A+M}, the square of the error of the iterate (F·Y would err
    // by its first power). Relative to ‖z_h‖²_{H¹} = ‖Z‖²_{A+M} it is the
    // square of the relative energy error ‖Z − Y‖_{A+M} / ‖Z‖_{A+M}: a
    // residual reduced by 10⁻⁶ leaves the value the same to round-off on
    // any number of processes, whose AMG hierarchies differ.
    VectorType z;
    riesz.initialize_dof_vector(z);
    ReductionControl     control(1000, 1e-300, 1e-6);
    SolverCG<VectorType> cg(control);
    cg.solve(riesz, z, rhs, preconditioner);
    // The vectors of CG stay in deal.II's pool until released.
    GrowingVectorMemory<VectorType>::release_unused_memory();
    const double f_z = rhs * z;
    riesz.vmult(rhs, z);
    return std::sqrt(std::max(2 * f_z - rhs * z, 0.));
  }



  template <int dim>
  double
  NegativeNorm<dim>::lambda_error(
    const DoFHandler<dim>                &dof_handler,
    const TrilinosWrappers::SparseMatrix &laplace_matrix,
    const DualMesh<dim>                  &dual_mesh,
    const TrilinosWrappers::MPI::Vector  &lambda_h,
    const ProblemData<dim>               &data) const
  {
    // λ_h on the piece K ∩ D_a of each point, read on the cell of the mesh
    // of the solution that is the same cell of the triangulation, and the
    // exact λ alone (ProblemData::exact_action_list(), not u and ∇u too).
    // The threads of the cell loop call it at once: it keeps no state.
    const auto rho = [&](const CellIterator            &cell,
                         const DualCellQuadrature<dim> &rule,
                         const std::vector<Point<dim>> &points,
                         std::vector<double>           &values) {
      const typename DoFHandler<dim>::active_cell_iterator solution_cell(
        &dof_handler.get_triangulation(),
        cell->level(),
        cell->index(),
        &dof_handler);
      std::array<double, GeometryInfo<dim>::vertices_per_cell> vertex_values;
      for (const unsigned int v : cell->vertex_indices())
        vertex_values[v] = dual_mesh.lambda_h_value(solution_cell, v, lambda_h);
      data.exact_action_list(points, values);
      for (unsigned int q = 0; q < points.size(); ++q)
        values[q] -= vertex_values[rule.vertex_of_point(q)];
    };
    // λ − λ_h varies by O(h) on a cell where λ is smooth, and by the jump
    // where λ jumps (λ_h between the values on either side).
    const double jump = lambda_jump_fraction * lambda_h.linfty_norm();
    return norm(dof_handler, laplace_matrix, rho, jump);
  }



  template class NegativeNorm<2>;
} // namespace membranes
