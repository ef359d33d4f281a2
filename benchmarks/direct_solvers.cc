/**
 * UMFPACK against MUMPS on the direct solves that `Linear solver = auto`
 * makes on one process (benchmarks/choices.md, "The direct solver on one
 * process"):
 *
 *   build/direct_solvers [repetitions [largest unknowns]]
 *
 * Defaults: 11 repetitions, meshes up to 10 000 unknowns. Four scenes of
 * parameters/ on one process: the default scene (disk, Q1, adaptive) and the
 * same on triangles (P1), and case M on the square under uniform refinement
 * (Q1 and P1). The meshes, the matrices and the active sets are the
 * program's: MembraneProblem's steps written out with the library's classes
 * (create_mesh, DiscreteProblem, ActiveSetSolver, ErrorEstimator, mark_cells),
 * the adaptive meshes refined by the residual indicators with the scene's
 * marking. On every mesh, after the active set method has converged, the two
 * scalar systems of DecoupledSystem are solved directly:
 *
 * - S: the Laplacian A of the mesh, condensed with the hanging node
 *   constraints and the boundary values (DiscreteProblem::laplace_matrix());
 * - W: μ̄ A with the rows and columns of the active vertices eliminated (the
 *   contact lines W_a = 0), the matrix that the direct solver factorizes at
 *   every active set iteration: DecoupledSystem condenses it from the cell
 *   matrices, with the same sparsity pattern and entries (but for the
 *   diagonal of an active vertex that constrains hanging vertices, which
 *   holds their shares here).
 *
 * Each is solved by factorization and solve, `repetitions` times, by MUMPS
 * through Amesos (TrilinosWrappers::SolverDirect with Amesos_Mumps, on the
 * Trilinos matrix) and by LinearSolver::solve_direct() on one process
 * (SparseDirectUMFPACK on a deal.II SparseMatrix copied from the Trilinos
 * matrix, the copy included), the two in turn. The table gives the medians
 * of the CPU times in milliseconds (the two are sequential; on a loaded
 * machine the wall time also holds the other jobs), the ratio of the sums
 * S + W by CPU and by wall time, and the larger relative difference of the
 * two solutions.
 */

#include <algorithm>
#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/timer.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/trilinos_solver.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <deal.II/lac/vector.h>
#include <functional>
#include <iomanip>
#include <iostream>
#include <membranes/active_set/active_set.h>
#include <membranes/active_set/active_set_solver.h>
#include <membranes/active_set/linear_solver.h>
#include <membranes/dual_mesh/discrete_action.h>
#include <membranes/dual_mesh/dual_mesh.h>
#include <membranes/estimators/error_estimator.h>
#include <membranes/mesh/cell_marking.h>
#include <membranes/mesh/discrete_problem.h>
#include <membranes/mesh/discretization.h>
#include <membranes/scene/parameters.h>
#include <membranes/scene/problem_data.h>
#include <string>
#include <vector>

using namespace dealii;
using namespace membranes;

namespace
{
  constexpr int dim = 2;
  using VectorType  = TrilinosWrappers::MPI::Vector;
  using MatrixType  = TrilinosWrappers::SparseMatrix;

  /** A scene of parameters/ and the entries set over it. */
  struct Scene
  {
    std::string              name;
    std::string              file;
    std::vector<std::string> settings;
  };

  Parameters::All
  read_parameters(const Scene &scene)
  {
    ParameterHandler prm;
    Parameters::All::declare_parameters(prm);
    Parameters::read_scene(prm,
                           std::string(MEMBRANES_SOURCE_DIR "/parameters/") +
                             scene.file);
    for (const std::string &assignment : scene.settings)
      Parameters::set_entry(prm, assignment);
    // The expressions by the parser: no compiler at run time, and the
    // assembly is not timed.
    Parameters::set_entry(prm, "Problem/Expression evaluation=parser");
    Parameters::set_entry(prm, "Solver/Method=decoupled");
    Parameters::All parameters;
    parameters.parse_parameters(prm);
    return parameters;
  }

  /** The CPU time and the wall time of one call, in ms. */
  struct Times
  {
    double cpu;
    double wall;
  };

  Times
  milliseconds(const std::function<void()> &solve)
  {
    Timer timer;
    solve();
    timer.stop();
    return {1e3 * timer.cpu_time(), 1e3 * timer.wall_time()};
  }

  /** The medians of the CPU and the wall times of @p times. */
  Times
  median(std::vector<Times> times)
  {
    const auto middle = [&](const auto time) {
      std::vector<double> values;
      for (const Times &t : times)
        values.push_back(t.*time);
      std::nth_element(values.begin(),
                       values.begin() + values.size() / 2,
                       values.end());
      return values[values.size() / 2];
    };
    return {middle(&Times::cpu), middle(&Times::wall)};
  }

  /** The two direct solvers on one matrix: their medians and difference. */
  struct Comparison
  {
    Times  mumps;
    Times  umfpack;
    double relative_difference;
  };

  Comparison
  compare(const MatrixType  &matrix,
          const VectorType  &rhs,
          const unsigned int repetitions)
  {
    VectorType mumps_x(rhs), umfpack_x(rhs);
    const auto mumps = [&]() {
      SolverControl                                  control;
      TrilinosWrappers::SolverDirect::AdditionalData data(
        false, LinearSolver::direct_solver_package);
      TrilinosWrappers::SolverDirect solver(control, data);
      solver.solve(matrix, mumps_x, rhs);
    };
    const LinearSolver linear_solver(Parameters::LinearSolverType::direct,
                                     MPI_COMM_WORLD);
    const auto         umfpack = [&]() {
      linear_solver.solve_direct(matrix, umfpack_x, rhs);
    };
    std::vector<Times> mumps_times, umfpack_times;
    for (unsigned int r = 0; r < repetitions; ++r)
      {
        mumps_times.push_back(milliseconds(mumps));
        umfpack_times.push_back(milliseconds(umfpack));
      }
    const double norm = mumps_x.l2_norm();
    umfpack_x -= mumps_x;
    return {median(mumps_times),
            median(umfpack_times),
            umfpack_x.l2_norm() / norm};
  }

  /**
   * One run of a scene: its meshes, each set up and solved as
   * MembraneProblem::setup_system() and solve() do.
   */
  class Run
  {
  public:
    explicit Run(const Scene &scene)
      : parameters(read_parameters(scene))
      , pcout(std::cout, false)
      , timer(pcout, TimerOutput::never, TimerOutput::wall_times)
      , data(parameters.problem, parameters.exact_solution, pcout)
      , discretization(parameters.geometry.cell_type)
      , triangulation(make_triangulation<dim>(parameters.geometry.cell_type,
                                              MPI_COMM_WORLD))
      , dof_handler(*triangulation)
      , dual_mesh(discretization)
      , problem(discretization, data)
      , action(data)
      , active_set(parameters.solver, data, MPI_COMM_WORLD)
    {
      create_mesh(parameters.geometry, *triangulation);
      discretization.select_mapping(*triangulation);
    }

    /** The mesh set up and the active set method solved on it. */
    void
    solve()
    {
      dof_handler.distribute_dofs(*discretization.fe);
      const IndexSet owned = dof_handler.locally_owned_dofs();
      IndexSet       relevant;
      DoFTools::extract_locally_relevant_dofs(dof_handler, relevant);
      constraints.clear();
      constraints.reinit(relevant);
      DoFTools::make_hanging_node_constraints(dof_handler, constraints);
      constraints.close();
      dual_mesh.reinit(dof_handler);
      problem.reinit(
        dof_handler, relevant, constraints, dual_mesh, MPI_COMM_WORLD);
      action.reinit(problem);
      active_set.reinit(problem);
      ActiveSetSolver<dim> solver(
        parameters.solver, data, pcout, timer, MPI_COMM_WORLD);
      solver.setup(problem, dof_handler);
      solution.reinit(std::vector<IndexSet>(2, owned), MPI_COMM_WORLD);
      solver.solve(problem, action, solution, active_set);
      ghosted_solution.reinit(std::vector<IndexSet>(2, owned),
                              std::vector<IndexSet>(2, relevant),
                              MPI_COMM_WORLD);
      ghosted_solution = solution;
    }

    /** S and W of the converged active set, each by both solvers. */
    std::pair<Comparison, Comparison>
    compare_solvers(const unsigned int repetitions) const
    {
      const double mu1 = data.mu[0], mu2 = data.mu[1];
      VectorType   s_rhs(problem.lifted_loads(0));
      s_rhs += problem.lifted_loads(1);
      VectorType w_rhs(s_rhs);
      w_rhs.equ(mu2 / (mu1 + mu2), problem.lifted_loads(0));
      w_rhs.add(-mu1 / (mu1 + mu2), problem.lifted_loads(1));

      const IndexSet active = active_set.locally_owned(problem);
      MatrixType     w_matrix;
      w_matrix.copy_from(problem.laplace_matrix());
      for (auto entry = w_matrix.begin(); entry != w_matrix.end(); ++entry)
        if (entry->row() != entry->column() &&
            (active.is_element(entry->row()) ||
             active.is_element(entry->column())))
          entry->value() = 0;
      w_matrix *= data.mu_bar;
      for (const auto dof : active)
        w_rhs[dof] = 0;
      w_rhs.compress(VectorOperation::insert);

      return {compare(problem.laplace_matrix(), s_rhs, repetitions),
              compare(w_matrix, w_rhs, repetitions)};
    }

    /** The next mesh: adaptive by the residual indicators, or uniform. */
    void
    refine()
    {
      const Parameters::Refinement &refinement = parameters.refinement;
      if (refinement.strategy == Parameters::RefinementStrategy::global)
        {
          triangulation->refine_global(1);
          return;
        }
      const VectorType lambda_h = action.lambda_h(problem, constraints);
      Vector<double>   indicators;
      ErrorEstimator<dim>(discretization, data)
        .residual_estimate(dof_handler,
                           ghosted_solution,
                           problem,
                           dual_mesh,
                           lambda_h,
                           indicators,
                           MPI_COMM_WORLD);
      mark_cells(*triangulation,
                 indicators,
                 refinement.marking,
                 refinement.refined_share(),
                 refinement.coarsen_fraction,
                 MPI_COMM_WORLD);
      triangulation->execute_coarsening_and_refinement();
    }

    types::global_dof_index
    n_unknowns() const
    {
      return dof_handler.n_dofs();
    }

    types::global_dof_index
    n_active() const
    {
      return active_set.n_active_vertices();
    }

  private:
    const Parameters::All                     parameters;
    ConditionalOStream                        pcout;
    TimerOutput                               timer;
    const ProblemData<dim>                    data;
    Discretization<dim>                       discretization;
    const std::unique_ptr<Triangulation<dim>> triangulation;
    DoFHandler<dim>                           dof_handler;
    AffineConstraints<double>                 constraints;
    DualMesh<dim>                             dual_mesh;
    DiscreteProblem<dim>                      problem;
    DiscreteAction<dim>                       action;
    ActiveSet<dim>                            active_set;
    TrilinosWrappers::MPI::BlockVector        solution, ghosted_solution;
  };
} // namespace



int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  AssertThrow(Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD) == 1,
              ExcMessage("direct_solvers measures the solvers of one "
                         "process."));
  const unsigned int repetitions = argc > 1 ? std::stoi(argv[1]) : 11;
  const types::global_dof_index largest =
    argc > 2 ? std::stoul(argv[2]) : 10000;

  const std::vector<Scene> scenes = {
    {"disk Q1 adaptive", "default.prm", {}},
    {"disk P1 adaptive", "default.prm", {"Geometry/Cell type=triangle"}},
    {"square Q1 uniform", "case-m-quadrilateral.prm", {}},
    {"square P1 uniform", "case-m-triangle.prm", {}}};

  std::cout << "| scene | unknowns | active | S MUMPS | S UMFPACK "
               "| W MUMPS | W UMFPACK | UMFPACK/MUMPS | wall time "
               "| difference |\n"
            << "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|" << std::endl;
  for (const Scene &scene : scenes)
    {
      Run run(scene);
      for (;;)
        {
          run.solve();
          const auto [s, w] = run.compare_solvers(repetitions);
          std::cout << "| " << scene.name << " | " << run.n_unknowns() << " | "
                    << run.n_active() << std::fixed << std::setprecision(2)
                    << " | " << s.mumps.cpu << " | " << s.umfpack.cpu << " | "
                    << w.mumps.cpu << " | " << w.umfpack.cpu << " | "
                    << (s.umfpack.cpu + w.umfpack.cpu) /
                         (s.mumps.cpu + w.mumps.cpu)
                    << " | "
                    << (s.umfpack.wall + w.umfpack.wall) /
                         (s.mumps.wall + w.mumps.wall)
                    << std::defaultfloat << std::setprecision(1) << " | "
                    << std::max(s.relative_difference, w.relative_difference)
                    << " |" << std::endl;
          if (run.n_unknowns() >= largest)
            break;
          run.refine();
        }
    }
}
