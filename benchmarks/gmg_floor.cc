/**
 * What a geometric multigrid costs on the operators of membranes, matrix-
 * free or on assembled level matrices, measured with deal.II's building
 * blocks alone.
 *
 *   gmg_floor s gmg|amg|gmgmatrix [refinements] [local refinements] [degree]
 *   gmg_floor w disk|halfplane|ring [refinements] [degree]
 *
 * membranes solves its linear systems by CG preconditioned with Trilinos'
 * ML AMG on assembled matrices. This program measures what the other
 * path, CG with a geometric multigrid V-cycle, costs on the same meshes,
 * on matrix-free operators in the way of deal.II's step-37 and step-50 or
 * on assembled level matrices in the way of step-16 and the matrix-based
 * path of step-50, and how it copes with the active set of the contact
 * problem. It does not integrate anything into membranes. The matrix-free
 * V-cycle is in benchmarks/gmg_floor_matrix_free.cc, the V-cycle on level
 * matrices in benchmarks/gmg_floor_matrix.cc, the parts that the three
 * files share in benchmarks/gmg_floor.h.
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
 * defaults otherwise). With `gmgmatrix`: the same assembled matrix, and a
 * V-cycle on level matrices: on each level a TrilinosWrappers::SparseMatrix
 * (double) of the Laplacian assembled on the cells of the level, its rows
 * at the level boundary DoFs and at the refinement edges left with their
 * diagonal, and interface matrices on the refinement edges (step-16);
 * MGTransferPrebuilt between the levels; Chebyshev smoothing of degree
 * @p degree (default 4) with the inverse of the diagonal of the level
 * matrix, smoothing range 15 and 10 CG iterations for the eigenvalue
 * estimate as for `gmg`, so that a V-cycle needs only sparse products,
 * vector updates and the sparse transfer. All three solve with CG from
 * zero to a residual of 10⁻¹⁰ times that of the right-hand side.
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
 * each applied as Π P Π + (I − Π), and two on the assembled matrix:
 *
 *  (a) P the plain V-cycle of the Laplacian of the `s` problem, the active
 *      set unknown to the levels;
 *  (b) the active set constrained on every level: a level DoF at a vertex
 *      of 𝒜 (the vertices of a level are vertices of the finest mesh) is
 *      added to the constraints of that level's MatrixFree and to
 *      MGConstrainedDoFs::add_user_constraints() as a homogeneous
 *      constraint, so that MGTransferMatrixFree sets it to zero before
 *      each prolongation from that level;
 *  (c) the same on the finest level only, the coarser levels plain;
 *  (d) (b) on assembled level matrices: the operator is the assembled
 *      matrix of `amg` (its rows at 𝒜 and the boundary keep their
 *      diagonal), P the V-cycle of `gmgmatrix` whose level DoFs at
 *      vertices of 𝒜 (the same as (b)'s) are added to the level boundary
 *      DoFs of MGConstrainedDoFs: the level matrices keep only their
 *      diagonal in those rows and columns, and MGTransferPrebuilt does not
 *      prolongate from them;
 *  (e) for comparison, the path of membranes: ML as in `amg` on the
 *      assembled matrix of (d), not projected.
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
 * the operator ("matvec", matrix-free or sparse), also per DoF, the CG
 * iterations and time, and the l2 norm of the solution vector, which does not
 * depend on the numbering of the DoFs and so may be compared between runs on 1
 * and 2 processes. Each process runs on one thread; the rows starting with
 * "| " are what benchmarks/gmg_floor.sh takes the medians of.
 */

#include "gmg_floor.h"

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
#include <deal.II/multigrid/mg_constrained_dofs.h>
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
  IndexSet
  active_level_dofs(const DoFHandler<dim>   &dof_handler,
                    const unsigned int       level,
                    const Shape              shape,
                    const MGConstrainedDoFs &constrained_dofs)
  {
    IndexSet                             active(dof_handler.n_dofs(level));
    std::vector<types::global_dof_index> indices(
      dof_handler.get_fe().n_dofs_per_cell());
    for (const auto &cell : dof_handler.mg_cell_iterators_on_level(level))
      if (cell->level_subdomain_id() != numbers::artificial_subdomain_id)
        {
          cell->get_mg_dof_indices(indices);
          for (const unsigned int v : cell->vertex_indices())
            if (in_active_set(shape, cell->vertex(v)) &&
                !constrained_dofs.is_boundary_index(level, indices[v]))
              active.add_index(indices[v]);
        }
    active.compress();
    return active;
  }



  /**
   * A preconditioner P applied as Π P Π + (I − Π), Π the projection on the
   * DoFs that the operator does not hold fixed (the boundary and, in the
   * `w` problem, the active set), given by their positions @p fixed in
   * the local storage of the vectors (the constrained DoFs of a MatrixFree,
   * or the constrained locally owned DoFs of a Trilinos vector).
   */
  template <typename Preconditioner, typename Vector = VectorType>
  class Projected
  {
  public:
    Projected(const Preconditioner            &preconditioner,
              const std::vector<unsigned int> &fixed)
      : preconditioner(preconditioner)
      , fixed(fixed)
    {}

    void
    vmult(Vector &dst, const Vector &src) const
    {
      projected.reinit(src, true);
      projected = src;
      for (const unsigned int i : fixed)
        projected.begin()[i] = 0;
      preconditioner.vmult(dst, projected);
      for (const unsigned int i : fixed)
        dst.begin()[i] = src.begin()[i];
    }

  private:
    const Preconditioner            &preconditioner;
    const std::vector<unsigned int> &fixed;
    mutable Vector                   projected;
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
    run_s_gmgmatrix(const unsigned int degree);
    void
    run_w(const unsigned int degree);

  private:
    void
    setup_matrix_free();
    void
    assemble_rhs();
    /** The assembled matrix and vectors of the problem (Trilinos). */
    struct SparseSystem
    {
      SparseMatrixType matrix;
      SparseVectorType rhs, solution;
    };
    void
    assemble_sparse(SparseSystem &system, const std::string &prefix);
    void
    initialize_amg(const SparseSystem                &system,
                   TrilinosWrappers::PreconditionAMG &amg,
                   const std::string                 &prefix);
    template <typename Matrix, typename Vector, typename Preconditioner>
    Result
    solve(const std::string    &label,
          const double          setup_start,
          const Matrix         &matrix,
          Vector               &solution,
          const Vector         &rhs,
          const Preconditioner &preconditioner);
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



  /**
   * CG from zero to a residual of 10⁻¹⁰ times that of the right-hand side,
   * timed as the step "<prefix of label> CG solve", and the result row:
   * setup the time of the steps since @p setup_start, the V-cycle and the
   * operator product timed after the solve.
   */
  template <typename Matrix, typename Vector, typename Preconditioner>
  Result
  Benchmark::solve(const std::string    &label,
                   const double          setup_start,
                   const Matrix         &matrix,
                   Vector               &solution,
                   const Vector         &rhs,
                   const Preconditioner &preconditioner)
  {
    Result            result{label, recorder.total() - setup_start, 0, 0, 0, 0};
    const std::string prefix = label[0] == '(' ? label.substr(0, 4) : "";
    recorder.timed(prefix + "CG solve", [&]() {
      SolverControl    control(2000, 1e-10 * rhs.l2_norm());
      SolverCG<Vector> cg(control);
      solution = 0;
      cg.solve(matrix, solution, rhs, preconditioner);
      constraints.distribute(solution);
      norms.push_back(solution.l2_norm());
      result.iterations = control.last_step();
    });
    result.solve  = recorder.total() - setup_start - result.setup;
    result.cycle  = cycle_time(preconditioner, rhs, comm);
    result.matvec = cycle_time(matrix, rhs, comm);
    return result;
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
    print({solve("GMG V-cycle",
                 start,
                 system_matrix,
                 solution,
                 rhs,
                 gmg.preconditioner())});
  }



  /**
   * The matrix of the problem assembled with FEValues through the
   * AffineConstraints into a TrilinosWrappers::SparseMatrix, and the
   * right-hand side; the constrained rows keep only their diagonal.
   */
  void
  Benchmark::assemble_sparse(SparseSystem &system, const std::string &prefix)
  {
    const IndexSet &owned = dof_handler.locally_owned_dofs();
    recorder.timed(prefix + "sparsity pattern, matrix reinit", [&]() {
      DynamicSparsityPattern dsp(locally_relevant_dofs);
      DoFTools::make_sparsity_pattern(dof_handler, dsp, constraints, false);
      SparsityTools::distribute_sparsity_pattern(dsp,
                                                 owned,
                                                 comm,
                                                 locally_relevant_dofs);
      system.matrix.reinit(owned, owned, dsp, comm);
      system.rhs.reinit(owned, comm);
      system.solution.reinit(owned, comm);
    });
    recorder.timed(prefix + "assembly", [&]() {
      CellLaplacian local(mapping, fe);
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
          {
            local.reinit(cell);
            cell->get_dof_indices(local.indices);
            constraints.distribute_local_to_global(local.matrix,
                                                   local.rhs,
                                                   local.indices,
                                                   system.matrix,
                                                   system.rhs);
          }
      system.matrix.compress(VectorOperation::add);
      system.rhs.compress(VectorOperation::add);
    });
  }



  void
  Benchmark::run_s_amg()
  {
    SparseSystem system;
    assemble_sparse(system, "");
    TrilinosWrappers::PreconditionAMG amg;
    const double                      start = recorder.total();
    initialize_amg(system, amg, "");
    print({solve(
      "ML AMG", start, system.matrix, system.solution, system.rhs, amg)});
  }



  /** ML on @p system with the settings of membranes' LinearSolver. */
  void
  Benchmark::initialize_amg(const SparseSystem                &system,
                            TrilinosWrappers::PreconditionAMG &amg,
                            const std::string                 &prefix)
  {
    recorder.timed(prefix + "AMG setup", [&]() {
      std::vector<std::vector<bool>> constant_modes;
      DoFTools::extract_constant_modes(dof_handler,
                                       ComponentMask(),
                                       constant_modes);
      TrilinosWrappers::PreconditionAMG::AdditionalData amg_data;
      amg_data.elliptic              = true;
      amg_data.higher_order_elements = false;
      amg_data.constant_modes        = constant_modes;
      amg_data.smoother_sweeps       = 2;
      amg.initialize(system.matrix, amg_data);
    });
  }



  void
  Benchmark::run_s_gmgmatrix(const unsigned int degree)
  {
    SparseSystem system;
    assemble_sparse(system, "");
    const double         start = recorder.total();
    MatrixBasedMultigrid gmg(
      dof_handler, mapping, Shape::none, degree, recorder, "");
    print({solve("GMG V-cycle, level matrices",
                 start,
                 system.matrix,
                 system.solution,
                 system.rhs,
                 gmg.preconditioner())});
  }



  void
  Benchmark::run_w(const unsigned int degree)
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
        const double                      start = recorder.total();
        GeometricMultigrid                gmg(dof_handler,
                               mapping,
                               shape,
                               first_level,
                               recorder,
                               label.substr(0, 4));
        const Projected<PreconditionType> preconditioner(gmg.preconditioner(),
                                                         fixed);
        results.push_back(
          solve(label, start, system_matrix, solution, rhs, preconditioner));
      }

    // (d): (b) on assembled level matrices, for the assembled operator.
    {
      SparseSystem system;
      assemble_sparse(system, "(d) ");
      const IndexSet           &owned = dof_handler.locally_owned_dofs();
      std::vector<unsigned int> fixed_owned;
      for (unsigned int i = 0; i < owned.n_elements(); ++i)
        if (constraints.is_constrained(owned.nth_index_in_set(i)))
          fixed_owned.push_back(i);
      const double         start = recorder.total();
      MatrixBasedMultigrid gmg(
        dof_handler, mapping, shape, degree, recorder, "(d) ");
      const Projected<SparsePreconditionType, SparseVectorType> preconditioner(
        gmg.preconditioner(), fixed_owned);
      results.push_back(solve("(d) (b) on level matrices",
                              start,
                              system.matrix,
                              system.solution,
                              system.rhs,
                              preconditioner));

      // (e): membranes' path, ML on the same assembled matrix.
      TrilinosWrappers::PreconditionAMG amg;
      const double                      amg_start = recorder.total();
      initialize_amg(system, amg, "(e) ");
      results.push_back(solve("(e) ML AMG",
                              amg_start,
                              system.matrix,
                              system.solution,
                              system.rhs,
                              amg));
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
      const unsigned int local =
        (argc > 4 && problem == "s") ? std::stoul(argv[4]) : 0;
      // The degree of the Chebyshev smoother on level matrices: the last
      // argument after the refinements.
      const int          degree_argument = problem == "s" ? 5 : 4;
      const unsigned int degree          = (argc > degree_argument) ?
                                             std::stoul(argv[degree_argument]) :
                                             default_matrix_degree;

      if (problem == "s" &&
          (variant == "gmg" || variant == "amg" || variant == "gmgmatrix"))
        {
          Benchmark benchmark(refinements,
                              local,
                              Shape::none,
                              variant != "amg");
          if (variant == "gmg")
            benchmark.run_s_gmg();
          else if (variant == "gmgmatrix")
            benchmark.run_s_gmgmatrix(degree);
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
          benchmark.run_w(degree);
        }
      else
        throw std::invalid_argument(
          "usage: gmg_floor s gmg|amg|gmgmatrix [refinements] "
          "[local refinements] [degree]\n"
          "       gmg_floor w disk|halfplane|ring [refinements] [degree]");
    }
  catch (const std::exception &exception)
    {
      std::cerr << "gmg_floor: error: " << exception.what() << std::endl;
      return 1;
    }
  return 0;
}
