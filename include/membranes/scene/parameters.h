#ifndef membranes_parameters_h
#define membranes_parameters_h

#include <deal.II/base/parameter_handler.h>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

/**
 * The run-time parameters of a scene. Each struct mirrors one subsection of
 * the parameter file; `declare_parameters()` documents every
 * entry, `parse_parameters()` reads it into typed fields and rejects values
 * that the pattern cannot catch (e.g. a ratio of the tensions beyond
 * max_tension_ratio) with a one-line message naming the entry.
 */
namespace membranes::Parameters
{
  using dealii::ParameterHandler;

  /**
   * An error in a scene. Its message is one line that names the entry as
   * `Subsection/Entry`, the offending value and what is allowed.
   */
  class InputError : public std::runtime_error
  {
  public:
    using std::runtime_error::runtime_error;
  };

  /**
   * An error that every process meets alike, because it is decided on
   * global quantities or by the first process and made known to all: every
   * process ends with exit status 1 and the first one prints the message
   * (no MPI_Abort).
   */
  class CollectiveError : public std::runtime_error
  {
  public:
    using std::runtime_error::runtime_error;
  };

  /**
   * The message of @p error on one line of printable text: deal.II's
   * description of its exceptions, or what(); line breaks, control
   * characters and runs of blanks become one blank, bytes that are not
   * part of valid UTF-8 are written as \\xNN.
   */
  std::string
  one_line_message(const std::exception &error);

  /**
   * The InputError for `entry = value`, which should be `allowed`. A value
   * longer than a line is shortened in the message.
   */
  InputError
  invalid_entry(const std::string &entry,
                const std::string &value,
                const std::string &allowed);

  /**
   * Why @p file_name cannot be read as an input file ("no such file", "not
   * a regular file", ...), or an empty string if it can. Directories,
   * devices and pipes are refused: they would read as nothing, or never
   * end (/dev/zero).
   */
  std::string
  unreadable_file(const std::string &file_name);

  /**
   * The largest magnitude of any number in the data: tensions lie in
   * [1/max_magnitude, max_magnitude], and every expression and every mesh
   * coordinate stays within ±max_magnitude where the program evaluates it.
   * Then no square or product that the program forms from the data (energy,
   * norms, residuals) overflows double precision.
   */
  constexpr double max_magnitude = 1e50;

  /**
   * The largest ratio μ1/μ2 or μ2/μ1 of the tensions. The active set method
   * balances forces of both membranes in one system; beyond this ratio the
   * softer membrane's forces drown in the round-off of the stiffer one's
   * and the method does not converge (observed from 1e16 on).
   */
  constexpr double max_tension_ratio = 1e12;

  /**
   * Read the scene @p file_name into @p prm by deal.II's parser
   * (ParameterHandler::parse_input()), once the program has made sure that
   * its `include` statements form no cycle (deal.II's parser would follow
   * one until the stack overflows). Any error is an InputError naming where
   * it is (the line, and `Subsection/Entry` or the subsection) and, for an
   * entry or a subsection that is not declared or a value that does not
   * match its pattern, what is allowed there: the declared entries or
   * subsections, or the pattern.
   */
  void
  read_scene(ParameterHandler &prm, const std::string &file_name);

  /**
   * Apply the command-line assignment `Subsection/Entry=value` to @p prm,
   * with the same messages as read_scene().
   */
  void
  set_entry(ParameterHandler &prm, const std::string &assignment);

  /**
   * Every parameter of @p prm, defaults included, as a parameter file in
   * deal.II's PRM style (each entry with its documentation), which
   * read_scene() reads back to the same values: what a run records in its
   * output directory as parameters.prm. A value that a parameter file
   * cannot hold (a line break; a '#', which starts a comment there; a '\\'
   * at the end, which continues the line) is an InputError naming its
   * entry.
   */
  std::string
  parameter_file(const ParameterHandler &prm);

  /**
   * The first entry, in declaration order, whose value differs between the
   * parameter files @p recorded and @p current (both of parameter_file()),
   * leaving out the entries @p free (`Subsection/Entry`), as
   * "'Sub/Entry' is 'a' here and was 'b'"; empty if there is none. An
   * entry that @p recorded cannot hold is an exception of
   * ParameterHandler.
   */
  std::string
  first_difference(const std::string              &recorded,
                   const std::string              &current,
                   const std::vector<std::string> &free);

  enum class Domain
  {
    square,
    lshape,
    slit,
    disk,
    file
  };

  enum class CellType
  {
    quadrilateral,
    triangle
  };

  /** Subsection `Geometry`: the domain ω and its initial mesh. */
  struct Geometry
  {
    Domain domain; ///< Square (−1,1)², L-shape, unit disk, or a Gmsh file.
    std::string  mesh_file; ///< Gmsh `.msh` file, read when `domain == file`.
    CellType     cell_type; ///< Q1 on quadrilaterals or P1 on triangles.
    unsigned int initial_refinement; ///< Global refinements of the coarse mesh.

    static void
    declare_parameters(ParameterHandler &prm);
    void
    parse_parameters(ParameterHandler &prm);
  };

  /** How the expressions of a scene are evaluated. */
  enum class ExpressionEvaluation
  {
    automatic, ///< Compiled when a compiler works, else the parser.
    compiled,  ///< Compiled to machine code (CompiledFunctions).
    parser     ///< Interpreted by muparser.
  };

  /** Subsection `Problem`: tensions, loads and boundary heights of (1.1). */
  struct Problem
  {
    double mu1; ///< Tension μ1 > 0 of membrane 1.
    double mu2; ///< Tension μ2 > 0 of membrane 2.
    std::string
      function_constants; ///< `name=value` pairs usable in expressions.
    std::string f1;       ///< Load f1(x, y).
    std::string f2;       ///< Load f2(x, y).
    std::string g;        ///< Height g ≥ 0 of membrane 1 on ∂ω.
    std::string g2;       ///< Height g2 ≤ g of membrane 2 on ∂ω.
    /** Compiled expressions, the parser, or compiled if possible. */
    ExpressionEvaluation expression_evaluation;

    static void
    declare_parameters(ParameterHandler &prm);
    void
    parse_parameters(ParameterHandler &prm);
  };

  /** Subsection `Exact solution`: (u1, u2, λ) when known, for error norms. */
  struct ExactSolution
  {
    bool        known;  ///< Compute error norms against the expressions below.
    std::string u1;     ///< Exact u1(x, y).
    std::string u2;     ///< Exact u2(x, y).
    std::string lambda; ///< Exact action λ(x, y).
    /**
     * ∇u1 as `∂/∂x; ∂/∂y`, two expressions separated by ';'; empty: central
     * finite differences of u1.
     */
    std::string u1_gradient;
    std::string u2_gradient; ///< ∇u2, likewise.
    /**
     * Derive the data from u1, u2, λ: f1 = −μ1Δu1 − λ, f2 = −μ2Δu2 + λ,
     * g = u1 and g2 = u2 on ∂ω (Problem/f1, f2, g, g2 stay unset).
     */
    bool manufactured;
    /**
     * 0, or N > 0: the errors by the composite reference rule of ErrorNorms
     * with 4^N triangles per sub-triangle.
     */
    unsigned int reference_quadrature;
    /**
     * The error columns of report.csv that the run computes (`Norms`), by
     * their names there; a subset of error_norm_names().
     */
    std::set<std::string> norms;

    /** The names of all error columns, the words of `Norms`. */
    static const std::vector<std::string> &
    error_norm_names();

    /** Whether the run computes the error column @p name. */
    bool
    computes(const std::string &name) const
    {
      return known && norms.count(name) != 0;
    }

    /** Whether the run computes any error column. */
    bool
    computes_any() const
    {
      return known && !norms.empty();
    }

    static void
    declare_parameters(ParameterHandler &prm);
    void
    parse_parameters(ParameterHandler &prm);
  };

  enum class SolverMethod
  {
    automatic,
    coupled,
    decoupled
  };

  enum class LinearSolverType
  {
    automatic,
    direct,
    cg_amg
  };

  /** When the active set method and its linear solves stop. */
  enum class Stopping
  {
    exact,   ///< At `Tolerance`: the discrete solution to round-off.
    balanced ///< At a fraction of the discretization error of the mesh.
  };

  /** Subsection `Solver`: the primal-dual active set method. */
  struct Solver
  {
    /** Coupled (u1, u2), decoupled (s, w), or auto (always decoupled). */
    SolverMethod method;
    LinearSolverType
                 linear_solver; ///< Sparse LU, CG with AMG, or chosen by size.
    double       tolerance;     ///< Relative KKT residual to reach.
    unsigned int max_active_set_iterations; ///< Give up after this many.
    Stopping     stopping; ///< Exact, or balanced against the estimator.
    /** γ: linearization + algebraic error ≤ γ η (balanced stopping). */
    double balance_fraction;

    static void
    declare_parameters(ParameterHandler &prm);
    void
    parse_parameters(ParameterHandler &prm);
  };

  enum class RefinementStrategy
  {
    global,
    adaptive
  };

  /**
   * The marking of adaptive refinement, by deal.II's names: the bulk
   * criterion (Dörfler marking, deal.II's
   * `refine_and_coarsen_fixed_fraction`), or a fixed share of the cells
   * (`refine_and_coarsen_fixed_number`).
   */
  enum class Marking
  {
    bulk,        ///< The fewest cells that hold the share θ of η².
    fixed_number ///< The share of the cells with the largest η_K.
  };

  enum class Estimator
  {
    residual,
    flux
  };

  /** Subsection `Refinement`: the sequence of meshes of one run. */
  struct Refinement
  {
    RefinementStrategy strategy; ///< Global or adaptive refinement.
    unsigned int       cycles;   ///< Number of meshes (cycles) of the run.
    Marking            marking;  ///< Bulk (Dörfler) or fixed number.
    double       bulk_parameter; ///< θ: the share of η² of bulk marking.
    double       refinement_fraction; ///< The share of cells of fixed number.
    double       coarsen_fraction;    ///< The same at the small end; 0 = none.
    double       minimum_growth;      ///< Least growth factor of the cells.
    unsigned int max_dofs;            ///< Stop before exceeding; 0 = no limit.
    Estimator    estimator;        ///< Which a posteriori estimator drives it.
    double       target_estimator; ///< Stop once η <= this; 0 = no target.

    static void
    declare_parameters(ParameterHandler &prm);
    void
    parse_parameters(ParameterHandler &prm);

    /**
     * The share that the marking refines: `Bulk parameter` (of η²) or
     * `Refinement fraction` (of the cells).
     */
    double
    refined_share() const;

  private:
    /**
     * `Marking` and its share; the former name `fixed fraction`, and the
     * share of the other marking set, refused.
     */
    void
    parse_marking(ParameterHandler &prm);
  };

  /** Subsection `Output`: what a run writes, and where. */
  struct Output
  {
    std::string directory;   ///< Where report.csv and VTU files go.
    bool        report;      ///< Write report.csv.
    bool        write_vtu;   ///< Write VTU files and a .pvd over cycles.
    bool write_nodal_values; ///< Write the nodal values as CSV, full precision.
    bool flux_reconstruction; ///< Compute and write the fluxes t_ih.
    /** Write a checkpoint after every k-th cycle and the last; 0: none. */
    unsigned int checkpoint_every;
    bool         resume; ///< Continue from the checkpoint of the directory.

    static void
    declare_parameters(ParameterHandler &prm);
    void
    parse_parameters(ParameterHandler &prm);
  };

  /** All subsections of a scene. */
  struct All
  {
    Geometry      geometry;
    Problem       problem;
    ExactSolution exact_solution;
    Solver        solver;
    Refinement    refinement;
    Output        output;

    static void
    declare_parameters(ParameterHandler &prm);
    void
    parse_parameters(ParameterHandler &prm);
  };
} // namespace membranes::Parameters

#endif
