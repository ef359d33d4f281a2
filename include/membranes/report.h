#ifndef membranes_report_h
#define membranes_report_h

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/convergence_table.h>
#include <deal.II/base/types.h>
#include <membranes/parameters.h>
#include <optional>
#include <string>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /** Everything a run records about one cycle (one row of report.csv). */
  struct CycleRecord
  {
    unsigned int cycle = 0;
    unsigned int cells = 0;
    /** Levels of the mesh hierarchy: the coarse mesh and its refinements. */
    unsigned int            levels                = 0;
    types::global_dof_index dofs                  = 0;
    unsigned int            active_set_iterations = 0;
    unsigned int            active_vertices       = 0;
    unsigned int            linear_iterations     = 0;
    /** Active vertices that are hanging nodes (0: the active set is on V_h). */
    unsigned int hanging_active_vertices = 0;
    /**
     * Wall time of the cycle's phases of the method (not of output
     * writing, nor of the error norms against the exact solution).
     */
    double wall_time = 0;
    /** The same, summed over this and all previous cycles. */
    double cumulative_wall_time = 0;
    double time_setup = 0, time_assembly = 0, time_solve = 0,
           time_postprocess = 0, time_estimate = 0;
    /** Flux reconstruction and flux estimator; empty when not computed. */
    std::optional<double> time_flux;
    /**
     * The error norms against the exact solution, a cost that a run
     * without one never pays: not part of wall_time. Empty without an exact
     * solution.
     */
    std::optional<double> time_errors;

    /** Errors; empty when the exact solution is not known. */
    std::optional<double> err_u1_H1, err_u2_H1, err_u1_L2, err_u2_L2,
      err_lambda_L2;
    /** Energy error (Σ_i μ_i |u_i − u_ih|²_{H1})^{1/2}; with the errors. */
    std::optional<double> err_energy;
    /** A posteriori estimator η and effectivity index η / err_energy. */
    std::optional<double> estimator, effectivity;
    /** The flux estimator and its effectivity, with the flux reconstruction. */
    std::optional<double> flux_estimator, flux_effectivity;
    /**
     * The parts of the flux estimator (ErrorEstimator::FluxEstimate): the
     * flux part (Σ_i η_F,i²)^{1/2}, the oscillation part (Σ_i η_R,i²)^{1/2}
     * and the contact part (2 B)^{1/2}; with the flux estimator.
     */
    std::optional<double> flux_estimator_flux, flux_estimator_oscillation,
      flux_estimator_contact;
    /**
     * The boundary data part (ErrorEstimator::FluxEstimate::boundary), not
     * part of the flux estimator; with it.
     */
    std::optional<double> flux_estimator_boundary;
    /**
     * Defects of (4.17), (4.18) and of the balance of Lemma 17 (see
     * FluxReconstruction::Identities), with the flux reconstruction.
     */
    std::optional<double> measure_defect, conservation_defect, balance_defect;

    /** Relative KKT residual of the active set solver at the end. */
    double kkt_residual = 0;
    /**
     * η_lin and η_alg of balanced stopping at the end (ActiveSetSolver);
     * empty with exact stopping and on the first mesh.
     */
    std::optional<double> linearization_estimate, algebraic_estimate;
    /** min_a (u1h − u2h)(a) and min_a λ_a over V_h. */
    double min_w = 0, min_lambda = 0;
    /** max_a |λ_1a − λ_2a| d_a / F, F the force scale of (4.5) (Prop. 12). */
    double prop12_defect = 0;
    /** max_a |λ_a d_a (u1h − u2h)(a)| / (F max|u_h|), (4.8). */
    double complementarity_defect = 0;

    /** The number of MPI processes of the run. */
    unsigned int processes = 1;
    /**
     * Peak resident memory (VmHWM) of the run so far, summed over the
     * processes, in MB: divided by the DoFs, the memory per DoF.
     */
    double memory_mb = 0;
  };



  /**
   * The report of a run: report.csv with one row per cycle,
   * rewritten after every cycle (to a temporary name, then renamed, so that
   * a stopped run never leaves a half-written file), and at the end the
   * same numbers as a deal.II ConvergenceTable with observed rates in h
   * (h ~ DoFs^{-1/2}) on the terminal.
   *
   * A row is one list of (column name, value) pairs, made from a
   * CycleRecord in report.cc: adding a column is one line there (and the
   * member of CycleRecord it reports).
   */
  class Report
  {
  public:
    Report(const Parameters::Output &parameters,
           const ConditionalOStream &pcout);

    /** Add the row of one cycle; write report.csv if asked for. */
    void
    add(const CycleRecord &record);

    /**
     * Print the table with the observed convergence rates of the error
     * columns, computed by ConvergenceTable against `dofs`: with
     * @p rates_in_dofs the rate r of e ~ N^(−r) in the number N of DoFs
     * (adaptive meshes have no one h), otherwise the rate in h of
     * e ~ h^r, as 2 r with h ~ N^(−1/2) (uniform refinement halves h).
     * A line above the table says which.
     */
    void
    print_convergence_table(const bool rates_in_dofs);

    /** The column names of report.csv, in order. */
    static const std::vector<std::string> &
    column_names();

  private:
    void
    write_csv() const;

    const Parameters::Output &parameters;
    const ConditionalOStream &pcout;
    std::vector<CycleRecord>  records;
  };
} // namespace membranes

#endif
