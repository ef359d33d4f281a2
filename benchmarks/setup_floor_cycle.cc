/**
 * The steps of the cycle of benchmarks/setup_floor.cc, each as membranes
 * does it on the cell type: the mesh, the solution transfer, the DoFs,
 * the constraints, the sparsity pattern and the matrix, the assembly, the
 * AMG and CG. The head comment of setup_floor.cc says what is measured.
 */

#include "setup_floor.h"

#include <algorithm>
#include <cmath>
#include <deal.II/base/function.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/utilities.h>
#include <deal.II/distributed/shared_tria.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_cartesian.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/numerics/vector_tools.h>

namespace setup_floor
{
  /**
   * The data of the no-contact run of solver_cost.sh: case M with
   * tensions μ1 = 1, μ2 = 2 and R = 1/2, membrane 2 clamped at g2 = -1.
   */
  namespace case_m
  {
    constexpr double mu[2] = {1, 2};
    constexpr double R     = 0.5;

    /** The load f_i of membrane @p i at @p p (inside and outside r = R). */
    double
    load(const unsigned int i, const Point<dim> &p)
    {
      const double r2     = p.square();
      const double theta  = mu[0] / (mu[0] + mu[1]);
      const double m      = mu[0] * mu[1] / (mu[0] + mu[1]);
      const double smooth = 4 - 2 * r2;
      const double bump   = 16 * r2 - 8 * R * R;
      if (r2 < R * R)
        return i == 0 ? -mu[0] * (smooth + theta * bump) - 8 * m * R * R :
                        -mu[1] * (smooth + theta * bump) + 8 * m * R * R;
      return i == 0 ? -mu[0] * (smooth + bump) : -mu[1] * smooth;
    }

    /** The boundary value of membrane @p i at @p p. */
    double
    boundary_value(const unsigned int i, const Point<dim> &p)
    {
      const double q = p.square() - R * R;
      return i == 0 ? q * q : -1.;
    }
  } // namespace case_m



  /**
   * The unknowns of the linear system. Like membranes' coupled system, the
   * program solves for x_i = √μ_i u_i: the operator μ_i ∫ ∇u_i·∇φ is then,
   * in both components, the Laplacian ∫ ∇x_i·∇φ, and the loads are
   * ∫ f_i φ / √μ_i. Its boundary values are √μ_i g_i.
   */
  class ScaledBoundaryValues : public Function<dim>
  {
  public:
    ScaledBoundaryValues()
      : Function<dim>(2)
    {}

    double
    value(const Point<dim> &p, const unsigned int component) const override
    {
      return std::sqrt(case_m::mu[component]) *
             case_m::boundary_value(component, p);
    }
  };



  std::unique_ptr<Triangulation<dim>>
  make_triangulation(const bool triangles, const MPI_Comm mpi_communicator)
  {
    if (!triangles)
      return std::make_unique<parallel::distributed::Triangulation<dim>>(
        mpi_communicator);
    return std::make_unique<parallel::shared::Triangulation<dim>>(
      mpi_communicator,
      Triangulation<dim>::none,
      /* allow_artificial_cells = */ true,
      parallel::shared::Triangulation<dim>::partition_zorder);
  }



  void
  make_mesh(const bool          triangles,
            const unsigned int  refinements,
            Triangulation<dim> &triangulation)
  {
    if (triangles)
      {
        Triangulation<dim> square;
        GridGenerator::hyper_cube(square, -1, 1);
        GridGenerator::convert_hypercube_to_simplex_mesh(square, triangulation);
      }
    else
      GridGenerator::hyper_cube(triangulation, -1, 1);
    triangulation.refine_global(refinements);
  }



  std::unique_ptr<FiniteElement<dim>>
  make_scalar_element(const bool triangles)
  {
    if (triangles)
      return std::make_unique<FE_SimplexP<dim>>(1);
    return std::make_unique<FE_Q<dim>>(1);
  }



  std::unique_ptr<Mapping<dim>>
  make_mapping(const bool triangles)
  {
    if (triangles)
      return std::make_unique<MappingFE<dim>>(FE_SimplexP<dim>(1));
    return std::make_unique<MappingCartesian<dim>>();
  }



  Quadrature<dim>
  make_quadrature(const bool triangles)
  {
    if (triangles)
      return QGaussSimplex<dim>(3);
    return QGauss<dim>(3);
  }



  /**
   * Global refinement as membranes::MembraneProblem::refine_grid() does it:
   * every cell flagged, and the solution and λ_h handed to a
   * SolutionTransfer. On p4est's mesh they are copied into vectors with
   * ghost entries, which the transfer packs into the refinement's data; on
   * triangles, into vectors with every entry (the copy gathers them), from
   * which the serial transfer reads each cell's values when it
   * interpolates.
   */
  void
  SetupFloor::prepare_transfer()
  {
    triangulation->set_all_refine_flags();
    triangulation->prepare_coarsening_and_refinement();
    if (triangles)
      {
        replicated_previous_vectors = {Vector<double>(solution),
                                       Vector<double>(lambda_h)};
        serial_transfer =
          std::make_unique<SolutionTransfer<dim, Vector<double>>>(dof_handler);
        serial_transfer->prepare_for_coarsening_and_refinement(
          replicated_previous_vectors);
        return;
      }
    previous_vectors.assign(2,
                            VectorType(locally_owned_dofs,
                                       locally_relevant_dofs,
                                       mpi_communicator));
    previous_vectors[0]  = solution;
    previous_vectors[1]  = lambda_h;
    distributed_transfer = std::make_unique<
      parallel::distributed::SolutionTransfer<dim, VectorType>>(dof_handler);
    distributed_transfer->prepare_for_coarsening_and_refinement(
      {&previous_vectors[0], &previous_vectors[1]});
  }



  /** The DoFs of (u1, u2), numbered as deal.II numbers them (no renumbering).
   */
  void
  SetupFloor::distribute_dofs()
  {
    dof_handler.distribute_dofs(fe);
    locally_owned_dofs = dof_handler.locally_owned_dofs();
  }



  /**
   * The previous solution and λ_h on the new mesh: the initial guess. The
   * serial transfer interpolates on every cell, into vectors with every
   * entry, of which the locally owned ones are copied.
   */
  void
  SetupFloor::interpolate_previous_solution()
  {
    std::vector<VectorType> interpolated(2,
                                         VectorType(locally_owned_dofs,
                                                    mpi_communicator));
    if (triangles)
      {
        std::vector<Vector<double>> replicated(
          2, Vector<double>(dof_handler.n_dofs()));
        serial_transfer->interpolate(replicated_previous_vectors, replicated);
        for (unsigned int v = 0; v < 2; ++v)
          {
            for (const auto i : locally_owned_dofs)
              interpolated[v][i] = replicated[v][i];
            interpolated[v].compress(VectorOperation::insert);
          }
      }
    else
      {
        std::vector<VectorType *> targets{&interpolated[0], &interpolated[1]};
        distributed_transfer->interpolate(targets);
      }
    distributed_transfer.reset();
    serial_transfer.reset();
    previous_vectors.clear();
    replicated_previous_vectors.clear();
    solution.swap(interpolated[0]);
    lambda_h.swap(interpolated[1]);
  }



  /**
   * The index sets of the step-40 layout, the hanging node constraints and
   * the boundary values in one AffineConstraints object (a hanging vertex
   * on the boundary keeps its hanging node constraint, as in membranes),
   * and the constant modes of the two components for the AMG.
   */
  void
  SetupFloor::make_constraints()
  {
    DoFTools::extract_locally_relevant_dofs(dof_handler, locally_relevant_dofs);
    constraints.clear();
    constraints.reinit(locally_relevant_dofs);
    DoFTools::make_hanging_node_constraints(dof_handler, constraints);
    VectorTools::interpolate_boundary_values(
      *mapping, dof_handler, 0, ScaledBoundaryValues(), constraints);
    constraints.close();
    DoFTools::extract_constant_modes(dof_handler,
                                     ComponentMask(),
                                     constant_modes);
  }



  /**
   * The sparsity pattern, condensed with the constraints, and the matrix:
   * each component coupled with itself, or every DoF of a cell with every
   * other (the contact lines of membranes' CoupledSystem couple u1 and
   * u2).
   */
  void
  SetupFloor::setup_matrix()
  {
    DynamicSparsityPattern dsp(locally_relevant_dofs);
    if (full_coupling)
      DoFTools::make_sparsity_pattern(dof_handler, dsp, constraints, false);
    else
      {
        Table<2, DoFTools::Coupling> coupling(2, 2);
        coupling(0, 0) = DoFTools::always;
        coupling(1, 1) = DoFTools::always;
        DoFTools::make_sparsity_pattern(
          dof_handler, coupling, dsp, constraints, false);
      }
    SparsityTools::distribute_sparsity_pattern(dsp,
                                               locally_owned_dofs,
                                               mpi_communicator,
                                               locally_relevant_dofs);
    system_matrix.reinit(locally_owned_dofs,
                         locally_owned_dofs,
                         dsp,
                         mpi_communicator);
    system_rhs.reinit(locally_owned_dofs, mpi_communicator);
  }



  /**
   * The cell loop, on one thread: the Laplacian of the scalar element on
   * each cell, once for both components, and the loads f_i / √μ_i, both
   * condensed with the constraints (which also lift the boundary values).
   */
  void
  SetupFloor::assemble()
  {
    const FiniteElement<dim> &scalar = fe.base_element(0);
    FEValues<dim>             fe_values(*mapping,
                            scalar,
                            quadrature,
                            update_values | update_gradients |
                              update_quadrature_points | update_JxW_values);
    const unsigned int        n = scalar.n_dofs_per_cell();
    FullMatrix<double>        laplace(n, n), cell_matrix(2 * n, 2 * n);
    Vector<double>            cell_rhs(2 * n);
    std::vector<types::global_dof_index> dof_indices(2 * n);
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(
            static_cast<typename Triangulation<dim>::cell_iterator>(cell));
          laplace  = 0;
          cell_rhs = 0;
          for (const unsigned int q : fe_values.quadrature_point_indices())
            {
              const double JxW = fe_values.JxW(q);
              const auto  &p   = fe_values.quadrature_point(q);
              for (unsigned int k = 0; k < 2 * n; ++k)
                {
                  const auto [c, i] = fe.system_to_component_index(k);
                  cell_rhs(k) += case_m::load(c, p) / std::sqrt(case_m::mu[c]) *
                                 fe_values.shape_value(i, q) * JxW;
                }
              for (unsigned int i = 0; i < n; ++i)
                for (unsigned int j = 0; j < n; ++j)
                  laplace(i, j) += fe_values.shape_grad(i, q) *
                                   fe_values.shape_grad(j, q) * JxW;
            }
          for (unsigned int k = 0; k < 2 * n; ++k)
            for (unsigned int l = 0; l < 2 * n; ++l)
              {
                const auto [c, i] = fe.system_to_component_index(k);
                const auto [d, j] = fe.system_to_component_index(l);
                cell_matrix(k, l) = (c == d) ? laplace(i, j) : 0.;
              }
          cell->get_dof_indices(dof_indices);
          constraints.distribute_local_to_global(
            cell_matrix, cell_rhs, dof_indices, system_matrix, system_rhs);
        }
    system_matrix.compress(VectorOperation::add);
    system_rhs.compress(VectorOperation::add);
  }



  /** The AMG of membranes::LinearSolver, for the two components. */
  void
  SetupFloor::setup_amg()
  {
    TrilinosWrappers::PreconditionAMG::AdditionalData amg_data;
    amg_data.elliptic        = true;
    amg_data.constant_modes  = constant_modes;
    amg_data.smoother_sweeps = 2;
    amg.initialize(system_matrix, amg_data);
  }



  /**
   * The bound on the residual of the scaled system that membranes' coupled
   * system gives CG: Solver/Tolerance (10⁻¹⁰) times the force scales of
   * (4.5) at the initial guess, divided by √μ̄ and √(μ1 + μ2). Of the terms
   * of a force scale, the diagonal one μ_i ∫|∇φ_a|² |u_i(a)| is the
   * largest by far on these meshes (the product with the operator and the
   * loads are of order h²); it alone is evaluated here, at the interior
   * vertices.
   */
  double
  SetupFloor::cg_tolerance() const
  {
    const double mu1 = case_m::mu[0], mu2 = case_m::mu[1];
    const double mu_bar = mu1 * mu2 / (mu1 + mu2);
    double       force = 0, contact_force = 0;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        for (const unsigned int v : cell->vertex_indices())
          {
            const auto a1 = cell->vertex_dof_index(v, 0);
            const auto a2 = cell->vertex_dof_index(v, 1);
            if (constraints.is_constrained(a1) ||
                !locally_owned_dofs.is_element(a1))
              continue;
            // The diagonal of the scaled operator is ∫|∇φ_a|² for both u_i.
            const double diagonal = system_matrix.diag_element(a1);
            const double u1       = std::abs(solution[a1]) / std::sqrt(mu1);
            const double u2       = std::abs(solution[a2]) / std::sqrt(mu2);
            force = std::max({force, mu1 * diagonal * u1, mu2 * diagonal * u2});
            contact_force =
              std::max(contact_force, mu_bar * diagonal * std::max(u1, u2));
          }
    force         = Utilities::MPI::max(force, mpi_communicator);
    contact_force = Utilities::MPI::max(contact_force, mpi_communicator);
    const double tolerance = 1e-10;
    return std::min(tolerance * contact_force / std::sqrt(mu_bar),
                    tolerance * force / std::sqrt(mu1 + mu2));
  }



  /**
   * CG from the initial guess in @p solution (with the boundary values of
   * this mesh set), to the bound of cg_tolerance() or 10⁻¹⁴ of the
   * right-hand side, whichever is larger. Returns the iterations.
   */
  unsigned int
  SetupFloor::solve_cg()
  {
    const double tolerance = cg_tolerance();
    constraints.distribute(solution);
    SolverControl        control(10000,
                          std::max(tolerance, 1e-14 * system_rhs.l2_norm()));
    SolverCG<VectorType> cg(control);
    cg.solve(system_matrix, solution, system_rhs, amg);
    constraints.distribute(solution);
    return control.last_step();
  }



  /** The linear system of a mesh is freed once the mesh is solved on. */
  void
  SetupFloor::clear_system()
  {
    amg.clear();
    system_matrix.clear();
    system_rhs.clear();
  }
} // namespace setup_floor
