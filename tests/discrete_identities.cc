/**
 * @file
 * The discrete identities of §3–4 of the paper on three tiny meshes, with
 * the library's own classes (DiscreteProblem, ActiveSet, ActiveSetSolver,
 * DiscreteAction, FluxReconstruction) against values computed by hand.
 *
 * <h3>The data</h3>
 * On the unit square ω = (0,1)², μ1 = 1, μ2 = 2 (μ̄ = μ1μ2/(μ1+μ2) = 2/3),
 * constant loads f1 = −2 (membrane 1 pushed down), f2 = 1 (membrane 2
 * pushed up), g = g2 = 0. Without contact u1 < 0 < u2, so the membranes
 * touch at every interior vertex: u1h = u2h = U, and U solves the Laplace
 * problem of the sum s = μ1 u1 + μ2 u2,
 *
 *   (μ1 + μ2) Σ_b A_ab U_b = (f1 + f2) d_a,   A_ab = ∫ ∇φ_a·∇φ_b,
 *
 * with d_a = ∫ φ_a (the loads are constant, so ∫ f_i φ_a = f_i d_a exactly).
 * The postprocessing (4.5) then gives, at every vertex a of V_h,
 *
 *   λ_1a d_a =  μ1 (AU)_a − f1 d_a = (μ1 f2 − μ2 f1)/(μ1+μ2) d_a,
 *   λ_2a d_a = −μ2 (AU)_a + f2 d_a = (μ1 f2 − μ2 f1)/(μ1+μ2) d_a,
 *
 * so λ_a = (μ1 f2 − μ2 f1)/(μ1 + μ2) = (1 + 4)/3 = 5/3 on every mesh (which
 * is also the exact λ of full contact): Prop. 12 (λ_1a = λ_2a) and (4.8)
 * (λ_a W_a = 0 with λ_a > 0, so W_a = u1h(a) − u2h(a) = 0) have the
 * hand-checkable values λ_a = 5/3, W_a = 0. On mesh 1 the reversed loads
 * (f1 = 2, f2 = −1) separate the membranes: λ_a = 0, W_a = 15/64 > 0, the
 * other branch of (4.8).
 *
 * <h3>Mesh 1: 2×2 squares (Q1), h = 1/2, one interior vertex a = (½,½)</h3>
 * On a square of side h the bilinear hat of a corner has ∫_K φ = h²/4 and
 * ∫_K |∇φ|² = 2/3 (independent of h in 2D). With four cells around a:
 *
 *   d_a = 4 h²/4 = 1/4,   ∫|∇φ_a|² = 4 · 2/3 = 8/3,
 *   c_a = μ̄ ∫|∇φ_a|² / d_a = (2/3)(8/3)/(1/4) = 64/9,
 *   U_a = (f1+f2) d_a / ((μ1+μ2) ∫|∇φ_a|²) = (−1)(1/4)/(3 · 8/3) = −1/32.
 *
 * Separating loads: u1(a) = f1 d_a/(μ1 · 8/3) = (1/2)/(8/3) = 3/16,
 * u2(a) = f2 d_a/(μ2 · 8/3) = (−1/4)/(16/3) = −3/64, W_a = 15/64, λ_a = 0.
 *
 * The weights of DiscreteAction::lambda(): on the zero iterate (not a
 * solution) the two formulas of (4.5) differ, λ_1a = −f1 = 2, λ_2a = f2 = 1,
 * and lambda() = (μ2 λ_1a + μ1 λ_2a)/(μ1+μ2) = (4 + 1)/3 = 5/3 (the plain
 * mean would be 3/2, the swapped weights 4/3).
 *
 * <h3>Mesh 2: mesh 1 with the cell [0,½]² refined (one level of hanging
 * nodes)</h3>
 * Vertices: a = (½,½) and b = (¼,¼) are free interior vertices; the
 * midpoints c1 = (½,¼) and c2 = (¼,½) of the edges that the refined cell
 * shares with its coarse neighbours hang, u(c_j) = ½ u(a) + ½ u(boundary
 * vertex) = ½ u(a). V_h = {a, b}. The condensed hat φ_a is the coarse hat on
 * the three coarse cells and, on the fine cells (side k = 1/4, ∫_K of a Q1
 * function = k²/4 × the sum of its corner values), the Q1 function with
 * φ_a(a) = 1, φ_a(c1) = φ_a(c2) = ½, φ_a(b) = 0:
 *
 *   d_a = 3 · (1/16) + (1/64)(1 + ½ + ½) + (1/64)(½) + (1/64)(½) = 15/64,
 *   d_b = 4 · (1/64) = 1/16.
 *
 * ∫|∇φ_a|² is, as DiscreteProblem::Vertex::stiffness_diagonal documents, Σ_K
 * A_K(a,a) over the cells with a as a vertex, without condensation: 4 · 2/3 =
 * 8/3 (the condensed hat has 2 + ½ + 1/6 + 1/6 = 17/6; see below). The same for
 * b: 8/3. So
 *
 *   c_a = (2/3)(8/3)/(15/64) = 1024/135,   c_b = (2/3)(8/3)/(1/16) = 256/9.
 *
 * The condensed stiffness on V_h: A_aa = 17/6 (coarse cells 3 · 2/3; on the
 * fine cell at a φ_a = (x+y)/2 in its reference coordinates, energy ½; on
 * the two fine cells at c1, c2 φ_a = xy/2, energy 1/6 each), A_bb = 8/3,
 * A_ab = −1/2 − 1/12 − 1/12 = −2/3. With (f1+f2)/(μ1+μ2) = −1/3:
 *
 *   [17/6 −2/3; −2/3 8/3] (U_a, U_b) = −1/3 (15/64, 1/16)
 *   ⇒ U_a = −1/32, U_b = −1/64, u(c1) = u(c2) = −1/64.
 *
 * <h3>Mesh 3: four triangles around the centre a = (½,½) (P1)</h3>
 * Each triangle K has one side of the square as its base (length 1) and a
 * as its apex (height ½), meas(K) = 1/4. On K, ∫_K φ_a = meas(K)/3 and
 * |∇φ_a| = 1/height = 2:
 *
 *   d_a = 4 · (1/4)/3 = 1/3,   ∫|∇φ_a|² = 4 · (1/4) · 4 = 4,
 *   c_a = (2/3) · 4/(1/3) = 8,   U_a = (−1)(1/3)/(3 · 4) = −1/36.
 *
 * The dual cell D_a (§4.2) consists of the sub-triangles (a, m_e, b_K) of
 * S_h, two per triangle; (4.17) says meas(K ∩ D_a) = meas(K)/3 = 1/12 =
 * ∫_K φ_a, and meas(D_a) = d_a = 1/3. (4.18) says
 *
 *   ∫_{D_a} div t_ih = μ_i ∫ ∇u_ih·∇φ_a = μ_i · 4 · U_a = −μ_i/9,
 *
 * −1/9 for membrane 1, −2/9 for membrane 2, and step 4 of Lemma 17 (the
 * loads are constant, f_ih = f_i) gives λ_a meas(D_a) = ∫_{D_a} div t_1h −
 * f1 meas(D_a) = −1/9 + 2/3 = 5/9. The measures and divergences are read
 * off the sub-triangles of FluxReconstruction::patches(), independently of
 * the library's own sums; the patches of the output hold their data as
 * float, so the checks of div t_ih allow 1e-6 (relative) instead of 1e-12.
 * FluxReconstruction::identities() reports the same identities in double
 * precision; its defects are checked at 1e-12.
 *
 * Every check prints one line PASS or FAIL with the measured and expected
 * value and the tolerance (1e-12 relative to the size of the quantity);
 * exit status 1 on any failure.
 */

#include <algorithm>
#include <array>
#include <cmath>
#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/timer.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_vector.h>
#include <functional>
#include <iomanip>
#include <iostream>
#include <map>
#include <membranes/active_set/active_set.h>
#include <membranes/active_set/active_set_solver.h>
#include <membranes/dual_mesh/discrete_action.h>
#include <membranes/flux/flux_reconstruction.h>
#include <membranes/mesh/discrete_problem.h>
#include <membranes/mesh/discretization.h>
#include <membranes/scene/parameters.h>
#include <membranes/scene/problem_data.h>
#include <string>

using namespace dealii;
using namespace membranes;

namespace
{
  constexpr int dim = 2;

  /** Relative tolerance of every check: the identities are exact. */
  constexpr double tolerance = 1e-12;

  /**
   * The same for values read from DataOutBase::Patch::data, which holds
   * them in single precision (float, ε = 6e-8): the divergences of t_ih
   * that FluxReconstruction::patches() writes for the output.
   */
  constexpr double float_tolerance = 1e-6;

  bool all_passed = true;

  /**
   * PASS if |measured − expected| ≤ tolerance · scale (scale: the size of
   * the quantity, |expected| unless that is zero).
   */
  void
  check(const std::string &what,
        const double       measured,
        const double       expected,
        const double       scale              = 0,
        const double       relative_tolerance = tolerance)
  {
    const double allowed =
      relative_tolerance * (scale > 0 ? scale : std::abs(expected));
    const bool passed = std::abs(measured - expected) <= allowed;
    all_passed &= passed;
    std::cout << (passed ? "PASS " : "FAIL ") << what << ": measured "
              << std::setprecision(16) << measured << ", expected " << expected
              << ", |difference| " << std::setprecision(3)
              << std::abs(measured - expected) << ", tolerance " << allowed
              << std::endl;
  }

  void
  check_true(const std::string &what, const bool passed)
  {
    all_passed &= passed;
    std::cout << (passed ? "PASS " : "FAIL ") << what << std::endl;
  }

  /**
   * The scene: μ1 = 1, μ2 = 2, the loads @p f1, @p f2, g = g2 = 0, the
   * expressions by the parser (no compiler at run time), exact stopping
   * with a direct solver.
   */
  Parameters::All
  scene(const Parameters::CellType cell_type,
        const std::string         &f1,
        const std::string         &f2)
  {
    ParameterHandler prm;
    Parameters::All::declare_parameters(prm);
    prm.enter_subsection("Geometry");
    prm.set("Cell type",
            cell_type == Parameters::CellType::triangle ? "triangle" :
                                                          "quadrilateral");
    prm.leave_subsection();
    prm.enter_subsection("Problem");
    prm.set("mu1", "1");
    prm.set("mu2", "2");
    prm.set("f1", f1);
    prm.set("f2", f2);
    prm.set("Expression evaluation", "parser");
    prm.leave_subsection();
    prm.enter_subsection("Solver");
    prm.set("Linear solver", "direct");
    prm.leave_subsection();
    Parameters::All parameters;
    parameters.parse_parameters(prm);
    return parameters;
  }

  /**
   * One mesh and the discrete problem on it, set up and solved with the
   * library's classes as MembraneProblem::setup_system(), solve(),
   * postprocess() and reconstruct_fluxes() do.
   */
  struct TinyProblem
  {
    TinyProblem(const Parameters::CellType                       cell_type,
                const std::function<void(Triangulation<dim> &)> &make_mesh,
                const std::string                               &f1,
                const std::string                               &f2)
      : parameters(scene(cell_type, f1, f2))
      , mpi_communicator(MPI_COMM_WORLD)
      , pcout(std::cout, false)
      , timer(pcout, TimerOutput::never, TimerOutput::wall_times)
      , data(parameters.problem, parameters.exact_solution, pcout)
      , discretization(cell_type)
      , triangulation(make_triangulation<dim>(cell_type, mpi_communicator))
      , dof_handler(*triangulation)
      , dual_mesh(discretization)
      , discrete_problem(discretization, data)
      , action(data)
      , active_set(parameters.solver, data, mpi_communicator)
      , solver(parameters.solver, data, pcout, timer, mpi_communicator)
      , flux_reconstruction(discretization, data)
    {
      make_mesh(*triangulation);
      discretization.select_mapping(*triangulation);

      dof_handler.distribute_dofs(*discretization.fe);
      owned_dofs = dof_handler.locally_owned_dofs();
      DoFTools::extract_locally_relevant_dofs(dof_handler, relevant_dofs);
      constraints.reinit(relevant_dofs);
      DoFTools::make_hanging_node_constraints(dof_handler, constraints);
      constraints.close();
      DoFTools::map_dofs_to_support_points(*discretization.mapping,
                                           dof_handler,
                                           support_points);

      dual_mesh.reinit(dof_handler);
      discrete_problem.reinit(
        dof_handler, relevant_dofs, constraints, dual_mesh, mpi_communicator);
      action.reinit(discrete_problem);
      active_set.reinit(discrete_problem);
      solver.setup(discrete_problem, dof_handler);

      solution.reinit(std::vector<IndexSet>(2, owned_dofs), mpi_communicator);
      ghosted_solution.reinit(std::vector<IndexSet>(2, owned_dofs),
                              std::vector<IndexSet>(2, relevant_dofs),
                              mpi_communicator);
      lambda_h.reinit(owned_dofs, relevant_dofs, mpi_communicator);
    }

    /** The active set method from the zero initial guess, then λ_h. */
    void
    solve()
    {
      solver.solve(discrete_problem, action, solution, active_set);
      ghosted_solution = solution;
      lambda_h         = action.lambda_h(discrete_problem, constraints);
    }

    /** The index in vertices() of the vertex of V_h at @p p. */
    unsigned int
    vertex_at(const Point<dim> &p) const
    {
      const auto &vertices = discrete_problem.vertices();
      for (unsigned int k = 0; k < vertices.size(); ++k)
        if (support_points.at(vertices[k].dof).distance(p) < 1e-12)
          return k;
      throw std::runtime_error("no vertex of V_h at the point");
    }

    /** The DoF of the (possibly hanging) vertex at @p p. */
    types::global_dof_index
    dof_at(const Point<dim> &p) const
    {
      for (const auto &cell : dof_handler.active_cell_iterators())
        for (const unsigned int v : cell->vertex_indices())
          if (cell->vertex(v).distance(p) < 1e-12)
            return cell->vertex_dof_index(v, 0);
      throw std::runtime_error("no vertex at the point");
    }

    using VectorType      = TrilinosWrappers::MPI::Vector;
    using BlockVectorType = TrilinosWrappers::MPI::BlockVector;

    const Parameters::All                         parameters;
    const MPI_Comm                                mpi_communicator;
    ConditionalOStream                            pcout;
    TimerOutput                                   timer;
    const ProblemData<dim>                        data;
    Discretization<dim>                           discretization;
    const std::unique_ptr<Triangulation<dim>>     triangulation;
    DoFHandler<dim>                               dof_handler;
    IndexSet                                      owned_dofs, relevant_dofs;
    AffineConstraints<double>                     constraints;
    std::map<types::global_dof_index, Point<dim>> support_points;
    DualMesh<dim>                                 dual_mesh;
    DiscreteProblem<dim>                          discrete_problem;
    DiscreteAction<dim>                           action;
    ActiveSet<dim>                                active_set;
    ActiveSetSolver<dim>                          solver;
    FluxReconstruction<dim>                       flux_reconstruction;
    BlockVectorType                               solution, ghosted_solution;
    VectorType                                    lambda_h;
  };

  /** The contact loads and the separating ones. */
  const std::string f1_contact = "-2", f2_contact = "1";
  const std::string f1_apart = "2", f2_apart = "-1";

  /** λ_a = (μ1 f2 − μ2 f1)/(μ1+μ2) of full contact. */
  constexpr double lambda_contact = 5. / 3.;

  /**
   * Prop. 12 and (4.8) at the vertex k of @p problem, whose solution has
   * the hand values @p u (both membranes, in contact) and λ_a =
   * lambda_contact.
   */
  void
  check_contact_vertex(const TinyProblem &problem,
                       const unsigned int k,
                       const std::string &name,
                       const double       u)
  {
    const auto &a      = problem.discrete_problem.vertices()[k];
    const auto &action = problem.action;
    // A wrong operator, load or solve (or boundary value) moves u_ih(a).
    check(name + ": u1h at the vertex",
          problem.ghosted_solution.block(0)[a.dof],
          u);
    check(name + ": u2h at the vertex",
          problem.ghosted_solution.block(1)[a.dof],
          u);
    // λ_a of membrane 1 by (4.5): a wrong d_a, sign or load term moves it.
    check(name + ": lambda_1a of (4.5)",
          action.lambda_from_membrane(0, k),
          lambda_contact);
    // λ_a of membrane 2 by (4.5): the same faults, with the sign of μ2's.
    check(name + ": lambda_2a of (4.5)",
          action.lambda_from_membrane(1, k),
          lambda_contact);
    // Prop. 12: the two formulas agree; fails if one membrane's term is off.
    check(name + ": Prop. 12, (lambda_1a - lambda_2a) d_a",
          (action.lambda_from_membrane(0, k) -
           action.lambda_from_membrane(1, k)) *
            a.dual_cell_measure,
          0,
          lambda_contact * a.dual_cell_measure);
    // λ_a of the active set method: a wrong combination of the two formulas.
    check(name + ": lambda_a = DiscreteAction::lambda()",
          action.lambda(k),
          lambda_contact);
    // (4.8) with λ_a > 0: fails if the contact constraint u1h(a) = u2h(a)
    // is not imposed (or the vertex is left inactive) where λ_a > 0.
    check_true(name + ": the vertex is active",
               problem.active_set.is_active(k));
    check(name + ": (4.8) lambda_a (u1h - u2h)(a)",
          action.lambda(k) *
            problem.discrete_problem.nodal_w(k, problem.solution),
          0,
          lambda_contact * std::abs(u));
  }



  /**
   * d_a, ∫|∇φ_a|² (as DiscreteProblem sums it) and c_a at the vertex @p a of
   * @p problem against the hand values. A scaled or unlumped mass moves
   * d_a; a wrong stiffness diagonal ∫|∇φ_a|²; μ1 or μ2 in place of μ̄, or
   * a wrong d_a, moves c_a = μ̄ ∫|∇φ_a|² / d_a.
   */
  void
  check_vertex_data(const TinyProblem                  &problem,
                    const DiscreteProblem<dim>::Vertex &a,
                    const std::string                  &name,
                    const double                        d_a,
                    const double                        stiffness,
                    const double                        c_a)
  {
    check(name + ": d_a = int phi_a", a.dual_cell_measure, d_a);
    check(name + ": int |grad phi_a|^2", a.stiffness_diagonal, stiffness);
    check(name + ": c_a = mu_bar int|grad phi_a|^2 / d_a",
          problem.active_set.contact_stiffness(a),
          c_a);
  }



  /** Mesh 1: 2×2 squares. */
  void
  two_by_two()
  {
    std::cout << "Mesh 1: 2x2 squares (Q1) of the unit square" << std::endl;
    const auto make_mesh = [](Triangulation<dim> &triangulation) {
      GridGenerator::subdivided_hyper_cube(triangulation, 2, 0., 1.);
    };
    TinyProblem problem(Parameters::CellType::quadrilateral,
                        make_mesh,
                        f1_contact,
                        f2_contact);
    const auto &vertices = problem.discrete_problem.vertices();
    // V_h: a boundary vertex counted as interior, or a missing vertex.
    check("Q1 2x2: |V_h| (one interior vertex)", vertices.size(), 1);
    const unsigned int k = problem.vertex_at(Point<dim>(0.5, 0.5));
    const auto        &a = vertices[k];

    // d_a = h² = 1/4, ∫|∇φ_a|² = 4 · 2/3, c_a = μ̄ (8/3)/(1/4) = 64/9.
    check_vertex_data(problem, a, "Q1 2x2", 1. / 4., 8. / 3., 64. / 9.);

    // The weights of lambda() on the zero iterate, where the two formulas
    // of (4.5) differ (λ_1a = 2, λ_2a = 1): swapped weights give 4/3.
    problem.action.compute(problem.discrete_problem, problem.solution);
    check("Q1 2x2, zero iterate: lambda_1a = -f1",
          problem.action.lambda_from_membrane(0, k),
          2.);
    check("Q1 2x2, zero iterate: lambda_2a = f2",
          problem.action.lambda_from_membrane(1, k),
          1.);
    check("Q1 2x2, zero iterate: lambda() = (mu2 l1 + mu1 l2)/(mu1+mu2)",
          problem.action.lambda(k),
          5. / 3.);

    problem.solve();
    check_contact_vertex(problem, k, "Q1 2x2, contact", -1. / 32.);

    // The other branch of (4.8): separating loads, a inactive, λ_a = 0.
    TinyProblem apart(Parameters::CellType::quadrilateral,
                      make_mesh,
                      f1_apart,
                      f2_apart);
    apart.solve();
    const unsigned int ka = apart.vertex_at(Point<dim>(0.5, 0.5));
    const auto        &b  = apart.discrete_problem.vertices()[ka];
    // A vertex kept in contact where the membranes separate.
    check_true("Q1 2x2, apart: vertex a is inactive",
               !apart.active_set.is_active(ka));
    check("Q1 2x2, apart: u1h(a)",
          apart.ghosted_solution.block(0)[b.dof],
          3. / 16.);
    check("Q1 2x2, apart: u2h(a)",
          apart.ghosted_solution.block(1)[b.dof],
          -3. / 64.);
    // λ_a = 0 off contact, from both formulas (the scale: f1 = 2).
    check("Q1 2x2, apart: lambda_1a of (4.5)",
          apart.action.lambda_from_membrane(0, ka),
          0,
          2.);
    check("Q1 2x2, apart: lambda_2a of (4.5)",
          apart.action.lambda_from_membrane(1, ka),
          0,
          2.);
    check("Q1 2x2, apart: (4.8) lambda_a (u1h - u2h)(a)",
          apart.action.lambda(ka) *
            apart.discrete_problem.nodal_w(ka, apart.solution),
          0,
          2. * 15. / 64.);
  }



  /** Mesh 2: 2×2 squares with the cell [0,½]² refined once. */
  void
  hanging_node()
  {
    std::cout << "Mesh 2: 2x2 squares (Q1), the cell [0,1/2]^2 refined"
              << std::endl;
    TinyProblem problem(
      Parameters::CellType::quadrilateral,
      [](Triangulation<dim> &triangulation) {
        GridGenerator::subdivided_hyper_cube(triangulation, 2, 0., 1.);
        for (const auto &cell : triangulation.active_cell_iterators())
          if (cell->center().distance(Point<dim>(0.25, 0.25)) < 1e-12)
            cell->set_refine_flag();
        triangulation.execute_coarsening_and_refinement();
      },
      f1_contact,
      f2_contact);
    const auto &vertices = problem.discrete_problem.vertices();
    // V_h = {a, b}: a hanging vertex taken into V_h.
    check("Q1 hanging: |V_h| (hanging vertices excluded)", vertices.size(), 2);
    const unsigned int ka = problem.vertex_at(Point<dim>(0.5, 0.5));
    const unsigned int kb = problem.vertex_at(Point<dim>(0.25, 0.25));
    const auto        &a  = vertices[ka];
    const auto        &b  = vertices[kb];

    // d_a = 15/64 with the shares ½ ∫ φ_c of the hanging vertices (without
    // condensation it would be 13/64); ∫|∇φ_a|² as Σ_K A_K(a,a), uncondensed
    // as documented: 4 · 2/3.
    check_vertex_data(
      problem, a, "Q1 hanging, vertex a", 15. / 64., 8. / 3., 1024. / 135.);
    // d_b = 4 (1/4)²/4 = 1/16: the fine cells' measure.
    check_vertex_data(
      problem, b, "Q1 hanging, vertex b", 1. / 16., 8. / 3., 256. / 9.);

    problem.solve();
    check_contact_vertex(problem, ka, "Q1 hanging, vertex a", -1. / 32.);
    check_contact_vertex(problem, kb, "Q1 hanging, vertex b", -1. / 64.);
    // The hanging vertex c1 = (½,¼) follows its parents: u = ½ U_a.
    const auto c1 = problem.dof_at(Point<dim>(0.5, 0.25));
    check_true("Q1 hanging: c1 = (1/2,1/4) is constrained",
               problem.constraints.is_constrained(c1));
    check("Q1 hanging: u1h(c1) = u1h(a)/2",
          problem.ghosted_solution.block(0)[c1],
          -1. / 64.);
  }



  /**
   * The pieces K ∩ D_a of the dual cell of the vertex at @p a, read off
   * the sub-triangles of S_h that FluxReconstruction::patches() gives for
   * the output, independently of the library's own sums: meas(K ∩ D_a)
   * for each cell K, meas(D_a) and ∫_{D_a} div t_ih, i = 1, 2.
   */
  struct DualCellPieces
  {
    unsigned int          sub_triangles_per_cell;
    std::vector<double>   cell_measure;
    double                measure    = 0;
    std::array<double, 2> divergence = {{0, 0}};
  };

  DualCellPieces
  dual_cell_pieces(TinyProblem &problem, const Point<dim> &a)
  {
    problem.flux_reconstruction.reconstruct(problem.dof_handler,
                                            problem.ghosted_solution);
    unsigned int a_vertex = numbers::invalid_unsigned_int;
    for (unsigned int v = 0; v < problem.triangulation->n_vertices(); ++v)
      if (problem.triangulation->get_vertices()[v].distance(a) < 1e-12)
        a_vertex = v;
    const auto patches =
      problem.flux_reconstruction.patches(problem.dof_handler,
                                          problem.dual_mesh,
                                          problem.lambda_h);
    const auto names  = FluxReconstruction<dim>::data_names();
    const auto column = [&](const std::string &name) {
      return std::find(names.begin(), names.end(), name) - names.begin();
    };
    DualCellPieces pieces;
    pieces.sub_triangles_per_cell =
      patches.size() / problem.triangulation->n_active_cells();
    pieces.cell_measure.resize(problem.triangulation->n_active_cells());
    for (unsigned int p = 0; p < patches.size(); ++p)
      {
        const auto &patch = patches[p];
        if (std::lround(patch.data(column("dual_vertex"), 0)) != a_vertex)
          continue;
        const Tensor<1, dim> e1   = patch.vertices[1] - patch.vertices[0];
        const Tensor<1, dim> e2   = patch.vertices[2] - patch.vertices[0];
        const double         area = std::abs(e1[0] * e2[1] - e1[1] * e2[0]) / 2;
        pieces.cell_measure[p / pieces.sub_triangles_per_cell] += area;
        pieces.measure += area;
        pieces.divergence[0] += patch.data(column("div_t1"), 0) * area;
        pieces.divergence[1] += patch.data(column("div_t2"), 0) * area;
      }
    return pieces;
  }



  /**
   * Mesh 3, the dual cell D_a of its vertex k (at the centre), from the
   * sub-triangles of S_h: (4.17), (4.18) and step 4 of Lemma 17.
   */
  void
  check_four_triangles_dual_cell(TinyProblem &problem, const unsigned int k)
  {
    const DualCellPieces pieces =
      dual_cell_pieces(problem, Point<dim>(0.5, 0.5));
    check_true("P1 4 triangles: S_h has two sub-triangles per vertex of K",
               pieces.sub_triangles_per_cell == 6);
    // (4.17): meas(K ∩ D_a) = meas(K)/3 on every K: a misplaced barycentre
    // or midpoint in the dual mesh.
    for (unsigned int c = 0; c < pieces.cell_measure.size(); ++c)
      check("P1 4 triangles: (4.17) meas(K" + std::to_string(c) +
              " cap D_a) = meas(K)/3",
            pieces.cell_measure[c],
            1. / 12.);
    // (4.17) summed: meas(D_a) = d_a = 1/3.
    check("P1 4 triangles: (4.17) meas(D_a) = d_a", pieces.measure, 1. / 3.);
    check("P1 4 triangles: (4.17) meas(D_a) = library's d_a",
          pieces.measure,
          problem.discrete_problem.vertices()[k].dual_cell_measure);
    // (4.18): the fluxes (4.13) through ∂D_a, i.e. t_ih · n = −μ_i ∂_n u_ih.
    for (unsigned int i = 0; i < 2; ++i)
      check("P1 4 triangles: (4.18) int_{D_a} div t_" + std::to_string(i + 1) +
              "h = mu_" + std::to_string(i + 1) + " int grad u_ih . grad phi_a",
            pieces.divergence[i],
            -(i + 1.) / 9.,
            (i + 1.) / 9.,
            float_tolerance);
    // Lemma 17, step 4: λ_a meas(D_a) = ∫_{D_a} (div t_1h − f_1h) = 5/9.
    check("P1 4 triangles: Lemma 17 lambda_a meas(D_a) = int_{D_a} (div t_1h "
          "- f_1h)",
          pieces.divergence[0] + 2. * pieces.measure,
          5. / 9.,
          5. / 9.,
          float_tolerance);
    check("P1 4 triangles: lambda_a meas(D_a) from the action",
          problem.action.lambda(k) * pieces.measure,
          5. / 9.);
  }



  /**
   * The library's own report of the identities of mesh 3, in double
   * precision: a fault in its sums over the pieces K ∩ D_a (or in t_ih on
   * a half-edge inside D_a that the float checks of the pieces would miss).
   */
  void
  check_four_triangles_identities(const TinyProblem &problem)
  {
    const auto identities =
      problem.flux_reconstruction.identities(problem.dof_handler,
                                             problem.constraints,
                                             problem.discrete_problem,
                                             problem.action);
    check("P1 4 triangles: identities().measure_defect",
          identities.measure_defect,
          0,
          1.);
    check("P1 4 triangles: identities().conservation_defect",
          identities.conservation_defect,
          0,
          1.);
    check("P1 4 triangles: identities().balance_defect",
          identities.balance_defect,
          0,
          1.);
  }



  /** Mesh 3: four triangles around the centre of the unit square. */
  void
  four_triangles()
  {
    std::cout << "Mesh 3: four triangles (P1) around the centre" << std::endl;
    TinyProblem problem(
      Parameters::CellType::triangle,
      [](Triangulation<dim> &triangulation) {
        const std::vector<Point<dim>> points = {
          {0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5, 0.5}};
        const unsigned int         corners[4][3] = {{0, 1, 4},
                                                    {1, 2, 4},
                                                    {2, 3, 4},
                                                    {3, 0, 4}};
        std::vector<CellData<dim>> cells;
        for (const auto &c : corners)
          {
            CellData<dim> cell(3);
            cell.vertices = {c[0], c[1], c[2]};
            cells.push_back(cell);
          }
        triangulation.create_triangulation(points, cells, SubCellData());
      },
      f1_contact,
      f2_contact);
    const auto &vertices = problem.discrete_problem.vertices();
    check("P1 4 triangles: |V_h|", vertices.size(), 1);
    const unsigned int k = problem.vertex_at(Point<dim>(0.5, 0.5));
    const auto        &a = vertices[k];

    // d_a = Σ_K meas(K)/3 = 1/3, ∫|∇φ_a|² = 4 triangles · area 1/4 ·
    // |∇φ_a|² = 4, c_a = μ̄ · 4/(1/3) = 8.
    check_vertex_data(problem, a, "P1 4 triangles", 1. / 3., 4., 8.);

    problem.solve();
    check_contact_vertex(problem, k, "P1 4 triangles, contact", -1. / 36.);

    // μ_i ∫ ∇u_ih·∇φ_a = μ_i · 4 · (−1/36) = −μ_i/9, the library's
    // stiffness terms of (4.5): a wrong operator.
    for (unsigned int i = 0; i < 2; ++i)
      check("P1 4 triangles: mu_" + std::to_string(i + 1) + " int grad u_" +
              std::to_string(i + 1) + "h . grad phi_a",
            problem.action.stiffness_term(problem.discrete_problem, i, k),
            -(i + 1.) / 9.);

    check_four_triangles_dual_cell(problem, k);
    check_four_triangles_identities(problem);
  }
} // namespace



int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi_initialization(argc, argv, 1);
  // Each mesh on its own: an exception (e.g. an active set method that does
  // not converge) fails its mesh and leaves the others to run.
  for (const auto &mesh : {two_by_two, hanging_node, four_triangles})
    try
      {
        mesh();
      }
    catch (const std::exception &error)
      {
        all_passed = false;
        std::cout << "FAIL exception: " << Parameters::one_line_message(error)
                  << std::endl;
      }
  std::cout << (all_passed ? "All checks passed." : "Some checks FAILED.")
            << std::endl;
  return all_passed ? 0 : 1;
}
