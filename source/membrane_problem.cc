#include <algorithm>
#include <deal.II/base/mpi.h>
#include <deal.II/dofs/dof_tools.h>
#include <limits>
#include <map>
#include <membranes/estimators/error_estimator.h>
#include <membranes/estimators/error_norms.h>
#include <membranes/estimators/negative_norm.h>
#include <membranes/flux/flux_equilibration.h>
#include <membranes/flux/flux_reconstruction.h>
#include <membranes/membrane_problem.h>
#include <membranes/mesh/cell_marking.h>

namespace membranes
{
  template <int dim>
  MembraneProblem<dim>::MembraneProblem(const Parameters::All &parameters,
                                        const Provenance      &provenance)
    : parameters(parameters)
    , mpi_communicator(MPI_COMM_WORLD)
    , pcout(std::cout, Utilities::MPI::this_mpi_process(mpi_communicator) == 0)
    , computing_timer(pcout, TimerOutput::never, TimerOutput::wall_times)
    , data(parameters.problem, parameters.exact_solution, pcout)
    , discretization(parameters.geometry.cell_type)
    , triangulation(make_triangulation<dim>(parameters.geometry.cell_type,
                                            mpi_communicator))
    , dof_handler(*triangulation)
    , dual_mesh(discretization)
    , discrete_problem(discretization, data)
    , active_set(parameters.solver, data, mpi_communicator)
    , action(data)
    , active_set_solver(parameters.solver,
                        data,
                        pcout,
                        computing_timer,
                        mpi_communicator)
    , flux_reconstruction(
        computes_fluxes() ?
          std::make_unique<FluxReconstruction<dim>>(discretization, data) :
          nullptr)
    , flux_equilibration(
        computes_fluxes() ?
          std::make_unique<FluxEquilibration<dim>>(*flux_reconstruction) :
          nullptr)
    , report(parameters.output, parameters.exact_solution, pcout)
    , field_output(parameters.output, discretization, mpi_communicator)
    , output_directory(parameters.output.directory,
                       provenance,
                       mpi_communicator)
    , checkpoint(
        parameters.output.checkpoint_every > 0 || parameters.output.resume ?
          std::make_unique<Checkpoint<dim>>(parameters.output.directory,
                                            mpi_communicator) :
          nullptr)
  {}



  template <int dim>
  MembraneProblem<dim>::~MembraneProblem() = default;



  /**
   * The coarse mesh, and the check of the boundary data against it. Every
   * process builds the coarse mesh from the same scene (and the same mesh
   * file), so an error there is met by all of them alike.
   */
  template <int dim>
  void
  MembraneProblem<dim>::make_grid()
  {
    output_directory.check();
    try
      {
        create_mesh(parameters.geometry, *triangulation);
      }
    catch (const Parameters::InputError &error)
      {
        throw Parameters::CollectiveError(error.what());
      }
    discretization.select_mapping(*triangulation);
    data.check_boundary_data(*triangulation);
    data.check_exact_solution(*triangulation,
                              *discretization.mapping,
                              discretization.cell_quadrature);
  }



  /**
   * The DoFs of the mesh (one per vertex), the hanging node constraints,
   * the interior vertices of the dual mesh (DualMesh), and the discrete
   * problem of the mesh (DiscreteProblem: the index sets of the step-40
   * layout, the Laplacian, the loads, V_h and d_a), which the discrete
   * action and the solver's systems read. The
   * vectors of the mesh: the two blocks (u1h, u2h) of the solution, and
   * λ_h.
   */
  template <int dim>
  void
  MembraneProblem<dim>::setup_system()
  {
    dof_handler.distribute_dofs(*discretization.fe);

    IndexSet locally_relevant_dofs;
    DoFTools::extract_locally_relevant_dofs(dof_handler, locally_relevant_dofs);
    hanging_node_constraints.clear();
    hanging_node_constraints.reinit(locally_relevant_dofs);
    DoFTools::make_hanging_node_constraints(dof_handler,
                                            hanging_node_constraints);
    hanging_node_constraints.close();

    dual_mesh.reinit(dof_handler);
    discrete_problem.reinit(dof_handler,
                            locally_relevant_dofs,
                            hanging_node_constraints,
                            dual_mesh,
                            mpi_communicator);
    action.reinit(discrete_problem);
    active_set_solver.setup(discrete_problem, dof_handler);

    const IndexSet &owned = discrete_problem.locally_owned_dofs();
    solution.reinit(std::vector<IndexSet>(2, owned), mpi_communicator);
    ghosted_solution.reinit(std::vector<IndexSet>(2, owned),
                            std::vector<IndexSet>(2, locally_relevant_dofs),
                            mpi_communicator);
    lambda_h.reinit(owned, locally_relevant_dofs, mpi_communicator);
  }



  /**
   * Nested iteration: the solution and λ_h of the previous mesh,
   * interpolated, are the initial guess, and give the initial active set.
   * The first mesh starts from zero with no active vertex.
   */
  template <int dim>
  void
  MembraneProblem<dim>::transfer_solution()
  {
    if (!distributed_transfer && !serial_transfer)
      {
        solution = 0;
        active_set.reinit(discrete_problem);
        return;
      }

    // u1h, u2h into the blocks of the solution, λ_h through a vector of the
    // locally owned DoFs.
    const IndexSet           &owned = discrete_problem.locally_owned_dofs();
    VectorType                owned_lambda_h(owned, mpi_communicator);
    std::vector<VectorType *> targets{&solution.block(0),
                                      &solution.block(1),
                                      &owned_lambda_h};
    if (distributed_transfer)
      distributed_transfer->interpolate(targets);
    else
      {
        std::vector<Vector<double>> replicated(
          targets.size(), Vector<double>(dof_handler.n_dofs()));
        serial_transfer->interpolate(replicated_previous_vectors, replicated);
        for (unsigned int v = 0; v < targets.size(); ++v)
          {
            for (const auto i : owned)
              (*targets[v])[i] = replicated[v][i];
            targets[v]->compress(VectorOperation::insert);
          }
      }
    distributed_transfer.reset();
    serial_transfer.reset();
    previous_mesh_vectors.clear();
    replicated_previous_vectors.clear();

    for (VectorType *vector : targets)
      hanging_node_constraints.distribute(*vector);
    ghosted_solution = solution;
    lambda_h         = owned_lambda_h;
    active_set.reinit(discrete_problem, solution, lambda_h);
  }



  /**
   * The active set method on the current mesh. If it stops without
   * convergence, the last iterate is written by write_unconverged_iterate()
   * and the run ends with the solver's message, the same on every process:
   * no row is added to the report.
   *
   * Balanced stopping compares with the discretization error expected on
   * this mesh, η̃ = η_prev (N_prev / N)^{1/2}: the residual estimator of the
   * previous mesh with N_prev DoFs, decreasing at the optimal rate of P1/Q1
   * elements in the energy norm, N^{−1/2} in two dimensions. Where the
   * error decreases more slowly (reduced regularity, global refinement),
   * η̃ is smaller than the error and the stopping errs on the safe side.
   * It costs nothing in the iteration; evaluating the estimator on the
   * iterates instead would cost one estimator (postprocessing of λ_h
   * included) per iteration.
   */
  template <int dim>
  SolveRecord
  MembraneProblem<dim>::solve(KKTDefects &defects)
  {
    ActiveSetStatistics statistics;
    const double        expected_error =
      previous_record.estimator ?
               *previous_record.estimator *
          std::sqrt(static_cast<double>(previous_record.mesh.dofs) /
                    record.mesh.dofs) :
               0.;
    try
      {
        statistics = active_set_solver.solve(
          discrete_problem, action, solution, active_set, expected_error);
      }
    catch (const ActiveSetNotConverged &error)
      {
        throw ActiveSetNotConverged(
          "cycle " + std::to_string(record.mesh.cycle) + ": " + error.what() +
          "; " + write_unconverged_iterate());
      }
    ghosted_solution = solution;
    defects          = statistics.kkt_defects;

    return {statistics.iterations,
            active_set.n_active_vertices(),
            statistics.linear_iterations,
            statistics.kkt_residual,
            statistics.linearization_estimate,
            statistics.algebraic_estimate};
  }



  /**
   * λ_h, and the discrete identities of §4.1 measured on the solution:
   * - Prop. 12: the two formulas of (4.5) agree, max_a |λ_1a − λ_2a| d_a,
   * - (4.8): λ_a (u1h − u2h)(a) = 0, max_a |λ_a d_a (u1h − u2h)(a)|,
   * both relative to the data: forces by the force scale F of (4.5), and
   * displacements by max |u_h|; and min_a λ_a, min_a (u1h − u2h)(a).
   */
  template <int dim>
  IdentityRecord
  MembraneProblem<dim>::postprocess(const KKTDefects &defects)
  {
    lambda_h = action.lambda_h(discrete_problem, hanging_node_constraints);

    const double force_scale =
      std::max(action.force_scale(), std::numeric_limits<double>::min());
    const double u_scale = displacement_scale(ghosted_solution);
    return {defects.min_w,
            defects.min_lambda,
            defects.sum_equilibrium / force_scale,
            defects.complementarity / (force_scale * u_scale)};
  }



  /**
   * The errors against the exact solution, when it is known, in the norms
   * that `Exact solution/Norms` names (after postprocess(), which gives
   * λ_h). Timed on their own, as `errors`: a run without an exact solution
   * never pays for them, so they are not part of the wall time of the
   * method.
   */
  template <int dim>
  ErrorRecord
  MembraneProblem<dim>::compute_errors()
  {
    const Parameters::ExactSolution &exact = parameters.exact_solution;
    if (!exact.computes_any())
      return {};
    TimerOutput::Scope scope(computing_timer, "errors");
    ErrorRecord        errors =
      ErrorNorms<dim>(discretization, data, exact.reference_quadrature)
        .compute(dof_handler,
                 ghosted_solution,
                 dual_mesh,
                 lambda_h,
                 exact,
                 mpi_communicator);
    // λ in H^{-1}(ω) through its Riesz representative of degree 2
    // (benchmarks/estimators.md, "The H^-1 norm of the action").
    if (exact.computes("err_lambda_Hm1"))
      errors.lambda_Hm1 = NegativeNorm<dim>(discretization)
                            .lambda_error(dof_handler,
                                          discrete_problem.laplace_matrix(),
                                          dual_mesh,
                                          lambda_h,
                                          data);
    return errors;
  }



  /**
   * Whether the fluxes are reconstructed: for the flux estimator when it
   * drives refinement, and when the scene asks for them in the output.
   */
  template <int dim>
  bool
  MembraneProblem<dim>::computes_fluxes() const
  {
    return parameters.refinement.estimator == Parameters::Estimator::flux ||
           parameters.output.flux_reconstruction;
  }



  /**
   * The residual estimator η and its indicators η_K², when it drives
   * adaptive refinement or a target estimator, or the run computes the
   * energy error (with its effectivity index η / |||e|||), or balanced stopping
   * needs it on every mesh. Its indicators are kept for marking unless the
   * flux estimator drives refinement (reconstruct_fluxes()).
   */
  template <int dim>
  std::optional<double>
  MembraneProblem<dim>::estimate_error()
  {
    const bool adaptive = parameters.refinement.strategy ==
                          Parameters::RefinementStrategy::adaptive;
    const bool balanced =
      parameters.solver.stopping == Parameters::Stopping::balanced;
    const bool flux_drives =
      parameters.refinement.estimator == Parameters::Estimator::flux;
    const bool drives = adaptive || parameters.refinement.target_estimator > 0;
    indicators.reinit(0);
    if (!(drives && !flux_drives) &&
        !parameters.exact_solution.computes("err_energy") && !balanced)
      return {};
    TimerOutput::Scope scope(computing_timer, "estimate");
    Vector<double>     residual_indicators;
    const double       eta = ErrorEstimator<dim>(discretization, data)
                         .residual_estimate(dof_handler,
                                            ghosted_solution,
                                            discrete_problem,
                                            dual_mesh,
                                            lambda_h,
                                            residual_indicators,
                                            mpi_communicator);
    if (!flux_drives)
      indicators.swap(residual_indicators);
    return eta;
  }



  /**
   * The fluxes t_ih of §4.2 and σ_ih, if computes_fluxes(); with
   * `Output/Flux reconstruction`, the defects of (4.17), (4.18) and of the
   * balance of Lemma 17 for the report. Then the flux estimator and its
   * parts, with its effectivity index when the exact solution is known; its
   * indicators are kept for marking when it drives refinement.
   */
  template <int dim>
  std::optional<FluxRecord>
  MembraneProblem<dim>::reconstruct_fluxes()
  {
    if (!computes_fluxes())
      return {};
    TimerOutput::Scope scope(computing_timer, "flux");
    flux_equilibration->equilibrate(
      dof_handler,
      flux_reconstruction->reconstruct(dof_handler, ghosted_solution),
      lambda_h,
      hanging_node_constraints,
      discrete_problem.locally_owned_dofs(),
      mpi_communicator);
    Vector<double> flux_indicators;
    FluxRecord     flux = ErrorEstimator<dim>(discretization, data)
                        .flux_estimate(dof_handler,
                                       ghosted_solution,
                                       dual_mesh,
                                       lambda_h,
                                       *flux_equilibration,
                                       flux_indicators,
                                       mpi_communicator);
    if (parameters.output.flux_reconstruction)
      {
        const auto identities = flux_reconstruction->identities(
          dof_handler, hanging_node_constraints, discrete_problem, action);
        flux.measure_defect      = identities.measure_defect;
        flux.conservation_defect = identities.conservation_defect;
        flux.balance_defect      = identities.balance_defect;
      }
    if (parameters.refinement.estimator == Parameters::Estimator::flux)
      indicators.swap(flux_indicators);
    return flux;
  }



  /**
   * The last iterate of an active set method that did not converge, to see
   * why, never as a result: VTU and nodal values of u1, u2, λ_h and the
   * active set in `<Directory>/unconverged/`, whatever the scene asks for.
   * Returns where they are.
   */
  template <int dim>
  std::string
  MembraneProblem<dim>::write_unconverged_iterate()
  {
    ghosted_solution = solution;
    lambda_h = action.lambda_h(discrete_problem, hanging_node_constraints);

    Parameters::Output output = parameters.output;
    output.directory = output_directory.create_subdirectory("unconverged");
    output.write_vtu = true;
    output.write_nodal_values = true;
    const std::vector<std::string> files =
      FieldOutput<dim>(output, discretization, mpi_communicator)
        .write(record.mesh.cycle,
               dof_handler,
               ghosted_solution,
               lambda_h,
               active_set.locally_owned(discrete_problem),
               nullptr);
    return "the last iterate is in " + output.directory + " (" + files[0] +
           ", " + files[1] + "), not in the report";
  }



  /**
   * u1, u2, u1 − u2, λ_h and the active set as VTU, and the nodal values as
   * CSV, if the scene asks for them.
   */
  template <int dim>
  void
  MembraneProblem<dim>::output_results(const unsigned int cycle)
  {
    field_output.write(cycle,
                       dof_handler,
                       ghosted_solution,
                       lambda_h,
                       active_set.locally_owned(discrete_problem),
                       indicators.size() ? &indicators : nullptr);
    if (parameters.output.flux_reconstruction && parameters.output.write_vtu)
      field_output.write_dual_mesh(cycle,
                                   flux_reconstruction->patches(dof_handler,
                                                                dual_mesh,
                                                                lambda_h),
                                   FluxReconstruction<dim>::data_names());
  }



  /**
   * Global refinement, or adaptive refinement by the estimator's η_K²:
   * bulk (Dörfler) marking refines the fewest cells whose η_K² sum up to
   * the share θ of η², fixed number a share of the cells with the largest
   * η_K (coarsening likewise at the other end). With `Minimum
   * growth` g > 1, a marking that refines fewer than the share
   * (g − 1)/(2^dim − 1) of the cells is extended to that share, again by
   * the largest η_K: both sets are the cells above a threshold, so the
   * larger one contains the smaller. The solution and λ_h are handed to a
   * SolutionTransfer first, to be interpolated onto the new mesh by
   * transfer_solution().
   *
   * mark_cells() finds the thresholds from all indicators, sorted, so that
   * any number of processes marks the same cells, also where indicators
   * tie. A mesh that every process holds whole (triangles, on a
   * parallel::shared::Triangulation) is flagged on every process, with the
   * indicators of all cells: each process contributes those of its own
   * cells (the others are zero) and the sum is the same vector everywhere,
   * so every process flags the same cells.
   *
   * If every indicator is zero (the estimator finds the discrete solution
   * exact), no cell can be marked: the run says so and ends (false)
   * instead of repeating the mesh.
   */
  template <int dim>
  bool
  MembraneProblem<dim>::refine_grid()
  {
    const auto &refinement = parameters.refinement;
    auto *const distributed_triangulation =
      dynamic_cast<parallel::distributed::Triangulation<dim> *>(
        triangulation.get());
    if (!distributed_triangulation &&
        refinement.strategy != Parameters::RefinementStrategy::global)
      {
        for (const auto &cell : triangulation->active_cell_iterators())
          if (!cell->is_locally_owned())
            indicators[cell->active_cell_index()] = 0;
        Utilities::MPI::sum(indicators, mpi_communicator, indicators);
      }
    if (refinement.strategy == Parameters::RefinementStrategy::global)
      triangulation->set_all_refine_flags();
    else if (Utilities::MPI::max(indicators.linfty_norm(), mpi_communicator) ==
             0)
      {
        pcout << "Stopping: every refinement indicator is zero (the discrete "
                 "solution is exact for the estimator), no cell to refine"
              << std::endl;
        return false;
      }
    else
      {
        mark_cells(*triangulation,
                   indicators,
                   refinement.marking,
                   refinement.refined_share(),
                   refinement.coarsen_fraction,
                   mpi_communicator);
        const double least_share =
          (refinement.minimum_growth - 1) /
          (GeometryInfo<dim>::max_children_per_cell - 1);
        unsigned int n_marked = 0;
        for (const auto &cell : triangulation->active_cell_iterators())
          if (cell->is_locally_owned() && cell->refine_flag_set())
            ++n_marked;
        if (Utilities::MPI::sum(n_marked, mpi_communicator) <
            least_share * triangulation->n_global_active_cells())
          mark_cells(*triangulation,
                     indicators,
                     Parameters::Marking::fixed_number,
                     least_share,
                     0,
                     mpi_communicator);
      }
    triangulation->prepare_coarsening_and_refinement();
    if (checkpoint)
      checkpoint->record_refinement(*triangulation);

    if (distributed_triangulation)
      {
        previous_mesh_vectors = {ghosted_solution.block(0),
                                 ghosted_solution.block(1),
                                 lambda_h};
        distributed_transfer  = std::make_unique<
          parallel::distributed::SolutionTransfer<dim, VectorType>>(
          dof_handler);
        distributed_transfer->prepare_for_coarsening_and_refinement(
          {&previous_mesh_vectors[0],
           &previous_mesh_vectors[1],
           &previous_mesh_vectors[2]});
      }
    else
      {
        // The whole mesh on every process: the serial SolutionTransfer
        // interpolates on every cell, so it reads vectors with every entry
        // (the copy from a distributed vector gathers them).
        replicated_previous_vectors = {
          Vector<double>(ghosted_solution.block(0)),
          Vector<double>(ghosted_solution.block(1)),
          Vector<double>(lambda_h)};
        serial_transfer =
          std::make_unique<SolutionTransfer<dim, Vector<double>>>(dof_handler);
        serial_transfer->prepare_for_coarsening_and_refinement(
          replicated_previous_vectors);
      }
    triangulation->execute_coarsening_and_refinement();
    complete_ghost_layer(*triangulation);
    return true;
  }



  /**
   * Whether the estimator of `Refinement/Estimator` of this cycle is at
   * most `Refinement/Target estimator` (when one is set); says so.
   */
  template <int dim>
  bool
  MembraneProblem<dim>::target_reached() const
  {
    const double                target = parameters.refinement.target_estimator;
    const std::optional<double> eta =
      (parameters.refinement.estimator == Parameters::Estimator::flux ?
         (record.flux ? std::optional<double>(record.flux->estimator) :
                        std::nullopt) :
         record.estimator);
    if (!(target > 0 && eta && *eta <= target))
      return false;
    pcout << "Stopping: the estimator " << *eta
          << " <= Target estimator = " << target << std::endl;
    return true;
  }



  /**
   * Whether the mesh just set up has more DoFs than `Refinement/Max dofs`
   * allows: an error on the first mesh, the end of the run on a later one.
   */
  template <int dim>
  bool
  MembraneProblem<dim>::exceeds_max_dofs(const unsigned int cycle) const
  {
    const types::global_dof_index n_dofs   = solution.size();
    const auto                    max_dofs = parameters.refinement.max_dofs;
    if (max_dofs == 0 || n_dofs <= max_dofs)
      return false;
    if (cycle == 0)
      throw Parameters::invalid_entry("Refinement/Max dofs",
                                      std::to_string(max_dofs),
                                      "the first mesh already has " +
                                        std::to_string(n_dofs) + " DoFs");
    pcout << "Stopping: the next mesh would have " << n_dofs
          << " DoFs > Max dofs = " << max_dofs << std::endl;
    return true;
  }



  /**
   * The mesh of the cycle and the number of processes into its record, and
   * the first line of its progress output. The DoFs are those of the pair
   * (u1h, u2h): both blocks of the solution.
   */
  template <int dim>
  void
  MembraneProblem<dim>::record_mesh(const unsigned int cycle)
  {
    record.mesh = {cycle,
                   triangulation->n_global_active_cells(),
                   triangulation->n_global_levels(),
                   static_cast<types::global_dof_index>(solution.size())};
    pcout << "Cycle " << cycle << ": " << record.mesh.cells << " cells, "
          << record.mesh.dofs << " DoFs";
    record.processes = Utilities::MPI::n_mpi_processes(mpi_communicator);
    if (record.processes > 1)
      pcout << " on " << record.processes << " processes";
    pcout << std::endl;
  }



  /**
   * The costs of the cycle into its record, and the last line of its
   * progress output: the wall time of each phase, from the sections of
   * computing_timer, on several processes that of the slowest process (each
   * phase ends in communication; the flux reconstruction has a time only
   * where it was computed, the error norms only with an exact solution;
   * TimerOutput::print_wall_time_statistics() prints the minimum, mean and
   * maximum over the processes to a stream, the report needs the maximum as
   * a number in its row), the cumulative time of the run, and the peak
   * memory summed over the processes.
   */
  template <int dim>
  void
  MembraneProblem<dim>::record_costs()
  {
    const std::map<std::string, double> times =
      computing_timer.get_summary_data(TimerOutput::total_wall_time);
    const auto time_of = [&](const std::string &section) {
      const auto time = times.find(section);
      return Utilities::MPI::max(time == times.end() ? 0. : time->second,
                                 mpi_communicator);
    };
    record.times.setup       = time_of("setup");
    record.times.assembly    = time_of("assembly");
    record.times.solve       = time_of("solve");
    record.times.postprocess = time_of("postprocess");
    record.times.estimate    = time_of("estimate");
    if (computes_fluxes())
      record.times.flux = time_of("flux");
    if (parameters.exact_solution.computes_any())
      record.times.errors = time_of("errors");
    record.cumulative_wall_time =
      previous_record.cumulative_wall_time + record.times.method();
    Utilities::System::MemoryStats memory;
    Utilities::System::get_memory_stats(memory);
    record.memory_mb =
      Utilities::MPI::sum(memory.VmHWM / 1024., mpi_communicator);
    pcout << "   " << record.solve.active_set_iterations
          << " active set iterations, " << record.solve.active_vertices
          << " active vertices, " << record.times.method() << " s" << std::endl;
  }



  /**
   * The state after the last finished cycle of the study of the output
   * directory, from its checkpoint (Checkpoint): the mesh, its DoFs, u1h,
   * u2h, λ_h and the indicators, what the report, the field output and
   * balanced stopping carry on; the next cycle then starts as in the
   * uninterrupted study, by refining this mesh. Returns that cycle.
   */
  template <int dim>
  unsigned int
  MembraneProblem<dim>::resume()
  {
    const CheckpointState state =
      checkpoint->load_mesh(*triangulation, [this](Triangulation<dim> &mesh) {
        create_mesh(parameters.geometry, mesh);
      });
    setup_system();
    VectorType owned_lambda_h(discrete_problem.locally_owned_dofs(),
                              mpi_communicator);
    checkpoint->load_vectors(
      dof_handler,
      {{&solution.block(0), &solution.block(1), &owned_lambda_h}},
      indicators);
    ghosted_solution = solution;
    lambda_h         = owned_lambda_h;
    report.resume(state.cycle);
    field_output.resume(state.solution_files, state.dual_mesh_files);
    previous_record.mesh.cycle           = state.cycle;
    previous_record.mesh.dofs            = state.dofs;
    previous_record.estimator            = state.estimator;
    previous_record.cumulative_wall_time = state.cumulative_wall_time;
    pcout << "Resuming after cycle " << state.cycle << " (" << state.dofs
          << " DoFs) from the checkpoint of " << parameters.output.directory
          << std::endl;
    return state.cycle + 1;
  }



  /**
   * The checkpoint of cycle @p cycle, after every k-th cycle (`Output/
   * Checkpoint every`) and after the last one of the run, so that a study
   * can also be extended by more cycles.
   */
  template <int dim>
  void
  MembraneProblem<dim>::write_checkpoint(const unsigned int cycle)
  {
    const unsigned int every = parameters.output.checkpoint_every;
    if (every == 0 ||
        ((cycle + 1) % every != 0 && cycle + 1 != parameters.refinement.cycles))
      return;
    CheckpointState state;
    state.cycle                = cycle;
    state.dofs                 = record.mesh.dofs;
    state.estimator            = record.estimator;
    state.cumulative_wall_time = record.cumulative_wall_time;
    std::tie(state.solution_files, state.dual_mesh_files) =
      field_output.written_files();
    Timer timer;
    checkpoint->write(
      state,
      dof_handler,
      {{&ghosted_solution.block(0), &ghosted_solution.block(1), &lambda_h}},
      indicators);
    pcout << "   checkpoint written in " << timer.wall_time() << " s"
          << std::endl;
  }



  template <int dim>
  void
  MembraneProblem<dim>::run()
  {
    make_grid();
    if (parameters.exact_solution.known &&
        !parameters.exact_solution.computes("err_energy"))
      pcout << "No effectivity index: it needs err_energy in Exact "
               "solution/Norms"
            << std::endl;
    output_directory.claim(parameters.output.resume);
    const unsigned int first_cycle = parameters.output.resume ? resume() : 0;
    for (unsigned int cycle = first_cycle; cycle < parameters.refinement.cycles;
         ++cycle)
      {
        record = CycleRecord();
        computing_timer.reset();
        {
          // Making the mesh of this cycle from the last one is part of its
          // cost.
          TimerOutput::Scope scope(computing_timer, "setup");
          if (cycle > 0 && !refine_grid())
            break;
          setup_system();
          if (exceeds_max_dofs(cycle))
            break;
          transfer_solution();
        }
        record_mesh(cycle);

        KKTDefects defects;
        record.solve = solve(defects);
        {
          TimerOutput::Scope scope(computing_timer, "postprocess");
          record.identities = postprocess(defects);
        }
        record.errors    = compute_errors();
        record.estimator = estimate_error();
        record.flux      = reconstruct_fluxes();
        record_costs();

        report.add(record);
        previous_record = record;
        output_results(cycle);
        write_checkpoint(cycle);
        if (target_reached())
          break;
      }
    report.print_convergence_table(parameters.refinement.strategy ==
                                   Parameters::RefinementStrategy::adaptive);
  }



  template class MembraneProblem<2>;
} // namespace membranes
