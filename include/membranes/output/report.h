#ifndef membranes_report_h
#define membranes_report_h

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/convergence_table.h>
#include <deal.II/base/types.h>
#include <membranes/scene/parameters.h>
#include <optional>
#include <string>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /** The mesh of a cycle. */
  struct MeshRecord
  {
    unsigned int cycle = 0;
    unsigned int cells = 0;
    /** Levels of the mesh hierarchy: the coarse mesh and its refinements. */
    unsigned int            levels = 0;
    types::global_dof_index dofs   = 0;
  };

  /** What the active set method reports at its end on one mesh. */
  struct SolveRecord
  {
    unsigned int active_set_iterations = 0;
    unsigned int active_vertices       = 0;
    /** CG iterations, summed over the active set iterations (0: direct). */
    unsigned int linear_iterations = 0;
    /** Relative KKT residual at the end. */
    double kkt_residual = 0;
    /**
     * η_lin and η_alg of balanced stopping at the end (ActiveSetSolver);
     * empty with exact stopping and on the first mesh.
     */
    std::optional<double> linearization_estimate, algebraic_estimate;
  };

  /** The discrete identities of §4.1 measured on the solution. */
  struct IdentityRecord
  {
    /** min_a (u1h − u2h)(a) and min_a λ_a over V_h. */
    double min_w = 0, min_lambda = 0;
    /** max_a |λ_1a − λ_2a| d_a / F, F the force scale of (4.5) (Prop. 12). */
    double prop12_defect = 0;
    /** max_a |λ_a d_a (u1h − u2h)(a)| / (F max|u_h|), (4.8). */
    double complementarity_defect = 0;
  };

  /**
   * The errors against a known exact solution, in the norms of the paper,
   * as ErrorNorms integrates them (its rules and their accuracy there):
   * each one where `Exact solution/Norms` names its column, empty
   * otherwise.
   */
  struct ErrorRecord
  {
    /** The full H1(ω) norms ‖u_i − u_ih‖_{H1(ω)} of (3.5). */
    std::optional<double> u1_H1, u2_H1;
    std::optional<double> u1_L2, u2_L2;
    /** ‖λ − λ_h‖_{L2(ω)} with λ_h = 0 on the strip ω ∖ ω_h, as in (4.36). */
    std::optional<double> lambda_L2;
    /** ‖λ − λ_h‖_{L2(ω_h)}: the same without the strip. */
    std::optional<double> lambda_L2_omega_h;
    /** Energy error (Σ_i μ_i |u_i − u_ih|²_{H1})^{1/2} (seminorms). */
    std::optional<double> energy;
    /**
     * ‖λ − λ_h‖_{H^{-1}(ω)}, the dual norm (4.20) of H¹₀(ω) with the full
     * H¹ norm, in which Theorem 21 bounds the error (4.34); λ_h = 0 on the
     * strip ω ∖ ω_h (NegativeNorm).
     */
    std::optional<double> lambda_Hm1;
  };

  /** The flux estimator and the identities of the flux reconstruction. */
  struct FluxRecord
  {
    /**
     * The flux estimator and its parts (ErrorEstimator::flux_estimate()): the
     * flux part (Σ_i η_F,i²)^{1/2}, the oscillation part (Σ_i η_R,i²)^{1/2}
     * and the contact part (2 B)^{1/2}; the boundary data part, not part of
     * the estimator.
     */
    double estimator = 0, flux = 0, oscillation = 0, contact = 0, boundary = 0;
    /**
     * Defects of (4.17), (4.18) and of the balance of Lemma 17 (see
     * FluxReconstruction::Identities), with `Output/Flux reconstruction`.
     */
    std::optional<double> measure_defect, conservation_defect, balance_defect;
  };

  /**
   * The wall time of each phase of a cycle. Output writing is not timed,
   * the error norms against the exact solution on their own.
   */
  struct TimeRecord
  {
    double setup = 0, assembly = 0, solve = 0, postprocess = 0, estimate = 0;
    /** The flux reconstruction and its estimator; where computed. */
    std::optional<double> flux;
    /**
     * The error norms, a cost that a run without exact solution (or
     * without `Exact solution/Norms`) never pays.
     */
    std::optional<double> errors;

    /** The phases of the method: all but the error norms. */
    double
    method() const
    {
      return setup + assembly + solve + postprocess + estimate +
             (flux ? *flux : 0.);
    }
  };

  /**
   * Everything a run records about one cycle (one row of report.csv): what
   * each phase of the cycle returns, copied by MembraneProblem::run().
   */
  struct CycleRecord
  {
    MeshRecord     mesh;
    SolveRecord    solve;
    IdentityRecord identities;
    /** The errors the scene asks for (all empty without exact solution). */
    ErrorRecord errors;
    /** The residual estimator η; empty when not computed. */
    std::optional<double> estimator;
    /** Empty when the fluxes are not reconstructed. */
    std::optional<FluxRecord> flux;
    TimeRecord                times;
    /** TimeRecord::method() summed over this and all previous cycles. */
    double cumulative_wall_time = 0;

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
   * rewritten after every cycle by write_atomically() (a stopped run never
   * leaves a half-written file; one that cannot be written is an error
   * naming it and the system's reason, and the last complete report.csv
   * stays), and at the end the
   * same numbers as a deal.II ConvergenceTable with observed rates in h
   * (h ~ DoFs^{-1/2}) on the terminal.
   *
   * A row is one list of (column name, value) pairs, made from a
   * CycleRecord in report.cc: adding a column is one line there (and the
   * member of the record it reports). The effectivity indices are made
   * there too: an estimator divided by the energy error. The columns that
   * compare with the exact solution are in report.csv only where the run
   * computes them: the errors that `Exact solution/Norms` names, and the
   * effectivity indices with err_energy; a run without exact solution has
   * none of them.
   */
  class Report
  {
  public:
    Report(const Parameters::Output        &parameters,
           const Parameters::ExactSolution &exact,
           const ConditionalOStream        &pcout);

    /** Add the row of one cycle; write report.csv if asked for. */
    void
    add(const CycleRecord &record);

    /**
     * Continue the report.csv of the output directory (a resumed study):
     * its rows of the cycles up to @p last_cycle come before those that
     * add() adds; later rows (of a cycle that ran after the checkpoint) go.
     * A file with other columns, or without these rows, is a
     * Parameters::CollectiveError. The terminal's table of rates covers
     * the cycles of this run.
     */
    void
    resume(const unsigned int last_cycle);

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

  private:
    /** Which columns of a row the file has (see add()), and its header. */
    std::pair<std::vector<bool>, std::string>
    columns() const;

    const Parameters::Output        &parameters;
    const Parameters::ExactSolution &exact;
    const ConditionalOStream        &pcout;
    std::vector<CycleRecord>         records;
    /** The rows of report.csv from before a resumed study, as written. */
    std::vector<std::string> earlier_rows;
  };
} // namespace membranes

#endif
