#include <cmath>
#include <membranes/parameters.h>

namespace membranes::Parameters
{
  using dealii::Patterns::Bool;
  using dealii::Patterns::Double;
  using dealii::Patterns::Integer;
  using dealii::Patterns::Selection;

  InputError
  invalid_entry(const std::string &entry,
                const std::string &value,
                const std::string &allowed)
  {
    return InputError(entry + " = '" + value + "' is invalid: " + allowed);
  }



  void
  Geometry::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Geometry");
    prm.declare_entry("Domain",
                      "square",
                      Selection("square|lshape|disk|file"),
                      "square = (-1,1)^2; lshape = (-1,1)^2 minus [0,1)^2; "
                      "disk = unit disk (curved boundary kept under "
                      "refinement); file = the Gmsh mesh in 'Mesh file'.");
    prm.declare_entry("Mesh file",
                      "",
                      dealii::Patterns::FileName(),
                      "Gmsh .msh file (triangles or quadrilaterals), read "
                      "when Domain = file.");
    prm.declare_entry("Cell type",
                      "quadrilateral",
                      Selection("quadrilateral|triangle"),
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
    const std::string d = prm.get("Domain");
    domain              = (d == "square" ? Domain::square :
                           d == "lshape" ? Domain::lshape :
                           d == "disk"   ? Domain::disk :
                                           Domain::file);
    mesh_file           = prm.get("Mesh file");
    if (domain == Domain::file && mesh_file.empty())
      throw invalid_entry("Geometry/Mesh file",
                          mesh_file,
                          "a Gmsh .msh file is needed when Domain = file");
    cell_type = (prm.get("Cell type") == "triangle" ? CellType::triangle :
                                                      CellType::quadrilateral);
    initial_refinement = prm.get_integer("Initial refinement");
    prm.leave_subsection();
  }



  void
  Problem::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Problem");
    prm.declare_entry("mu1", "1", Double(), "Tension of membrane 1 (> 0).");
    prm.declare_entry("mu2", "1", Double(), "Tension of membrane 2 (> 0).");
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
    prm.leave_subsection();
  }

  void
  Problem::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Problem");
    mu1 = prm.get_double("mu1");
    mu2 = prm.get_double("mu2");
    for (const auto &[name, value] : {std::pair{"mu1", mu1}, {"mu2", mu2}})
      if (!(value > 0) || !std::isfinite(value))
        throw invalid_entry(std::string("Problem/") + name,
                            prm.get(name),
                            "a tension must be a finite number > 0");
    function_constants = prm.get("Function constants");
    f1                 = prm.get("f1");
    f2                 = prm.get("f2");
    g                  = prm.get("g");
    g2                 = prm.get("g2");
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
    prm.leave_subsection();
  }

  void
  ExactSolution::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Exact solution");
    known  = prm.get_bool("Known");
    u1     = prm.get("u1");
    u2     = prm.get("u2");
    lambda = prm.get("lambda");
    prm.leave_subsection();
  }



  void
  Solver::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Solver");
    prm.declare_entry("Method",
                      "coupled",
                      Selection("coupled|decoupled"),
                      "coupled: active set method on (u1, u2); decoupled: "
                      "linear problem for s = mu1 u1 + mu2 u2 and obstacle "
                      "problem for w = u1 - u2.");
    prm.declare_entry("Linear solver",
                      "auto",
                      Selection("auto|direct|cg-amg"),
                      "direct: UMFPACK; cg-amg: CG with Trilinos ML AMG; "
                      "auto: direct for small problems on one process.");
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
    prm.leave_subsection();
  }

  void
  Solver::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Solver");
    method = (prm.get("Method") == "decoupled" ? SolverMethod::decoupled :
                                                 SolverMethod::coupled);
    const std::string ls      = prm.get("Linear solver");
    linear_solver             = (ls == "direct" ? LinearSolverType::direct :
                                 ls == "cg-amg" ? LinearSolverType::cg_amg :
                                                  LinearSolverType::automatic);
    tolerance                 = prm.get_double("Tolerance");
    max_active_set_iterations = prm.get_integer("Max active set iterations");
    prm.leave_subsection();
  }



  void
  Refinement::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Refinement");
    prm.declare_entry("Strategy",
                      "global",
                      Selection("global|adaptive"),
                      "global: every cell is refined in every cycle; "
                      "adaptive: cells are marked by the residual "
                      "estimator.");
    prm.declare_entry("Cycles",
                      "6",
                      Integer(1, 100),
                      "Number of meshes (cycles) of the run.");
    prm.declare_entry("Marking",
                      "bulk",
                      Selection("bulk|fixed fraction"),
                      "Marking for adaptive refinement: bulk (Doerfler) "
                      "refines the fewest cells that hold the share 'Bulk "
                      "parameter' of the squared estimator; fixed fraction "
                      "refines that share of the cells, those with the "
                      "largest indicators.");
    prm.declare_entry("Bulk parameter",
                      "0.5",
                      Double(0, 1),
                      "The share theta of the marking (0 < theta <= 1).");
    prm.declare_entry("Coarsen fraction",
                      "0",
                      Double(0, 1),
                      "The same share for coarsening, at the small end of "
                      "the indicators; 0 = no coarsening (quadrilaterals "
                      "only: deal.II 9.4 cannot coarsen triangles).");
    prm.declare_entry("Max dofs",
                      "0",
                      Integer(0),
                      "The run ends before a mesh with more DoFs than this; "
                      "0 = no limit.");
    prm.declare_entry("Estimator",
                      "residual",
                      Selection("residual|flux"),
                      "A posteriori estimator that drives adaptive "
                      "refinement: residual, or flux (built on the flux "
                      "reconstruction t_ih; needs 'Output/Flux "
                      "reconstruction = true'). The residual estimator is "
                      "computed when Strategy = adaptive or when the exact "
                      "solution is known (for the effectivity index), the "
                      "flux estimator whenever the flux reconstruction is.");
    prm.leave_subsection();
  }

  void
  Refinement::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Refinement");
    strategy =
      (prm.get("Strategy") == "adaptive" ? RefinementStrategy::adaptive :
                                           RefinementStrategy::global);
    cycles = prm.get_integer("Cycles");
    marking =
      (prm.get("Marking") == "bulk" ? Marking::bulk : Marking::fixed_fraction);
    bulk_parameter = prm.get_double("Bulk parameter");
    if (!(bulk_parameter > 0))
      throw invalid_entry("Refinement/Bulk parameter",
                          prm.get("Bulk parameter"),
                          "the share must be in (0, 1]");
    coarsen_fraction = prm.get_double("Coarsen fraction");
    max_dofs         = prm.get_integer("Max dofs");
    estimator =
      (prm.get("Estimator") == "flux" ? Estimator::flux : Estimator::residual);
    prm.leave_subsection();
  }



  void
  Output::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Output");
    prm.declare_entry("Directory",
                      "output",
                      dealii::Patterns::DirectoryName(),
                      "Directory for report.csv and the field output; created "
                      "if missing.");
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
                      "Compute the flux reconstruction of the paper's "
                      "section 4.2: the fluxes t_ih on the sub-mesh of the "
                      "dual mesh, the defects of (4.17), (4.18) and of the "
                      "balance of Lemma 17 (report.csv), the flux "
                      "estimator, and with 'Write vtu' the dual mesh with "
                      "t_ih as dual-mesh-NN.vtu.");
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
    if (refinement.estimator == Estimator::flux && !output.flux_reconstruction)
      throw invalid_entry("Refinement/Estimator",
                          "flux",
                          "the flux estimator needs 'Output/Flux "
                          "reconstruction = true' (or use 'residual')");
  }
} // namespace membranes::Parameters
