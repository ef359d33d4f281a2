#ifndef membranes_membrane_problem_h
#define membranes_membrane_problem_h

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/timer.h>
#include <deal.II/distributed/solution_transfer.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/trilinos_vector.h>
#include <deal.II/numerics/solution_transfer.h>
#include <membranes/active_set/active_set.h>
#include <membranes/active_set/active_set_solver.h>
#include <membranes/dual_mesh/discrete_action.h>
#include <membranes/dual_mesh/dual_mesh.h>
#include <membranes/mesh/discrete_problem.h>
#include <membranes/mesh/discretization.h>
#include <membranes/output/checkpoint.h>
#include <membranes/output/field_output.h>
#include <membranes/output/output_directory.h>
#include <membranes/output/report.h>
#include <membranes/scene/parameters.h>
#include <membranes/scene/problem_data.h>
#include <memory>

namespace membranes
{
  using namespace dealii;

  template <int dim>
  class FluxReconstruction;
  template <int dim>
  class FluxEquilibration;



  /**
   * The driver of one run: the contact problem (1.1) between two membranes,
   * discretized by P1/Q1 finite elements (the reduced problem (3.4)),
   * solved by the primal-dual active set method on a sequence of meshes,
   * with the action λ_h by the local postprocessing (4.5).
   *
   * run() is the whole story: make the coarse mesh and check the data on
   * it, claim the output directory (OutputDirectory), then for each cycle,
   * refine the last mesh (globally, or by the estimator's indicators), set
   * up DoFs and constraints, transfer the previous solution and active set to
   * the new mesh (nested iteration), solve, postprocess (λ_h, the discrete
   * identities), the errors against the exact solution, the residual
   * estimator, the fluxes t_ih and σ_ih with the flux estimator (if the
   * scene asks for them), add a row to the report, write fields.
   *
   * Data layout is that of deal.II's step-40: a distributed triangulation
   * (make_triangulation(): p4est for quadrilaterals, a shared triangulation
   * for triangles),
   * locally owned and locally relevant index sets, Trilinos vectors and
   * matrices, ghosted vectors for reading; every cell loop runs over the
   * locally owned cells (and the ghost cells where a quantity of an owned
   * vertex or edge needs its neighbours), every global quantity is an MPI
   * reduction, and the terminal and report.csv are written by the first
   * process. One process is the case N = 1 of the same code.
   */
  template <int dim>
  class MembraneProblem
  {
  public:
    /**
     * The run of @p parameters; @p provenance is recorded in its output
     * directory (OutputDirectory).
     */
    MembraneProblem(const Parameters::All &parameters,
                    const Provenance      &provenance);

    ~MembraneProblem();

    void
    run();

  private:
    using VectorType      = TrilinosWrappers::MPI::Vector;
    using BlockVectorType = TrilinosWrappers::MPI::BlockVector;

    void
    make_grid();
    void
    setup_system();
    void
    transfer_solution();
    SolveRecord
    solve(KKTDefects &defects);
    IdentityRecord
    postprocess(const KKTDefects &defects);
    ErrorRecord
    compute_errors();
    bool
    computes_fluxes() const;
    std::optional<FluxRecord>
    reconstruct_fluxes();
    std::optional<double>
    estimate_error();
    std::string
    write_unconverged_iterate();
    void
    output_results(const unsigned int cycle);
    bool
    target_reached() const;
    bool
    refine_grid();
    bool
    exceeds_max_dofs(const unsigned int cycle) const;
    void
    record_mesh(const unsigned int cycle);
    void
    record_costs();
    unsigned int
    resume();
    void
    write_checkpoint(const unsigned int cycle);

    const Parameters::All &parameters;
    MPI_Comm               mpi_communicator;
    ConditionalOStream     pcout;
    /**
     * The phases of a cycle: setup, assembly, solve, postprocess, estimate,
     * flux, and the error norms (errors); reset at the start of each cycle.
     */
    TimerOutput computing_timer;

    const ProblemData<dim> data;
    /** Its mapping is chosen on the coarse mesh, in make_grid(). */
    Discretization<dim> discretization;

    const std::unique_ptr<Triangulation<dim>> triangulation;
    /** The DoFs of the scalar P1/Q1 element: one per vertex. */
    DoFHandler<dim>           dof_handler;
    AffineConstraints<double> hanging_node_constraints;
    /** The interior vertices, whose dual cells make up ω_h. */
    DualMesh<dim> dual_mesh;
    /**
     * Laplacian, loads, d_a and V_h of the current mesh, and its index sets
     * (locally owned and relevant DoFs).
     */
    DiscreteProblem<dim> discrete_problem;

    /**
     * (u1h, u2h) as the blocks 0 and 1: locally owned entries, and a ghosted
     * copy for reading.
     */
    BlockVectorType solution;
    BlockVectorType ghosted_solution;
    /** λ_a at every vertex a of V_h (ghosted; DiscreteAction::lambda_h()). */
    VectorType     lambda_h;
    ActiveSet<dim> active_set;
    /** η_K² of the estimator that drives refinement, by active cell index. */
    Vector<double> indicators;

    DiscreteAction<dim>  action;
    ActiveSetSolver<dim> active_set_solver;
    /** t_ih and σ_ih, only when the scene asks for fluxes. */
    std::unique_ptr<FluxReconstruction<dim>> flux_reconstruction;
    std::unique_ptr<FluxEquilibration<dim>>  flux_equilibration;
    Report                                   report;
    FieldOutput<dim>                         field_output;
    /** Held from the start of the first cycle to the end of the run. */
    OutputDirectory output_directory;
    /**
     * The checkpoint of the study, when the scene writes or resumes one
     * (`Output/Checkpoint every`, `Output/Resume`).
     */
    std::unique_ptr<Checkpoint<dim>> checkpoint;

    /**
     * Carries (u1h, u2h, λ_h) from one mesh to the next: the distributed
     * SolutionTransfer on p4est meshes, with the ghosted vectors; the serial
     * one on triangles, whose mesh every process holds whole, with copies
     * of the vectors that hold every entry.
     */
    std::unique_ptr<parallel::distributed::SolutionTransfer<dim, VectorType>>
                            distributed_transfer;
    std::vector<VectorType> previous_mesh_vectors;
    std::unique_ptr<SolutionTransfer<dim, Vector<double>>> serial_transfer;
    std::vector<Vector<double>> replicated_previous_vectors;

    /** The row of the current cycle. */
    CycleRecord record;
    /** The previous row, for the error expected on the next mesh. */
    CycleRecord previous_record;
  };
} // namespace membranes

#endif
