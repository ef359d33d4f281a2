/**
 * The floor of the setup of one cycle of case M, measured with deal.II's
 * building blocks alone.
 *
 *   setup_floor [quadrilateral|triangle] [refinements] [components|full]
 *               [trim]
 *
 * One cycle of the active set method on a new mesh needs, before its first
 * linear solve: the refined mesh with the previous solution carried over
 * to it, the DoFs, the constraints, and the matrix and right-hand side of
 * the linear system. This program does exactly that and nothing more, in
 * the way membranes does it on the cell type (the same triangulation,
 * mapping, element, quadrature, solution transfer, constraints, sparsity
 * pattern, matrix type and AMG settings), and times each step. The linear
 * solve that follows, one CG-AMG solve of the coupled (u1, u2) system
 * without contact, is the yardstick of benchmarks/solver_cost.sh: the
 * ratio of the two says how much of the setup no implementation on these
 * building blocks can save.
 *
 * The mesh of case M is the square (-1,1)² under global refinement. With
 * `quadrilateral` (the default) it lives in a
 * parallel::distributed::Triangulation (p4est), with MappingCartesian,
 * FE_Q(1), QGauss(3), and the solution goes to the new mesh by
 * parallel::distributed::SolutionTransfer; it is refined @p refinements
 * times (default 9: 512 × 512 cells) and solved on, as the previous
 * cycle, and the measured cycle is the next one (1024 × 1024 cells). With
 * `triangle` the square is split into 8 triangles, as membranes splits
 * it for `Cell type = triangle`, in a parallel::shared::Triangulation
 * (every process holds the whole mesh, partitioned in z-order), with
 * MappingFE(FE_SimplexP(1)), FE_SimplexP(1), QGaussSimplex(3), and the
 * serial SolutionTransfer of vectors with every entry, which membranes
 * uses where p4est cannot hold the mesh; the default of 7 refinements
 * makes the measured cycle go from 131 072 to 524 288 triangles, the last
 * cycle of parameters/degenerate-free-boundary.prm.
 *
 * After each step the program reads the peak resident set size (VmHWM) and
 * the current one (VmRSS) of the process. With `trim`, the memory freed in
 * a step goes back to the system first (glibc's malloc_trim), so that the
 * current resident set is what the process holds; the later steps then
 * touch fresh pages instead of reusing freed ones, which costs time, so
 * the times are read without it.
 *
 * The matrix couples the DoFs of a cell each component only with itself
 * (`components`, the default: two scalar Laplacians, twice the one matrix
 * of membranes' DiscreteProblem), or in
 * the way of its CoupledSystem, every DoF with every other (`full`: the
 * matrix that the yardstick of solver_cost.sh solves with, whose u1–u2
 * entries stay zero without contact).
 */

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deal.II/base/function.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/utilities.h>
#include <deal.II/distributed/shared_tria.h>
#include <deal.II/distributed/solution_transfer.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_cartesian.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/solution_transfer.h>
#include <deal.II/numerics/vector_tools.h>
#include <iomanip>
#include <iostream>
#include <malloc.h>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace setup_floor
{
  using namespace dealii;

  constexpr int dim = 2;
  using VectorType  = TrilinosWrappers::MPI::Vector;

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



  /**
   * The triangulation that membranes makes for the cell type: on
   * quadrilaterals p4est's, on triangles (@p triangles), which p4est cannot
   * hold, one that every process holds whole.
   */
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



  /**
   * The square (-1,1)², with @p triangles split into 8 triangles as
   * membranes splits it (convert_hypercube_to_simplex_mesh of a serial
   * mesh), in @p triangulation, refined @p refinements times.
   */
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



  /** The element of one component: linear on the cell type. */
  std::unique_ptr<FiniteElement<dim>>
  make_scalar_element(const bool triangles)
  {
    if (triangles)
      return std::make_unique<FE_SimplexP<dim>>(1);
    return std::make_unique<FE_Q<dim>>(1);
  }



  /**
   * The mapping of membranes' Discretization: on triangles the linear one
   * of simplices, on the axis-parallel squares of case M the Cartesian one.
   */
  std::unique_ptr<Mapping<dim>>
  make_mapping(const bool triangles)
  {
    if (triangles)
      return std::make_unique<MappingFE<dim>>(FE_SimplexP<dim>(1));
    return std::make_unique<MappingCartesian<dim>>();
  }



  /** The cell quadrature of membranes' Discretization. */
  Quadrature<dim>
  make_quadrature(const bool triangles)
  {
    if (triangles)
      return QGaussSimplex<dim>(3);
    return QGauss<dim>(3);
  }



  /** One timed step: its wall time and the memory of the process after it. */
  struct Step
  {
    std::string name;
    bool        setup; // one of steps 1-4, else part of the solve
    double      seconds;
    double      peak_kib;    // VmHWM
    double      current_kib; // VmRSS
  };



  class SetupFloor
  {
  public:
    SetupFloor(const bool         triangles,
               const unsigned int refinements,
               const bool         full_coupling,
               const bool         trim_memory);

    void
    run();

  private:
    template <typename Action>
    void
    timed(const std::string &name, const bool setup, const Action &action);

    double
    time_refinement_alone() const;
    void
    prepare_transfer();
    void
    distribute_dofs();
    void
    interpolate_previous_solution();
    void
    make_constraints();
    void
    setup_matrix();
    void
    assemble();
    void
    setup_amg();
    double
    cg_tolerance() const;
    unsigned int
    solve_cg();
    void
    clear_system();
    std::vector<std::pair<std::string, double>>
    objects_held() const;
    void
    print_objects(
      const std::vector<std::pair<std::string, double>> &objects) const;
    void
    print_table(const double       refinement_alone,
                const unsigned int cg_iterations) const;

    const bool                                triangles;
    const unsigned int                        refinements;
    const bool                                full_coupling;
    const bool                                trim_memory;
    MPI_Comm                                  mpi_communicator;
    const std::unique_ptr<Triangulation<dim>> triangulation;
    const FESystem<dim>                       fe;
    const std::unique_ptr<const Mapping<dim>> mapping;
    const Quadrature<dim>                     quadrature;
    DoFHandler<dim>                           dof_handler;

    IndexSet                          locally_owned_dofs;
    IndexSet                          locally_relevant_dofs;
    AffineConstraints<double>         constraints;
    std::vector<std::vector<bool>>    constant_modes;
    TrilinosWrappers::SparseMatrix    system_matrix;
    VectorType                        system_rhs;
    TrilinosWrappers::PreconditionAMG amg;

    // The solution x and a second vector of the same layout, which stands
    // in for λ_h (membranes carries both to the next mesh); their copies on
    // the previous mesh while a transfer holds them: ghosted ones for the
    // transfer of p4est's mesh, ones with every entry for the serial
    // transfer of triangles.
    VectorType                  solution;
    VectorType                  lambda_h;
    std::vector<VectorType>     previous_vectors;
    std::vector<Vector<double>> replicated_previous_vectors;
    std::unique_ptr<parallel::distributed::SolutionTransfer<dim, VectorType>>
                                                           distributed_transfer;
    std::unique_ptr<SolutionTransfer<dim, Vector<double>>> serial_transfer;

    std::vector<Step> steps;
  };



  SetupFloor::SetupFloor(const bool         triangles,
                         const unsigned int refinements,
                         const bool         full_coupling,
                         const bool         trim_memory)
    : triangles(triangles)
    , refinements(refinements)
    , full_coupling(full_coupling)
    , trim_memory(trim_memory)
    , mpi_communicator(MPI_COMM_WORLD)
    , triangulation(make_triangulation(triangles, mpi_communicator))
    , fe(*make_scalar_element(triangles), 2)
    , mapping(make_mapping(triangles))
    , quadrature(make_quadrature(triangles))
    , dof_handler(*triangulation)
  {}



  /**
   * Run @p action, and record its wall time and the memory of the process
   * afterwards as the step @p name: the peak of the resident set so far,
   * and the current one (with trim_memory: once the memory freed in the step
   * has gone back to the system).
   */
  template <typename Action>
  void
  SetupFloor::timed(const std::string &name,
                    const bool         setup,
                    const Action      &action)
  {
    const auto start = std::chrono::steady_clock::now();
    action();
    const std::chrono::duration<double> seconds =
      std::chrono::steady_clock::now() - start;
    if (trim_memory)
      malloc_trim(0);
    Utilities::System::MemoryStats memory;
    Utilities::System::get_memory_stats(memory);
    steps.push_back({name,
                     setup,
                     seconds.count(),
                     static_cast<double>(memory.VmHWM),
                     static_cast<double>(memory.VmRSS)});
  }



  /**
   * The cycle: the previous mesh is set up and solved on untimed, from a
   * zero start; then the next mesh is made from it and set up step by
   * step, and solved on once. Last, the refinement of the previous mesh is
   * timed on its own.
   */
  void
  SetupFloor::run()
  {
    timed("0. the process at start (the libraries)", true, []() {});
    make_mesh(triangles, refinements, *triangulation);
    distribute_dofs();
    solution.reinit(locally_owned_dofs, mpi_communicator);
    make_constraints();
    setup_matrix();
    assemble();
    setup_amg();
    solve_cg();
    lambda_h = solution;
    clear_system();
    timed("0. the previous mesh solved on, its system freed", true, []() {});

    // The serial transfer of triangles notes the DoF indices of each cell
    // when it is handed the vectors; the refinement packs nothing.
    timed(triangles ? "1a. refine flags; the two vectors, whole, to the "
                      "transfer" :
                      "1a. refine flags; the two vectors to the transfer",
          true,
          [&]() { prepare_transfer(); });
    timed(triangles ? "1b. refinement" :
                      "1b. refinement, the vectors packed on the way",
          true,
          [&]() { triangulation->execute_coarsening_and_refinement(); });
    timed("2. distribute_dofs, owned DoFs", true, [&]() { distribute_dofs(); });
    timed("1c. interpolation of the two vectors", true, [&]() {
      interpolate_previous_solution();
    });
    timed("3. relevant DoFs, constraints, constant modes", true, [&]() {
      make_constraints();
    });
    timed("4a. sparsity pattern, matrix and vector reinit", true, [&]() {
      setup_matrix();
    });
    timed("4b. assembly of the operator and the loads", true, [&]() {
      assemble();
    });
    timed("5a. AMG setup", false, [&]() { setup_amg(); });
    unsigned int cg_iterations = 0;
    timed("5b. CG", false, [&]() { cg_iterations = solve_cg(); });
    const auto objects = objects_held();
    // Last, so that the second mesh does not raise the peaks read above.
    clear_system();
    const double refinement_alone = time_refinement_alone();
    print_table(refinement_alone, cg_iterations);
    print_objects(objects);
  }



  /**
   * Refinement on its own: a second triangulation of the previous mesh,
   * with no DoFHandler and no data attached, refined once.
   */
  double
  SetupFloor::time_refinement_alone() const
  {
    const std::unique_ptr<Triangulation<dim>> mesh =
      make_triangulation(triangles, mpi_communicator);
    make_mesh(triangles, refinements, *mesh);
    const auto start = std::chrono::steady_clock::now();
    mesh->refine_global(1);
    const std::chrono::duration<double> seconds =
      std::chrono::steady_clock::now() - start;
    return seconds.count();
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



  /**
   * One table: each step's wall time and the memory of the process after
   * it, in bytes per DoF of the new mesh; then the sums.
   */
  void
  SetupFloor::print_table(const double       refinement_alone,
                          const unsigned int cg_iterations) const
  {
    const double n_dofs  = dof_handler.n_dofs();
    const auto   per_dof = [&](const double kib) {
      return static_cast<long>(std::round(kib * 1024 / n_dofs));
    };
    std::cout << (full_coupling ? "full" : "components") << " coupling, "
              << (trim_memory ? "freed memory trimmed, " : "")
              << triangulation->n_global_active_cells()
              << (triangles ? " triangles, " : " cells, ")
              << dof_handler.n_dofs() << " DoFs, " << cg_iterations
              << " CG iterations\n\n"
              << "| step | s | peak MiB | peak B/DoF | current B/DoF |\n"
              << "|---|--:|--:|--:|--:|\n"
              << std::fixed;
    double setup = 0, solve = 0;
    for (const Step &step : steps)
      {
        (step.setup ? setup : solve) += step.seconds;
        std::cout << "| " << step.name << " | " << std::setprecision(3)
                  << step.seconds << " | " << std::setprecision(0)
                  << step.peak_kib / 1024 << " | " << per_dof(step.peak_kib)
                  << " | " << per_dof(step.current_kib) << " |\n";
      }
    std::cout << std::setprecision(3)
              << "| refinement alone (no DoFs, no data) | " << refinement_alone
              << " | | | |\n"
              << "| setup floor (steps 1-4) | " << setup << " | | | |\n"
              << "| solve (step 5) | " << solve << " | | | |\n"
              << "| floor / solve | " << setup / solve << " | | | |\n"
              << std::endl;
  }


  /**
   * What the objects of the cycle report as their own size
   * (memory_consumption()), in bytes, at the end of the solve. The AMG
   * hierarchy is not among them: ML does not report it; the growth of the
   * resident set in step 5a stands for it.
   */
  std::vector<std::pair<std::string, double>>
  SetupFloor::objects_held() const
  {
    return {
      {triangles ? "triangulation (the whole mesh)" :
                   "triangulation (with p4est)",
       static_cast<double>(triangulation->memory_consumption())},
      {"DoF handler", static_cast<double>(dof_handler.memory_consumption())},
      {"constraints", static_cast<double>(constraints.memory_consumption())},
      {"matrix", static_cast<double>(system_matrix.memory_consumption())},
      {"vectors (rhs, solution, λ_h)",
       static_cast<double>(system_rhs.memory_consumption() +
                           solution.memory_consumption() +
                           lambda_h.memory_consumption())}};
  }



  /** The sizes of objects_held(), in bytes per DoF. */
  void
  SetupFloor::print_objects(
    const std::vector<std::pair<std::string, double>> &objects) const
  {
    std::cout << "| object | B/DoF |\n|---|--:|\n";
    for (const auto &[name, bytes] : objects)
      std::cout << "| " << name << " | " << std::setprecision(0)
                << bytes / dof_handler.n_dofs() << " |\n";
    std::cout << std::endl;
  }
} // namespace setup_floor



int
main(int argc, char *argv[])
{
  try
    {
      dealii::Utilities::MPI::MPI_InitFinalize mpi_initialization(argc, argv);
      const std::string cell_type = (argc > 1) ? argv[1] : "quadrilateral";
      if (cell_type != "quadrilateral" && cell_type != "triangle")
        throw std::invalid_argument("the cell type is 'quadrilateral' or "
                                    "'triangle', not '" +
                                    cell_type + "'");
      const bool triangles = (cell_type == "triangle");
      // The previous mesh of the last cycle of case M (512 × 512 cells) or
      // of degenerate-free-boundary.prm (131 072 triangles).
      const unsigned int refinements =
        (argc > 2) ? std::stoi(argv[2]) : (triangles ? 7 : 9);
      const std::string coupling = (argc > 3) ? argv[3] : "components";
      if (coupling != "components" && coupling != "full")
        throw std::invalid_argument("the coupling is 'components' or 'full', "
                                    "not '" +
                                    coupling + "'");
      const bool trim = (argc > 4) && std::string(argv[4]) == "trim";
      setup_floor::SetupFloor(triangles, refinements, coupling == "full", trim)
        .run();
    }
  catch (const std::exception &exception)
    {
      std::cerr << "setup_floor: " << exception.what() << std::endl;
      return 1;
    }
  return 0;
}
