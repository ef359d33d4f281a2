#include <deal.II/base/utilities.h>
#include <membranes/scene/parameters.h>
#include <sstream>
#include <tuple>
#include <vector>

namespace membranes::Parameters
{
  using dealii::Patterns::Bool;
  using dealii::Patterns::Double;
  using dealii::Patterns::Integer;
  using dealii::Patterns::Selection;
  using dealii::Utilities::trim;



  InputError
  invalid_entry(const std::string &entry,
                const std::string &value,
                const std::string &allowed)
  {
    const std::size_t longest = 200;
    const std::string shown =
      value.size() <= longest ? value : value.substr(0, longest) + "...";
    return InputError(entry + " = '" + shown + "' is invalid: " + allowed);
  }



  namespace
  {
    /**
     * The number in entry @p entry of the current subsection @p subsection.
     * The Double pattern lets numbers through that std::strtod then refuses
     * (below the normal range of double precision, e.g. 1e-308): an
     * InputError names them.
     */
    double
    get_double(const ParameterHandler &prm,
               const std::string      &subsection,
               const std::string      &entry)
    {
      try
        {
          return prm.get_double(entry);
        }
      catch (const dealii::ExceptionBase &)
        {
          throw invalid_entry(subsection + "/" + entry,
                              prm.get(entry),
                              "not a number of double precision (at least "
                              "2.3e-308 in magnitude, or 0)");
        }
    }



    /**
     * The words of a `Selection` entry and the values they stand for: the
     * one mapping between a scene and the program, from which the entry's
     * pattern is declared (selection()) and its value read (selected()).
     */
    template <typename Enum>
    using Choices = std::vector<std::pair<std::string, Enum>>;

    const Choices<Domain>           domains{{"square", Domain::square},
                                  {"lshape", Domain::lshape},
                                  {"slit", Domain::slit},
                                  {"disk", Domain::disk},
                                  {"file", Domain::file}};
    const Choices<CellType>         cell_types{{"quadrilateral",
                                                CellType::quadrilateral},
                                       {"triangle", CellType::triangle}};
    const Choices<SolverMethod>     methods{{"auto", SolverMethod::automatic},
                                        {"coupled", SolverMethod::coupled},
                                        {"decoupled", SolverMethod::decoupled}};
    const Choices<LinearSolverType> linear_solvers{
      {"auto", LinearSolverType::automatic},
      {"direct", LinearSolverType::direct},
      {"cg-amg", LinearSolverType::cg_amg}};
    const Choices<Stopping>           stoppings{{"exact", Stopping::exact},
                                      {"balanced", Stopping::balanced}};
    const Choices<RefinementStrategy> strategies{
      {"global", RefinementStrategy::global},
      {"adaptive", RefinementStrategy::adaptive}};
    const Choices<Marking>   markings{{"bulk", Marking::bulk},
                                    {"fixed number", Marking::fixed_number}};
    const Choices<Estimator> estimators{{"residual", Estimator::residual},
                                        {"flux", Estimator::flux}};
    const Choices<ExpressionEvaluation> evaluations{
      {"auto", ExpressionEvaluation::automatic},
      {"compiled", ExpressionEvaluation::compiled},
      {"parser", ExpressionEvaluation::parser}};

    /**
     * The former name of `Marking = fixed number`, which deal.II gives the
     * bulk criterion: in the pattern of the entry, so that reading it can
     * say what to write instead.
     */
    const std::string former_fixed_number = "fixed fraction";

    /**
     * The default of `Exact solution/Norms`: every error column that
     * ErrorNorms computes in its one pass over the cells, not the H^{-1}
     * norm of the action (NegativeNorm), which solves a problem of its own.
     */
    const std::string default_norms =
      "err_u1_H1, err_u2_H1, err_u1_L2, err_u2_L2, err_energy, "
      "err_lambda_L2, err_lambda_L2_omega_h";

    /** The defaults of `Bulk parameter` and `Refinement fraction`. */
    const std::string default_bulk_parameter      = "0.5";
    const std::string default_refinement_fraction = "0.5";

    /**
     * The Selection pattern of @p choices: their words, in this order, and
     * the word @p refused, which reading the entry rejects.
     */
    template <typename Enum>
    Selection
    selection(const Choices<Enum> &choices, const std::string &refused = "")
    {
      std::string words;
      for (const auto &choice : choices)
        words += (words.empty() ? "" : "|") + choice.first;
      return Selection(refused.empty() ? words : words + "|" + refused);
    }

    /**
     * The value of the Selection entry @p path (`Subsection/Entry`, the
     * current subsection's) in its enum. Its pattern, selection(@p choices),
     * admits no other word, except a value that deal.II does not check (one
     * with '{', which it keeps for its parameter loops): that one gets the
     * usual error line, with the allowed words.
     */
    template <typename Enum>
    Enum
    selected(const ParameterHandler &prm,
             const std::string      &path,
             const Choices<Enum>    &choices)
    {
      const std::string word = prm.get(path.substr(path.rfind('/') + 1));
      for (const auto &[name, value] : choices)
        if (name == word)
          return value;
      throw invalid_entry(
        path, word, "expected one of " + selection(choices).description());
    }
  } // namespace



  void
  Geometry::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Geometry");
    prm.declare_entry("Domain",
                      "square",
                      selection(domains),
                      "square = (-1,1)^2; lshape = (-1,1)^2 minus [0,1)^2; "
                      "slit = (-1,1)^2 minus the segment [0,1) x {0} (both "
                      "faces of the slit are boundary); disk = unit disk "
                      "(curved boundary kept under refinement); file = the "
                      "Gmsh mesh in 'Mesh file'.");
    prm.declare_entry("Mesh file",
                      "",
                      dealii::Patterns::FileName(),
                      "Gmsh .msh file (triangles or quadrilaterals), read "
                      "when Domain = file.");
    prm.declare_entry("Cell type",
                      "quadrilateral",
                      selection(cell_types),
                      "quadrilateral: Q1 elements; triangle: P1 elements (the "
                      "paper's setting). Quadrilateral meshes are split into "
                      "triangles when triangle is asked for.");
    prm.declare_entry("Initial refinement",
                      "3",
                      Integer(0, 20),
                      "Global refinements of the coarse mesh before cycle 0.");
    prm.leave_subsection();
  }

  void
  Geometry::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Geometry");
    domain    = selected(prm, "Geometry/Domain", domains);
    mesh_file = prm.get("Mesh file");
    if (domain == Domain::file && mesh_file.empty())
      throw invalid_entry("Geometry/Mesh file",
                          mesh_file,
                          "a Gmsh .msh file is needed when Domain = file");
    cell_type          = selected(prm, "Geometry/Cell type", cell_types);
    initial_refinement = prm.get_integer("Initial refinement");
    prm.leave_subsection();
  }



  void
  Problem::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Problem");
    prm.declare_entry("mu1",
                      "1",
                      Double(1 / max_magnitude, max_magnitude),
                      "Tension of membrane 1, in [1e-50, 1e50], with "
                      "mu1/mu2 in [1e-12, 1e12].");
    prm.declare_entry("mu2",
                      "1",
                      Double(1 / max_magnitude, max_magnitude),
                      "Tension of membrane 2, likewise.");
    prm.declare_entry("Function constants",
                      "",
                      dealii::Patterns::Anything(),
                      "Comma separated name=value pairs usable in every "
                      "expression, e.g. 'R=0.5, k=2'. The names mu1, mu2 and "
                      "pi are always defined.");
    prm.declare_entry("f1",
                      "0",
                      dealii::Patterns::Anything(),
                      "Load on membrane 1, an expression in x, y.");
    prm.declare_entry("f2",
                      "0",
                      dealii::Patterns::Anything(),
                      "Load on membrane 2, an expression in x, y.");
    prm.declare_entry("g",
                      "0",
                      dealii::Patterns::Anything(),
                      "Height of membrane 1 on the boundary, g >= 0.");
    prm.declare_entry("g2",
                      "0",
                      dealii::Patterns::Anything(),
                      "Height of membrane 2 on the boundary (the paper: 0); "
                      "g - g2 >= 0.");
    prm.declare_entry("Expression evaluation",
                      "auto",
                      selection(evaluations),
                      "compiled: the expressions are translated to C++, "
                      "compiled with the compiler that built the program "
                      "(or $MEMBRANES_CXX) and cached; parser: muparser "
                      "interprets them; auto: compiled if a compiler works, "
                      "else the parser.");
    prm.leave_subsection();
  }

  void
  Problem::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Problem");
    mu1 = get_double(prm, "Problem", "mu1");
    mu2 = get_double(prm, "Problem", "mu2");
    if (!(mu1 <= max_tension_ratio * mu2 && mu2 <= max_tension_ratio * mu1))
      {
        std::ostringstream message;
        message << "Problem/mu1 = '" << prm.get("mu1")
                << "' and Problem/mu2 = '" << prm.get("mu2")
                << "' are invalid: the ratio mu1/mu2 must "
                << "lie in [" << 1 / max_tension_ratio << ", "
                << max_tension_ratio << "]";
        throw InputError(message.str());
      }
    function_constants = prm.get("Function constants");
    f1                 = prm.get("f1");
    f2                 = prm.get("f2");
    g                  = prm.get("g");
    g2                 = prm.get("g2");
    expression_evaluation =
      selected(prm, "Problem/Expression evaluation", evaluations);
    prm.leave_subsection();
  }



  void
  ExactSolution::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Exact solution");
    prm.declare_entry("Known",
                      "false",
                      Bool(),
                      "Whether u1, u2, lambda below are the exact solution; "
                      "error norms are computed only then.");
    prm.declare_entry("u1", "0", dealii::Patterns::Anything(), "Exact u1.");
    prm.declare_entry("u2", "0", dealii::Patterns::Anything(), "Exact u2.");
    prm.declare_entry("lambda",
                      "0",
                      dealii::Patterns::Anything(),
                      "Exact action lambda of membrane 2 on membrane 1.");
    prm.declare_entry("u1 gradient",
                      "",
                      dealii::Patterns::Anything(),
                      "Gradient of the exact u1 as two expressions separated "
                      "by ';', the derivatives by x and by y (e.g. '2*x; "
                      "2*y' for u1 = x^2 + y^2), for the H1 errors; empty: "
                      "central finite differences of u1.");
    prm.declare_entry("u2 gradient",
                      "",
                      dealii::Patterns::Anything(),
                      "Gradient of the exact u2, likewise.");
    prm.declare_entry("Manufactured data",
                      "false",
                      Bool(),
                      "Derive the data from u1, u2, lambda above: f1 = "
                      "-mu1 Laplace(u1) - lambda, f2 = -mu2 Laplace(u2) + "
                      "lambda, g = u1 and g2 = u2 on the boundary (Problem/"
                      "f1, f2, g, g2 are then not set). Needs compiled "
                      "expressions.");
    prm.declare_entry("Reference quadrature",
                      "0",
                      Integer(0, 6),
                      "0: the error norms' own rule; N > 0: all errors "
                      "but err_lambda_Hm1 integrated instead by a "
                      "composite rule, each "
                      "sub-triangle of the dual mesh cut into 4^N triangles "
                      "with 4 points on each, the reference of "
                      "benchmarks/error_quadrature.sh (slow).");
    std::string names;
    for (const std::string &name : error_norm_names())
      names += (names.empty() ? "" : "|") + name;
    prm.declare_entry(
      "Norms",
      default_norms,
      dealii::Patterns::MultipleSelection(names),
      "The error columns of the report, a comma-separated list of "
      "err_u1_H1, err_u2_H1 (full H1 norms), err_u1_L2, err_u2_L2, "
      "err_energy (the energy norm; the effectivity indices need it), "
      "err_lambda_L2 (on omega), err_lambda_L2_omega_h (on omega_h), "
      "err_lambda_Hm1 (the H^-1 norm of (4.20), by a Riesz problem of "
      "degree 2 on the mesh: it costs more than all others together). "
      "The default computes all but err_lambda_Hm1, in one pass over the "
      "cells.");
    prm.leave_subsection();
  }

  void
  ExactSolution::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Exact solution");
    known        = prm.get_bool("Known");
    u1           = prm.get("u1");
    u2           = prm.get("u2");
    lambda       = prm.get("lambda");
    u1_gradient  = prm.get("u1 gradient");
    u2_gradient  = prm.get("u2 gradient");
    manufactured = prm.get_bool("Manufactured data");

    reference_quadrature = prm.get_integer("Reference quadrature");
    norms.clear();
    for (const std::string &name :
         dealii::Utilities::split_string_list(prm.get("Norms")))
      norms.insert(name);
    prm.leave_subsection();
  }



  const std::vector<std::string> &
  ExactSolution::error_norm_names()
  {
    static const std::vector<std::string> names{"err_u1_H1",
                                                "err_u2_H1",
                                                "err_u1_L2",
                                                "err_u2_L2",
                                                "err_energy",
                                                "err_lambda_L2",
                                                "err_lambda_L2_omega_h",
                                                "err_lambda_Hm1"};
    return names;
  }



  void
  Solver::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Solver");
    prm.declare_entry("Method",
                      "auto",
                      selection(methods),
                      "coupled: active set method on (u1, u2); decoupled: "
                      "linear problem for s = mu1 u1 + mu2 u2 and obstacle "
                      "problem for w = u1 - u2; auto: always decoupled (half "
                      "the size, s solved once per mesh, its operators from "
                      "the matrix of the mesh); coupled and decoupled give "
                      "the same discrete solution.");
    prm.declare_entry(
      "Linear solver",
      "auto",
      selection(linear_solvers),
      "direct: sparse LU (UMFPACK on one process, Trilinos Amesos "
      "MUMPS on several); cg-amg: CG with Trilinos ML AMG; auto: "
      "direct up to 1000 unknowns on one process, cg-amg above.");
    prm.declare_entry("Tolerance",
                      "1e-10",
                      Double(1e-15, 1e-2),
                      "Relative KKT residual at which the active set method "
                      "stops (once the active set repeats).");
    prm.declare_entry("Max active set iterations",
                      "100",
                      Integer(1, 100000),
                      "The run stops with an error if the active set method "
                      "has not converged after this many iterations.");
    prm.declare_entry("Stopping",
                      "exact",
                      selection(stoppings),
                      "exact: the active set method stops at Tolerance; "
                      "balanced: it and its CG solves stop once the "
                      "linearization and algebraic errors are below Balance "
                      "fraction times the discretization error expected on "
                      "the mesh (the residual estimator of the previous mesh "
                      "scaled to this one; the first mesh stops exactly).");
    prm.declare_entry("Balance fraction",
                      "0.1",
                      Double(),
                      "gamma in (0, 1) of Stopping = balanced.");
    prm.leave_subsection();
  }

  void
  Solver::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Solver");
    method        = selected(prm, "Solver/Method", methods);
    linear_solver = selected(prm, "Solver/Linear solver", linear_solvers);
    tolerance     = get_double(prm, "Solver", "Tolerance");
    max_active_set_iterations = prm.get_integer("Max active set iterations");
    stopping                  = selected(prm, "Solver/Stopping", stoppings);
    balance_fraction          = get_double(prm, "Solver", "Balance fraction");
    if (!(balance_fraction > 0 && balance_fraction < 1))
      throw invalid_entry("Solver/Balance fraction",
                          prm.get("Balance fraction"),
                          "the fraction must be in (0, 1)");
    prm.leave_subsection();
  }



  void
  Refinement::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Refinement");
    prm.declare_entry("Strategy",
                      "global",
                      selection(strategies),
                      "global: every cell is refined in every cycle; "
                      "adaptive: cells are marked by the estimator of "
                      "'Estimator'.");
    prm.declare_entry("Cycles",
                      "6",
                      Integer(1, 100),
                      "Number of meshes (cycles) of the run.");
    prm.declare_entry("Marking",
                      "bulk",
                      selection(markings, former_fixed_number),
                      "Marking for adaptive refinement, by deal.II's "
                      "names: bulk (Doerfler marking, the bulk criterion; "
                      "deal.II's refine_and_coarsen_fixed_fraction) "
                      "refines the fewest cells, those with the largest "
                      "indicators, whose squared indicators sum up to the "
                      "share 'Bulk parameter' of the squared estimator; "
                      "fixed number (deal.II's "
                      "refine_and_coarsen_fixed_number) refines the share "
                      "'Refinement fraction' of the cells, those with the "
                      "largest indicators. 'fixed fraction' is refused with "
                      "what to write instead: this entry once used it for "
                      "fixed number. Where every indicator is zero (the "
                      "estimator finds the discrete solution exact) no "
                      "cell is marked: the run says so in one line and "
                      "ends after that cycle.");
    prm.declare_entry("Bulk parameter",
                      default_bulk_parameter,
                      Double(0, 1),
                      "The share theta of the squared estimator that "
                      "Marking = bulk refines (0 < theta <= 1); only with "
                      "bulk.");
    prm.declare_entry("Refinement fraction",
                      default_refinement_fraction,
                      Double(0, 1),
                      "The share of the cells that Marking = fixed number "
                      "refines, those with the largest indicators (0 < "
                      "share <= 1); only with fixed number.");
    prm.declare_entry("Coarsen fraction",
                      "0",
                      Double(0, 1),
                      "The share coarsened at the small end of the "
                      "indicators, of the squared estimator (bulk) or of "
                      "the cells (fixed number), with the refined share + "
                      "Coarsen fraction <= 1; 0 = no coarsening "
                      "(quadrilaterals only: deal.II 9.4 cannot coarsen "
                      "triangles).");
    prm.declare_entry("Minimum growth",
                      "1",
                      Double(1, 4),
                      "Adaptive refinement refines at least the (Minimum "
                      "growth - 1)/3 cells with the largest indicators, so "
                      "that the number of cells grows at least by this "
                      "factor per cycle (each refined cell makes four); "
                      "where the marking selects more cells, it stands. "
                      "1 = the marking alone, 4 = global refinement.");
    prm.declare_entry("Max dofs",
                      "0",
                      Integer(0),
                      "The run ends before a mesh with more DoFs than this; "
                      "0 = no limit.");
    prm.declare_entry("Estimator",
                      "residual",
                      selection(estimators),
                      "A posteriori estimator that drives adaptive "
                      "refinement: residual, or flux (built on the "
                      "equilibrated fluxes of the paper's section 4.2, "
                      "which it computes; report columns flux_estimator "
                      "and its parts flux_estimator_flux, _oscillation, "
                      "_contact). The residual estimator is computed when "
                      "it drives refinement or when the exact solution is "
                      "known (for the effectivity index), the flux "
                      "estimator when it is chosen here or when 'Output/"
                      "Flux reconstruction = true'.");
    prm.declare_entry("Target estimator",
                      "0",
                      Double(0),
                      "The run ends after the first cycle whose estimator "
                      "(the one of 'Estimator', the value of its report "
                      "column) is at most this value, or after 'Cycles', or "
                      "before 'Max dofs', whichever comes first; 0 = no "
                      "target.");
    prm.leave_subsection();
  }

  void
  Refinement::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Refinement");
    strategy = selected(prm, "Refinement/Strategy", strategies);
    cycles   = prm.get_integer("Cycles");
    parse_marking(prm);
    coarsen_fraction = get_double(prm, "Refinement", "Coarsen fraction");
    // Shares of the same cells (or of the same η²), at its two ends.
    if (refined_share() + coarsen_fraction > 1)
      throw invalid_entry("Refinement/Coarsen fraction",
                          prm.get("Coarsen fraction"),
                          (marking == Marking::bulk ? "Bulk parameter" :
                                                      "Refinement fraction") +
                            std::string(" + Coarsen fraction must be <= 1"));
    minimum_growth   = get_double(prm, "Refinement", "Minimum growth");
    max_dofs         = prm.get_integer("Max dofs");
    estimator        = selected(prm, "Refinement/Estimator", estimators);
    target_estimator = get_double(prm, "Refinement", "Target estimator");
    prm.leave_subsection();
  }



  void
  Refinement::parse_marking(ParameterHandler &prm)
  {
    if (prm.get("Marking") == former_fixed_number)
      throw invalid_entry(
        "Refinement/Marking",
        former_fixed_number,
        "write 'fixed number' to refine the share 'Refinement fraction' of "
        "the cells with the largest indicators (deal.II's "
        "refine_and_coarsen_fixed_number), or 'bulk' for the bulk criterion "
        "with 'Bulk parameter' (Doerfler marking, which deal.II calls "
        "refine_and_coarsen_fixed_fraction)");
    marking = selected(prm, "Refinement/Marking", markings);
    for (const auto &[entry, share, default_value, used] :
         {std::tuple{"Bulk parameter",
                     &bulk_parameter,
                     default_bulk_parameter,
                     marking == Marking::bulk},
          std::tuple{"Refinement fraction",
                     &refinement_fraction,
                     default_refinement_fraction,
                     marking == Marking::fixed_number}})
      {
        *share = get_double(prm, "Refinement", entry);
        if (!(*share > 0))
          throw invalid_entry(std::string("Refinement/") + entry,
                              prm.get(entry),
                              "the share must be in (0, 1]");
        // The share of the other marking, set: the scene meant this one.
        if (!used && *share != std::stod(default_value))
          throw invalid_entry(
            std::string("Refinement/") + entry,
            prm.get(entry),
            std::string("it sets the share of Marking = ") +
              (marking == Marking::bulk ?
                 "fixed number; Marking = bulk refines the share 'Bulk "
                 "parameter' of the squared estimator" :
                 "bulk; Marking = fixed number refines the share "
                 "'Refinement fraction' of the cells"));
      }
  }

  double
  Refinement::refined_share() const
  {
    return marking == Marking::bulk ? bulk_parameter : refinement_fraction;
  }



  void
  Output::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Output");
    prm.declare_entry("Directory",
                      "output",
                      dealii::Patterns::DirectoryName(),
                      "Directory for report.csv, the field output, "
                      "parameters.prm and run-info.txt; created if missing. "
                      "One run at a time holds it, and removes the files "
                      "that an earlier run wrote there (those only) before "
                      "its first cycle, unless it resumes that run "
                      "('Resume').");
    prm.declare_entry("Report",
                      "true",
                      Bool(),
                      "Write report.csv, one row per cycle.");
    prm.declare_entry("Write vtu",
                      "true",
                      Bool(),
                      "Write u1, u2, u1-u2, lambda_h and the active set as "
                      "VTU, with a .pvd over cycles.");
    prm.declare_entry("Write nodal values",
                      "false",
                      Bool(),
                      "Write x, y, u1, u2, lambda_h and the active set at "
                      "every vertex, in full precision, to "
                      "nodal-values-NN.csv (one file per cycle).");
    prm.declare_entry("Flux reconstruction",
                      "false",
                      Bool(),
                      "Write the flux reconstruction of the paper's "
                      "section 4.2: the defects of (4.17), (4.18) and of "
                      "the balance of Lemma 17 (report.csv), and with "
                      "'Write vtu' the dual mesh with t_ih as "
                      "dual-mesh-NN.vtu. It is computed for this, and the "
                      "flux estimator with it; 'Refinement/Estimator = "
                      "flux' computes both without writing them.");
    prm.declare_entry("Checkpoint every",
                      "0",
                      dealii::Patterns::Integer(0),
                      "Keep in checkpoint/ of the output directory what the "
                      "next cycle needs (the mesh, u1, u2, lambda_h and the "
                      "indicators) after every k-th cycle and the last; 0 "
                      "keeps none. Only the last checkpoint is kept.");
    prm.declare_entry("Resume",
                      "false",
                      Bool(),
                      "Continue the study of the output directory from its "
                      "checkpoint, with the cycle after it, appending to "
                      "report.csv and the .pvd files (also: --resume). The "
                      "scene must be the one that wrote it, but for "
                      "'Refinement/Cycles' and the entries of 'Output'.");
    prm.leave_subsection();
  }

  void
  Output::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Output");
    directory = prm.get("Directory");
    if (directory.empty())
      throw invalid_entry("Output/Directory", "", "a directory name is needed");
    report              = prm.get_bool("Report");
    write_vtu           = prm.get_bool("Write vtu");
    write_nodal_values  = prm.get_bool("Write nodal values");
    flux_reconstruction = prm.get_bool("Flux reconstruction");
    checkpoint_every    = prm.get_integer("Checkpoint every");
    resume              = prm.get_bool("Resume");
    prm.leave_subsection();
  }



  void
  All::declare_parameters(ParameterHandler &prm)
  {
    Geometry::declare_parameters(prm);
    Problem::declare_parameters(prm);
    ExactSolution::declare_parameters(prm);
    Solver::declare_parameters(prm);
    Refinement::declare_parameters(prm);
    Output::declare_parameters(prm);
  }

  void
  All::parse_parameters(ParameterHandler &prm)
  {
    geometry.parse_parameters(prm);
    problem.parse_parameters(prm);
    exact_solution.parse_parameters(prm);
    solver.parse_parameters(prm);
    refinement.parse_parameters(prm);
    output.parse_parameters(prm);
    if (geometry.cell_type == CellType::triangle &&
        refinement.strategy == RefinementStrategy::adaptive &&
        refinement.coarsen_fraction > 0)
      throw invalid_entry("Refinement/Coarsen fraction",
                          std::to_string(refinement.coarsen_fraction),
                          "deal.II 9.4 cannot coarsen triangle meshes: use 0 "
                          "with 'Cell type = triangle'");
    if (exact_solution.manufactured)
      {
        if (problem.expression_evaluation == ExpressionEvaluation::parser)
          throw invalid_entry(
            "Exact solution/Manufactured data",
            "true",
            "derives the loads by differentiating the compiled expressions "
            "of u1, u2: use it with Problem/Expression evaluation = auto or "
            "compiled, not parser");
        // The data that it derives: left at their defaults ("0").
        for (const auto &[entry, value] : {std::pair{"Problem/f1", problem.f1},
                                           std::pair{"Problem/f2", problem.f2},
                                           std::pair{"Problem/g", problem.g},
                                           std::pair{"Problem/g2", problem.g2}})
          if (trim(value) != "0")
            throw invalid_entry(entry,
                                value,
                                "not set with Exact solution/Manufactured "
                                "data = true, which derives it from u1, u2 "
                                "and lambda");
      }
  }
} // namespace membranes::Parameters
