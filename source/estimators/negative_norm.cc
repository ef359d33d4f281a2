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
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <membranes/estimators/error_norms.h>
#include <membranes/estimators/negative_norm.h>
#include <membranes/mesh/cell_loop.h>

namespace membranes
{
  namespace
  {
    /** What one thread of the assembly of NegativeNorm works with. */
    template <int dim>
    struct RieszScratch
    {
      RieszScratch(const Mapping<dim>       &mapping,
                   const FiniteElement<dim> &fe,
                   const Quadrature<dim>    &cell_quadrature,
                   const Quadrature<dim>    &density_quadrature,
                   const Quadrature<dim>    &jump_quadrature)
        : fe_values(mapping,
                    fe,
                    cell_quadrature,
                    update_values | update_gradients | update_JxW_values)
        , density_values(mapping,
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
      FEValues<dim>       fe_values, density_values, jump_values;
      std::vector<double> rho;

      /**
       * The last two cells of this thread whose matrix was computed, and
       * their matrices. The mappings of Discretization are determined by
       * the vertices of a cell, so a cell that is a translation of one of
       * them has the same Jacobians at the same quadrature points, the same
       * shape gradients and JxW, hence the same cell matrix: on a uniform
       * mesh of quadrilaterals every cell is a translation of the previous
       * one, on one of triangles every other cell (the two orientations of
       * the triangles of a square alternate).
       */
      std::array<typename Triangulation<dim>::cell_iterator, 2> matrix_cells;
      std::array<FullMatrix<double>, 2>                         matrices;
      unsigned int                                              next_matrix = 0;

      /**
       * The H¹ inner product ∫_K ∇φ_i·∇φ_j + φ_i φ_j on @p cell into
       * @p cell_matrix (zero on entry): that of matrices if @p cell is a
       * translate of one of matrix_cells, otherwise by the Gauss rule of
       * fe_values, then kept in place of the older of the two.
       */
      template <typename CellIterator>
      void
      cell_matrix(const CellIterator &cell, FullMatrix<double> &cell_matrix)
      {
        const typename Triangulation<dim>::cell_iterator tria_cell(cell);
        for (unsigned int k = 0; k < matrix_cells.size(); ++k)
          if (matrix_cells[k].state() == IteratorState::valid &&
              tria_cell->is_translation_of(matrix_cells[k]))
            {
              cell_matrix = matrices[k];
              return;
            }
        fe_values.reinit(cell);
        const unsigned int n_dofs = cell_matrix.m();
        for (const unsigned int q : fe_values.quadrature_point_indices())
          for (unsigned int i = 0; i < n_dofs; ++i)
            for (unsigned int j = 0; j < n_dofs; ++j)
              cell_matrix(i, j) +=
                (fe_values.shape_grad(i, q) * fe_values.shape_grad(j, q) +
                 fe_values.shape_value(i, q) * fe_values.shape_value(j, q)) *
                fe_values.JxW(q);
        matrix_cells[next_matrix] = tria_cell;
        matrices[next_matrix]     = cell_matrix;
        next_matrix ^= 1;
      }
    };
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
  NegativeNorm<dim>::assemble(const DoFHandler<dim>           &dof_handler,
                              const AffineConstraints<double> &constraints,
                              const Density                   &rho,
                              const double                     jump,
                              TrilinosWrappers::SparseMatrix  &matrix,
                              TrilinosWrappers::MPI::Vector   &rhs) const
  {
    // The H¹ inner product ∫ ∇φ_i·∇φ_j + φ_i φ_j with the Gauss rule of the
    // element, and ∫ ρ φ_i on the pieces of the dual cells, by the composite
    // rule where ρ jumps.
    struct Copy
    {
      FullMatrix<double>                   cell_matrix;
      Vector<double>                       cell_rhs;
      std::vector<types::global_dof_index> dof_indices;
    };
    const unsigned int n_dofs = fe->n_dofs_per_cell();
    run_on_cells<Copy>(
      dof_handler,
      [&]() {
        return std::make_unique<RieszScratch<dim>>(
          *discretization.mapping,
          *fe,
          cell_quadrature,
          density_quadrature.quadrature(),
          jump_quadrature.quadrature());
      },
      [&](const auto &cell, RieszScratch<dim> &scratch, Copy &copy) {
        copy.dof_indices.clear();
        if (!cell->is_locally_owned())
          return;
        copy.cell_matrix.reinit(n_dofs, n_dofs);
        copy.cell_rhs.reinit(n_dofs);
        copy.dof_indices.resize(n_dofs);
        cell->get_dof_indices(copy.dof_indices);

        scratch.cell_matrix(cell, copy.cell_matrix);

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
          constraints.distribute_local_to_global(
            copy.cell_matrix, copy.cell_rhs, copy.dof_indices, matrix, rhs);
      });
    matrix.compress(VectorOperation::add);
    rhs.compress(VectorOperation::add);
  }



  template <int dim>
  double
  NegativeNorm<dim>::norm(const Triangulation<dim> &triangulation,
                          const Density            &rho,
                          const double              jump,
                          const MPI_Comm            mpi_communicator) const
  {
    // The space of z_h: degree p on the mesh, zero on ∂ω, with the hanging
    // node constraints of its own DoFs.
    DoFHandler<dim> dof_handler(triangulation);
    dof_handler.distribute_dofs(*fe);
    const IndexSet &owned = dof_handler.locally_owned_dofs();
    IndexSet        relevant;
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

    // The pattern is freed before the matrix is assembled and its AMG
    // hierarchy built, the peak memory of a run with errors.
    TrilinosWrappers::SparseMatrix matrix;
    {
      DynamicSparsityPattern dsp(relevant);
      DoFTools::make_sparsity_pattern(dof_handler, dsp, constraints, false);
      SparsityTools::distribute_sparsity_pattern(dsp,
                                                 owned,
                                                 mpi_communicator,
                                                 relevant);
      matrix.reinit(owned, owned, dsp, mpi_communicator);
    }
    TrilinosWrappers::MPI::Vector rhs(owned, mpi_communicator);
    assemble(dof_handler, constraints, rho, jump, matrix, rhs);

    // (A + M) Z = F by CG with an AMG hierarchy for elements of higher
    // degree. ‖z_h‖²_{H¹} = max_Y 2 F·Y − Y·(A + M)Y, attained at Y = Z: the
    // value at the CG iterate Y errs by ‖Z − Y‖²_{A+M}, the square of the
    // error of the iterate (F·Y would err by its first power). Relative to
    // ‖z_h‖²_{H¹} = ‖Z‖²_{A+M} it is the square of the relative energy
    // error ‖Z − Y‖_{A+M} / ‖Z‖_{A+M}: a residual reduced by 10⁻⁶ leaves
    // the value the same to round-off on any number of processes, whose
    // AMG hierarchies differ.
    TrilinosWrappers::PreconditionAMG                 amg;
    TrilinosWrappers::PreconditionAMG::AdditionalData amg_data;
    amg_data.elliptic              = true;
    amg_data.higher_order_elements = fe->degree > 1;
    amg.initialize(matrix, amg_data);
    TrilinosWrappers::MPI::Vector           z(owned, mpi_communicator);
    ReductionControl                        control(1000, 1e-300, 1e-6);
    SolverCG<TrilinosWrappers::MPI::Vector> cg(control);
    cg.solve(matrix, z, rhs, amg);
    TrilinosWrappers::MPI::Vector product(owned, mpi_communicator);
    matrix.vmult(product, z);
    return std::sqrt(std::max(2 * (rhs * z) - product * z, 0.));
  }



  template <int dim>
  double
  NegativeNorm<dim>::lambda_error(const DoFHandler<dim> &dof_handler,
                                  const DualMesh<dim>   &dual_mesh,
                                  const TrilinosWrappers::MPI::Vector &lambda_h,
                                  const ProblemData<dim>              &data,
                                  const MPI_Comm mpi_communicator) const
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
    return norm(dof_handler.get_triangulation(), rho, jump, mpi_communicator);
  }



  template class NegativeNorm<2>;
} // namespace membranes
