/**
 * What a matrix-free geometric multigrid costs on the operators of
 * membranes, measured with deal.II's building blocks alone.
 *
 *   gmg_floor s gmg|amg [refinements] [local refinements]
 *   gmg_floor w disk|halfplane|ring [refinements]
 *
 * membranes solves its linear systems by CG preconditioned with Trilinos'
 * ML AMG on assembled matrices. This program measures what the other
 * path, CG with a geometric multigrid V-cycle on matrix-free operators in
 * the way of deal.II's step-37 and step-50, costs on the same meshes, and
 * how it copes with the active set of the contact problem. It does not
 * integrate anything into membranes.
 *
 * The mesh is the square (-1,1)² in a parallel::distributed::Triangulation
 * (p4est) with the multigrid hierarchy, one coarse cell refined
 * @p refinements times (default 10: 1024 × 1024 cells, 1 050 625 DoFs),
 * MappingQ1, FE_Q(1). With @p local refinements > 0 (the `s` problem
 * only), the cells whose centre lies in the disk r < 1/2 are refined that
 * many times more, so that the mesh has hanging nodes and the multigrid
 * smooths locally, on the refined part of each level only (step-50).
 *
 * <h3>The `s` problem</h3>
 *
 * -Δs = 1 in the square, s = 0 on its boundary. With `gmg`: the operator
 * is MatrixFreeOperators::LaplaceOperator on a MatrixFree<2,double> of the
 * active cells with the constraints of the hanging nodes and the boundary;
 * the level operators are the same in float on each level, with the level
 * boundary DoFs of MGConstrainedDoFs as constraints and interface
 * operators on the refinement edges; MGTransferMatrixFree between the
 * levels; Chebyshev smoothing of degree 5 with the inverse diagonal on
 * each level (smoothing range 15, 10 CG iterations for the eigenvalue
 * estimate) and, on the coarse level, Chebyshev iterated to accuracy;
 * Multigrid and PreconditionMG give one V-cycle. With `amg`: the path of
 * membranes, the TrilinosWrappers::SparseMatrix of the same problem
 * assembled with FEValues through the same AffineConstraints, and
 * TrilinosWrappers::PreconditionAMG with the settings of membranes'
 * LinearSolver (elliptic, constant modes, 2 smoother sweeps, deal.II's
 * defaults otherwise). Both solve with CG from zero to a residual of
 * 10⁻¹⁰ times that of the right-hand side.
 *
 * <h3>The `w` problem</h3>
 *
 * Given an active set 𝒜 of vertices (`disk`: r ≤ 1/2; `halfplane`:
 * x < 0.3; `ring`: 0.45 ≤ r ≤ 1/2), CG solves (Π A Π + (I − Π)) w = Π g,
 * A the Laplacian, g the load 1, Π the 0/1 projection on the vertices
 * outside 𝒜: the system in which the active set method of membranes holds
 * w fixed at the active vertices. The operator is the LaplaceOperator on
 * a MatrixFree whose AffineConstraints hold the boundary and the active
 * vertices (its constrained rows are the identity). Three preconditioners,
 * each applied as Π P Π + (I − Π):
 *
 *  (a) P the plain V-cycle of the Laplacian of the `s` problem, the active
 *      set unknown to the levels;
 *  (b) the active set constrained on every level: a level DoF at a vertex
 *      of 𝒜 (the vertices of a level are vertices of the finest mesh) is
 *      added to the constraints of that level's MatrixFree and to
 *      MGConstrainedDoFs::add_user_constraints() as a homogeneous
 *      constraint, so that MGTransferMatrixFree sets it to zero before
 *      each prolongation from that level;
 *  (c) the same on the finest level only, the coarser levels plain.
 *
 * <h3>What is printed</h3>
 *
 * Each step of the setup is timed with std::chrono between two barriers,
 * and after it the peak resident set size (VmHWM of /proc/self/status) and
 * the current one (VmRSS) are read and summed over the processes; they are
 * printed in bytes per DoF of the mesh, the first row at the start of the
 * process (the libraries). The current one stays at the peak, as the
 * memory freed by a step is kept by the allocator: what a step adds is the
 * increase of the peak. Then the time of one preconditioner application
 * (the mean of 5, "V-cycle"; for AMG one ML cycle) and of one product with
 * the operator ("matvec"), also per DoF, the CG iterations and time, and
 * the l2 norm of the solution vector, which does not depend on the
 * numbering of the DoFs and so may be compared between runs on 1 and 2
 * processes. Each process runs on one thread; the rows starting with
 * "| " are what benchmarks/gmg_floor.sh takes the medians of.
 */

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/function.h>
#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/utilities.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/la_parallel_vector.h>
#include <deal.II/lac/precondition.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <deal.II/lac/vector.h>
#include <deal.II/matrix_free/fe_evaluation.h>
#include <deal.II/matrix_free/matrix_free.h>
#include <deal.II/matrix_free/operators.h>
#include <deal.II/multigrid/mg_coarse.h>
#include <deal.II/multigrid/mg_constrained_dofs.h>
#include <deal.II/multigrid/mg_matrix.h>
#include <deal.II/multigrid/mg_smoother.h>
#include <deal.II/multigrid/mg_tools.h>
#include <deal.II/multigrid/mg_transfer_matrix_free.h>
#include <deal.II/multigrid/multigrid.h>
#include <deal.II/numerics/vector_tools.h>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace gmg_floor
{
  using namespace dealii;

  constexpr int dim = 2;

  using VectorType      = LinearAlgebra::distributed::Vector<double>;
  using LevelVectorType = LinearAlgebra::distributed::Vector<float>;
  using SystemMatrixType =
    MatrixFreeOperators::LaplaceOperator<dim, 1, 2, 1, VectorType>;
  using LevelMatrixType =
    MatrixFreeOperators::LaplaceOperator<dim, 1, 2, 1, LevelVectorType>;
  using TransferType = MGTransferMatrixFree<dim, float>;
  using SmootherType = PreconditionChebyshev<LevelMatrixType, LevelVectorType>;
  using PreconditionType = PreconditionMG<dim, LevelVectorType, TransferType>;

  /** The active sets of the `w` problem; `none` for the `s` problem. */
  enum class Shape
  {
    none,
    disk,
    halfplane,
    ring
  };

  /** Whether the vertex at @p p belongs to the active set @p shape. */
  bool
  in_active_set(const Shape shape, const Point<dim> &p)
  {
    const double tolerance = 1e-12;
    const double r         = p.norm();
    switch (shape)
      {
        case Shape::disk:
          return r <= 0.5 + tolerance;
        case Shape::halfplane:
          return p[0] < 0.3;
        case Shape::ring:
          return r >= 0.45 - tolerance && r <= 0.5 + tolerance;
        default:
          return false;
      }
  }



  /**
   * The timed steps: wall time between two barriers, and the peak resident
   * set size of all processes together after the step.
   */
  class Recorder
  {
  public:
    explicit Recorder(const MPI_Comm comm)
      : comm(comm)
    {}

    void
    timed(const std::string &name, const std::function<void()> &action)
    {
      MPI_Barrier(comm);
      const auto start = std::chrono::steady_clock::now();
      action();
      MPI_Barrier(comm);
      const std::chrono::duration<double> seconds =
        std::chrono::steady_clock::now() - start;
      steps.push_back({name, seconds.count(), peak_bytes(), held_bytes()});
    }

    /** A row without a time: the memory of the process when it starts. */
    void
    start()
    {
      steps.push_back(
        {"process start (the libraries)", -1, peak_bytes(), held_bytes()});
    }

    /** The sum over the processes of VmHWM, in bytes. */
    double
    peak_bytes() const
    {
      Utilities::System::MemoryStats memory;
      Utilities::System::get_memory_stats(memory);
      return Utilities::MPI::sum(1024. * memory.VmHWM, comm);
    }

    /** The sum over the processes of VmRSS, in bytes. */
    double
    held_bytes() const
    {
      Utilities::System::MemoryStats memory;
      Utilities::System::get_memory_stats(memory);
      return Utilities::MPI::sum(1024. * memory.VmRSS, comm);
    }

    /** The sum of the times of the steps so far. */
    double
    total() const
    {
      double sum = 0;
      for (const auto &step : steps)
        sum += std::max(step.seconds, 0.);
      return sum;
    }

    void
    print(std::ostream &out, const double n_dofs) const
    {
      out << "| step | s | peak B/DoF | held B/DoF |\n|---|--:|--:|--:|\n";
      for (const auto &step : steps)
        {
          out << "| " << step.name << " | ";
          if (step.seconds >= 0)
            out << std::fixed << std::setprecision(3) << step.seconds;
          out << " | " << std::fixed << std::setprecision(0)
              << step.peak / n_dofs << " | " << step.held / n_dofs << " |\n";
        }
      out << "| **the steps above** | " << std::setprecision(3) << total()
          << " | | |\n";
    }

  private:
    struct Step
    {
      std::string name;
      double      seconds;
      double      peak;
      double      held;
    };
    const MPI_Comm    comm;
    std::vector<Step> steps;
  };



  /**
   * The multigrid preconditioner of step-37: level operators, transfer,
   * Chebyshev smoother, coarse solver, V-cycle. The active set of
   * @p shape, if any, is constrained on the levels from @p
   * first_constrained_level on (variants (b) and (c) of the `w` problem).
   */
  class GeometricMultigrid
  {
  public:
    GeometricMultigrid(const DoFHandler<dim> &dof_handler,
                       const Mapping<dim>    &mapping,
                       const Shape            shape,
                       const unsigned int     first_constrained_level,
                       Recorder              &recorder,
                       const std::string     &label);

    const PreconditionType &
    preconditioner() const
    {
      return *mg_preconditioner;
    }

  private:
    MGConstrainedDoFs              constrained_dofs;
    MGLevelObject<LevelMatrixType> matrices;
    MGLevelObject<MatrixFreeOperators::MGInterfaceOperator<LevelMatrixType>>
                                                          interface_matrices;
    TransferType                                          transfer;
    mg::SmootherRelaxation<SmootherType, LevelVectorType> smoother;
    MGCoarseGridApplySmoother<LevelVectorType>            coarse;
    mg::Matrix<LevelVectorType>                           matrix_wrapper;
    mg::Matrix<LevelVectorType>                           interface_wrapper;
    std::unique_ptr<Multigrid<LevelVectorType>>           multigrid;
    std::unique_ptr<PreconditionType>                     mg_preconditioner;
  };



  GeometricMultigrid::GeometricMultigrid(
    const DoFHandler<dim> &dof_handler,
    const Mapping<dim>    &mapping,
    const Shape            shape,
    const unsigned int     first_constrained_level,
    Recorder              &recorder,
    const std::string     &label)
  {
    const unsigned int n_levels =
      dof_handler.get_triangulation().n_global_levels();

    recorder.timed(label + "levels: constrained DoFs, level MatrixFree", [&]() {
      constrained_dofs.initialize(dof_handler);
      constrained_dofs.make_zero_boundary_constraints(dof_handler, {0});
      matrices.resize(0, n_levels - 1);
      for (unsigned int level = 0; level < n_levels; ++level)
        {
          IndexSet relevant_dofs;
          DoFTools::extract_locally_relevant_level_dofs(dof_handler,
                                                        level,
                                                        relevant_dofs);
          AffineConstraints<double> level_constraints(relevant_dofs);
          level_constraints.add_lines(
            constrained_dofs.get_boundary_indices(level));

          if (shape != Shape::none && level >= first_constrained_level)
            {
              // The level DoFs at the vertices of the active set, as
              // homogeneous constraints of the level operator and as user
              // constraints of the transfer.
              AffineConstraints<double>            active(relevant_dofs);
              std::vector<types::global_dof_index> indices(
                dof_handler.get_fe().n_dofs_per_cell());
              for (const auto &cell :
                   dof_handler.mg_cell_iterators_on_level(level))
                if (cell->level_subdomain_id() !=
                    numbers::artificial_subdomain_id)
                  {
                    cell->get_mg_dof_indices(indices);
                    for (const unsigned int v : cell->vertex_indices())
                      if (in_active_set(shape, cell->vertex(v)) &&
                          !constrained_dofs.is_boundary_index(level,
                                                              indices[v]) &&
                          !active.is_constrained(indices[v]))
                        active.add_line(indices[v]);
                  }
              active.close();
              level_constraints.merge(
                active,
                AffineConstraints<
                  double>::MergeConflictBehavior::right_object_wins);
              constrained_dofs.add_user_constraints(level, active);
            }
          level_constraints.close();

          typename MatrixFree<dim, float>::AdditionalData data;
          data.tasks_parallel_scheme =
            MatrixFree<dim, float>::AdditionalData::none;
          data.mapping_update_flags = update_gradients | update_JxW_values;
          data.mg_level             = level;
          auto level_storage = std::make_shared<MatrixFree<dim, float>>();
          level_storage->reinit(
            mapping, dof_handler, level_constraints, QGauss<1>(2), data);
          matrices[level].initialize(level_storage, constrained_dofs, level);
        }
    });

    recorder.timed(label + "transfer", [&]() {
      transfer.initialize_constraints(constrained_dofs);
      transfer.build(dof_handler);
    });

    recorder.timed(label + "smoother: diagonals, eigenvalue estimates", [&]() {
      MGLevelObject<SmootherType::AdditionalData> smoother_data(0,
                                                                n_levels - 1);
      for (unsigned int level = 0; level < n_levels; ++level)
        {
          if (level > 0)
            {
              smoother_data[level].smoothing_range     = 15.;
              smoother_data[level].degree              = 5;
              smoother_data[level].eig_cg_n_iterations = 10;
            }
          else
            {
              smoother_data[0].smoothing_range = 1e-3;
              smoother_data[0].degree          = numbers::invalid_unsigned_int;
              smoother_data[0].eig_cg_n_iterations = matrices[0].m();
            }
          matrices[level].compute_diagonal();
          smoother_data[level].preconditioner =
            matrices[level].get_matrix_diagonal_inverse();
        }
      smoother.initialize(matrices, smoother_data);
      coarse.initialize(smoother);

      interface_matrices.resize(0, n_levels - 1);
      for (unsigned int level = 0; level < n_levels; ++level)
        interface_matrices[level].initialize(matrices[level]);
      matrix_wrapper.initialize(matrices);
      interface_wrapper.initialize(interface_matrices);

      multigrid = std::make_unique<Multigrid<LevelVectorType>>(
        matrix_wrapper, coarse, transfer, smoother, smoother);
      multigrid->set_edge_matrices(interface_wrapper, interface_wrapper);
      mg_preconditioner =
        std::make_unique<PreconditionType>(dof_handler, *multigrid, transfer);
    });
  }



  /**
   * A preconditioner P applied as Π P Π + (I − Π), Π the projection on the
   * DoFs that the operator does not hold fixed (the constrained DoFs of
   * its MatrixFree: the boundary and, in the `w` problem, the active set).
   */
  template <typename Preconditioner>
  class Projected
  {
  public:
    Projected(const Preconditioner            &preconditioner,
              const std::vector<unsigned int> &fixed)
      : preconditioner(preconditioner)
      , fixed(fixed)
    {}

    void
    vmult(VectorType &dst, const VectorType &src) const
    {
      projected.reinit(src, true);
      projected = src;
      for (const unsigned int i : fixed)
        projected.local_element(i) = 0;
      preconditioner.vmult(dst, projected);
      for (const unsigned int i : fixed)
        dst.local_element(i) = src.local_element(i);
    }

  private:
    const Preconditioner            &preconditioner;
    const std::vector<unsigned int> &fixed;
    mutable VectorType               projected;
  };



  /** The mean wall time of 5 applications of @p preconditioner. */
  template <typename Preconditioner, typename Vector>
  double
  cycle_time(const Preconditioner &preconditioner,
             const Vector         &src,
             const MPI_Comm        comm)
  {
    Vector dst(src);
    preconditioner.vmult(dst, src);
    MPI_Barrier(comm);
    const auto start = std::chrono::steady_clock::now();
    for (unsigned int k = 0; k < 5; ++k)
      preconditioner.vmult(dst, src);
    MPI_Barrier(comm);
    const std::chrono::duration<double> seconds =
      std::chrono::steady_clock::now() - start;
    return seconds.count() / 5;
  }



  /** One result row of the second table. */
  struct Result
  {
    std::string label;
    double      setup, cycle, iterations, solve, matvec;
  };

  void
  print_results(std::ostream              &out,
                const std::vector<Result> &results,
                const double               n_dofs)
  {
    out << "\n| preconditioner | setup s | V-cycle s | V-cycle ns/DoF "
           "| CG its | CG s | matvec ns/DoF |\n"
           "|---|--:|--:|--:|--:|--:|--:|\n";
    for (const auto &r : results)
      out << "| " << r.label << " | " << std::fixed << std::setprecision(3)
          << r.setup << " | " << std::setprecision(4) << r.cycle << " | "
          << std::setprecision(1) << 1e9 * r.cycle / n_dofs << " | "
          << std::setprecision(0) << r.iterations << " | "
          << std::setprecision(3) << r.solve << " | " << std::setprecision(1)
          << 1e9 * r.matvec / n_dofs << " |\n";
  }



  /** The mesh, the DoFs and the constraints of both problems. */
  class Benchmark
  {
  public:
    Benchmark(const unsigned int refinements,
              const unsigned int local_refinements,
              const Shape        shape,
              const bool         multigrid);

    void
    run_s_gmg();
    void
    run_s_amg();
    void
    run_w();

  private:
    void
    setup_matrix_free();
    void
    assemble_rhs();
    template <typename Preconditioner>
    unsigned int
    solve(const Preconditioner &preconditioner);
    void
    print(const std::vector<Result> &results);

    const MPI_Comm                            comm;
    const Shape                               shape;
    Recorder                                  recorder;
    ConditionalOStream                        pcout;
    parallel::distributed::Triangulation<dim> triangulation;
    MappingQ1<dim>                            mapping;
    FE_Q<dim>                                 fe;
    DoFHandler<dim>                           dof_handler;
    IndexSet                                  locally_relevant_dofs;
    AffineConstraints<double>                 constraints;
    SystemMatrixType                          system_matrix;
    VectorType                                solution, rhs;
    std::vector<double>                       norms;
  };



  Benchmark::Benchmark(const unsigned int refinements,
                       const unsigned int local_refinements,
                       const Shape        shape,
                       const bool         multigrid)
    : comm(MPI_COMM_WORLD)
    , shape(shape)
    , recorder(comm)
    , pcout(std::cout, Utilities::MPI::this_mpi_process(comm) == 0)
    , triangulation(
        comm,
        Triangulation<dim>::limit_level_difference_at_vertices,
        multigrid ? parallel::distributed::Triangulation<
                      dim>::construct_multigrid_hierarchy :
                    parallel::distributed::Triangulation<dim>::default_setting)
    , fe(1)
    , dof_handler(triangulation)
  {
    recorder.start();
    recorder.timed("mesh", [&]() {
      GridGenerator::hyper_cube(triangulation, -1, 1);
      triangulation.refine_global(refinements);
      for (unsigned int k = 0; k < local_refinements; ++k)
        {
          for (const auto &cell : triangulation.active_cell_iterators())
            if (cell->is_locally_owned() && cell->center().norm() < 0.5)
              cell->set_refine_flag();
          triangulation.execute_coarsening_and_refinement();
        }
    });
    recorder.timed("DoFs, constraints", [&]() {
      dof_handler.distribute_dofs(fe);
      if (multigrid)
        dof_handler.distribute_mg_dofs();
      DoFTools::extract_locally_relevant_dofs(dof_handler,
                                              locally_relevant_dofs);
      constraints.reinit(locally_relevant_dofs);
      DoFTools::make_hanging_node_constraints(dof_handler, constraints);
      VectorTools::interpolate_boundary_values(
        mapping, dof_handler, 0, Functions::ZeroFunction<dim>(), constraints);
      if (shape != Shape::none)
        {
          std::vector<types::global_dof_index> indices(fe.n_dofs_per_cell());
          for (const auto &cell : dof_handler.active_cell_iterators())
            if (!cell->is_artificial())
              {
                cell->get_dof_indices(indices);
                for (const unsigned int v : cell->vertex_indices())
                  if (in_active_set(shape, cell->vertex(v)) &&
                      !constraints.is_constrained(indices[v]))
                    constraints.add_line(indices[v]);
              }
        }
      constraints.close();
    });
    pcout << "cells " << triangulation.n_global_active_cells() << ", DoFs "
          << dof_handler.n_dofs() << ", levels "
          << triangulation.n_global_levels() << ", processes "
          << Utilities::MPI::n_mpi_processes(comm) << ", load average " <<
      [] {
        std::ifstream in("/proc/loadavg");
        std::string   a, b, c;
        in >> a >> b >> c;
        return a + " " + b + " " + c;
      }() << "\n\n";
  }



  void
  Benchmark::setup_matrix_free()
  {
    recorder.timed("active MatrixFree, vectors, right-hand side", [&]() {
      typename MatrixFree<dim, double>::AdditionalData data;
      data.tasks_parallel_scheme =
        MatrixFree<dim, double>::AdditionalData::none;
      data.mapping_update_flags = update_gradients | update_JxW_values;
      auto storage              = std::make_shared<MatrixFree<dim, double>>();
      storage->reinit(mapping, dof_handler, constraints, QGauss<1>(2), data);
      system_matrix.initialize(storage);
      system_matrix.initialize_dof_vector(solution);
      system_matrix.initialize_dof_vector(rhs);
      assemble_rhs();
    });
  }



  /** The load 1, zero in the constrained rows (Π g in the `w` problem). */
  void
  Benchmark::assemble_rhs()
  {
    rhs = 0;
    FEEvaluation<dim, 1, 2, 1, double> phi(*system_matrix.get_matrix_free());
    for (unsigned int cell = 0;
         cell < system_matrix.get_matrix_free()->n_cell_batches();
         ++cell)
      {
        phi.reinit(cell);
        for (const unsigned int q : phi.quadrature_point_indices())
          phi.submit_value(make_vectorized_array<double>(1.), q);
        phi.integrate(EvaluationFlags::values);
        phi.distribute_local_to_global(rhs);
      }
    rhs.compress(VectorOperation::add);
  }



  /** CG from zero to a residual of 10⁻¹⁰ times that of the right-hand side. */
  template <typename Preconditioner>
  unsigned int
  Benchmark::solve(const Preconditioner &preconditioner)
  {
    SolverControl        control(2000, 1e-10 * rhs.l2_norm());
    SolverCG<VectorType> cg(control);
    solution = 0;
    cg.solve(system_matrix, solution, rhs, preconditioner);
    constraints.distribute(solution);
    norms.push_back(solution.l2_norm());
    return control.last_step();
  }



  void
  Benchmark::print(const std::vector<Result> &results)
  {
    std::ostringstream out;
    recorder.print(out, dof_handler.n_dofs());
    print_results(out, results, dof_handler.n_dofs());
    out << "\n";
    for (unsigned int k = 0; k < results.size(); ++k)
      out << "l2 norm of the solution, " << results[k].label << ": "
          << std::scientific << std::setprecision(15) << norms[k] << "\n";
    out << "peak memory at the end, all processes: " << std::fixed
        << std::setprecision(0) << recorder.peak_bytes() / dof_handler.n_dofs()
        << " B/DoF\n";
    pcout << out.str() << std::flush;
  }



  void
  Benchmark::run_s_gmg()
  {
    setup_matrix_free();
    const double       start = recorder.total();
    GeometricMultigrid gmg(dof_handler,
                           mapping,
                           Shape::none,
                           numbers::invalid_unsigned_int,
                           recorder,
                           "");
    const double       setup = recorder.total() - start;

    Result result{"GMG V-cycle", setup, 0, 0, 0, 0};
    recorder.timed("CG solve",
                   [&]() { result.iterations = solve(gmg.preconditioner()); });
    result.solve  = recorder.total() - start - setup;
    result.cycle  = cycle_time(gmg.preconditioner(), rhs, comm);
    result.matvec = cycle_time(system_matrix, rhs, comm);
    print({result});
  }



  void
  Benchmark::run_s_amg()
  {
    const IndexSet                   &owned = dof_handler.locally_owned_dofs();
    TrilinosWrappers::SparseMatrix    matrix;
    TrilinosWrappers::MPI::Vector     amg_rhs(owned, comm);
    TrilinosWrappers::MPI::Vector     amg_solution(owned, comm);
    TrilinosWrappers::PreconditionAMG amg;

    recorder.timed("sparsity pattern, matrix reinit", [&]() {
      DynamicSparsityPattern dsp(locally_relevant_dofs);
      DoFTools::make_sparsity_pattern(dof_handler, dsp, constraints, false);
      SparsityTools::distribute_sparsity_pattern(dsp,
                                                 owned,
                                                 comm,
                                                 locally_relevant_dofs);
      matrix.reinit(owned, owned, dsp, comm);
    });
    recorder.timed("assembly", [&]() {
      const QGauss<dim>                    quadrature(2);
      FEValues<dim>                        fe_values(mapping,
                              fe,
                              quadrature,
                              update_values | update_gradients |
                                update_JxW_values);
      const unsigned int                   n = fe.n_dofs_per_cell();
      FullMatrix<double>                   cell_matrix(n, n);
      Vector<double>                       cell_rhs(n);
      std::vector<types::global_dof_index> indices(n);
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
          {
            fe_values.reinit(cell);
            cell_matrix = 0;
            cell_rhs    = 0;
            for (const unsigned int q : fe_values.quadrature_point_indices())
              for (unsigned int i = 0; i < n; ++i)
                {
                  for (unsigned int j = 0; j < n; ++j)
                    cell_matrix(i, j) += fe_values.shape_grad(i, q) *
                                         fe_values.shape_grad(j, q) *
                                         fe_values.JxW(q);
                  cell_rhs(i) += fe_values.shape_value(i, q) * fe_values.JxW(q);
                }
            cell->get_dof_indices(indices);
            constraints.distribute_local_to_global(
              cell_matrix, cell_rhs, indices, matrix, amg_rhs);
          }
      matrix.compress(VectorOperation::add);
      amg_rhs.compress(VectorOperation::add);
    });
    const double start = recorder.total();
    recorder.timed("AMG setup", [&]() {
      std::vector<std::vector<bool>> constant_modes;
      DoFTools::extract_constant_modes(dof_handler,
                                       ComponentMask(),
                                       constant_modes);
      TrilinosWrappers::PreconditionAMG::AdditionalData amg_data;
      amg_data.elliptic              = true;
      amg_data.higher_order_elements = false;
      amg_data.constant_modes        = constant_modes;
      amg_data.smoother_sweeps       = 2;
      amg.initialize(matrix, amg_data);
    });
    const double setup = recorder.total() - start;

    Result result{"ML AMG", setup, 0, 0, 0, 0};
    recorder.timed("CG solve", [&]() {
      SolverControl control(2000, 1e-10 * amg_rhs.l2_norm());
      SolverCG<TrilinosWrappers::MPI::Vector> cg(control);
      cg.solve(matrix, amg_solution, amg_rhs, amg);
      constraints.distribute(amg_solution);
      norms.push_back(amg_solution.l2_norm());
      result.iterations = control.last_step();
    });
    result.solve  = recorder.total() - start - setup;
    result.cycle  = cycle_time(amg, amg_rhs, comm);
    result.matvec = cycle_time(matrix, amg_rhs, comm);
    print({result});
  }



  void
  Benchmark::run_w()
  {
    setup_matrix_free();
    const auto &fixed = system_matrix.get_matrix_free()->get_constrained_dofs();
    const unsigned int n_fixed = Utilities::MPI::sum(fixed.size(), comm);
    pcout << "active set and boundary: " << n_fixed << " of "
          << dof_handler.n_dofs() << " DoFs fixed\n\n";

    const unsigned int finest = triangulation.n_global_levels() - 1;
    const std::vector<std::pair<std::string, unsigned int>> variants = {
      {"(a) plain levels", numbers::invalid_unsigned_int},
      {"(b) active set on every level", 0},
      {"(c) active set on the finest level", finest}};
    std::vector<Result> results;
    for (const auto &[label, first_level] : variants)
      {
        const double start = recorder.total();
        Result       result{label, 0, 0, 0, 0, 0};
        {
          const std::string  prefix = label.substr(0, 3) + " ";
          GeometricMultigrid gmg(
            dof_handler, mapping, shape, first_level, recorder, prefix);
          result.setup = recorder.total() - start;
          const Projected<PreconditionType> preconditioner(gmg.preconditioner(),
                                                           fixed);
          recorder.timed(prefix + "CG solve",
                         [&]() { result.iterations = solve(preconditioner); });
          result.solve  = recorder.total() - start - result.setup;
          result.cycle  = cycle_time(preconditioner, rhs, comm);
          result.matvec = cycle_time(system_matrix, rhs, comm);
        }
        results.push_back(result);
      }
    print(results);
  }
} // namespace gmg_floor



int
main(int argc, char **argv)
{
  using namespace gmg_floor;
  try
    {
      // One thread per process: the measured work is that of the process.
      Utilities::MPI::MPI_InitFinalize mpi_initialization(argc, argv, 1);
      const std::string                problem = (argc > 1) ? argv[1] : "s";
      const std::string                variant =
        (argc > 2) ? argv[2] : (problem == "w" ? "disk" : "gmg");
      const unsigned int refinements = (argc > 3) ? std::stoul(argv[3]) : 10;
      const unsigned int local       = (argc > 4) ? std::stoul(argv[4]) : 0;

      if (problem == "s" && (variant == "gmg" || variant == "amg"))
        {
          Benchmark benchmark(refinements,
                              local,
                              Shape::none,
                              variant == "gmg");
          if (variant == "gmg")
            benchmark.run_s_gmg();
          else
            benchmark.run_s_amg();
        }
      else if (problem == "w" && (variant == "disk" || variant == "halfplane" ||
                                  variant == "ring"))
        {
          const Shape shape = variant == "disk"      ? Shape::disk :
                              variant == "halfplane" ? Shape::halfplane :
                                                       Shape::ring;
          Benchmark   benchmark(refinements, 0, shape, true);
          benchmark.run_w();
        }
      else
        throw std::invalid_argument(
          "usage: gmg_floor s gmg|amg [refinements] [local refinements]\n"
          "       gmg_floor w disk|halfplane|ring [refinements]");
    }
  catch (const std::exception &exception)
    {
      std::cerr << "gmg_floor: error: " << exception.what() << std::endl;
      return 1;
    }
  return 0;
}
