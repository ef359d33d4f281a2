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

#include "setup_floor.h"

#include <chrono>
#include <cmath>
#include <deal.II/base/utilities.h>
#include <iomanip>
#include <iostream>
#include <malloc.h>
#include <stdexcept>

namespace setup_floor
{
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
