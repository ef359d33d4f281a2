#ifndef membranes_problem_data_h
#define membranes_problem_data_h

#include <array>
#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/function.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/grid/tria.h>
#include <membranes/scene/compiled_function.h>
#include <membranes/scene/parameters.h>
#include <memory>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The data of problem (1.1): tensions μ1, μ2, loads f1, f2, boundary
   * heights g (membrane 1) and g2 (membrane 2, 0 in the paper), and, when
   * known, the exact solution (u1, u2, λ).
   *
   * Every function is an expression in x, y in the syntax of deal.II's
   * FunctionParser, with the scene's `Function constants` and the names
   * `mu1`, `mu2`, `pi`, so that a manufactured solution written in terms of
   * the tensions stays exact for any μ1, μ2. The expressions are compiled
   * to machine code (CompiledFunctions) unless `Problem/Expression
   * evaluation = parser`, or `auto` finds no working compiler; otherwise
   * they are evaluated by muparser directly, set up as FunctionParser sets
   * it up (the same values to the last bit), one set of parsers per thread,
   * looked up once per list of points (a cell's quadrature points), not, as
   * FunctionParser does, on every evaluation. Every value is
   * checked where the program evaluates it: one that is not finite, or
   * larger than Parameters::max_magnitude in magnitude, is an InputError
   * naming the entry and the point.
   *
   * The gradients of the exact displacements (for the H1 errors) are, when
   * compiled, those of forward-mode dual numbers (exact); the scene's
   * `Exact solution/u1 gradient` and `u2 gradient` (two expressions
   * `∂/∂x; ∂/∂y`), when given, are then checked against them. With the
   * parser they are those entries when given, otherwise central
   * (second-order) finite differences of u1 and u2, with a step set by
   * set_gradient_step().
   *
   * With `Exact solution/Manufactured data` the loads are f1 = −μ1Δu1 − λ
   * and f2 = −μ2Δu2 + λ, their Laplacians by second-order dual numbers,
   * and g = u1, g2 = u2.
   */
  template <int dim>
  class ProblemData
  {
  public:
    /**
     * The data of the scene. With `Problem/Expression evaluation = auto` and
     * no working compiler, a one-line note on @p pcout says so.
     */
    ProblemData(const Parameters::Problem       &problem,
                const Parameters::ExactSolution &exact,
                const ConditionalOStream        &pcout);

    ~ProblemData();

    /** The loads at a list of points. */
    struct LoadValues
    {
      /** f_i at each point (i = 0 or 1 for membranes 1 and 2). */
      std::array<std::vector<double>, 2> f;
      /** The compiled group's values, kept between calls. */
      std::vector<double> group_values;
    };

    /**
     * The loads f1, f2 at @p points, into @p values (resized to them).
     * With compiled expressions one call evaluates both together at all
     * points (with manufactured data, the Laplacians of u1 and u2 and λ
     * they are made of).
     */
    void
    load_list(const std::vector<Point<dim>> &points, LoadValues &values) const;

    /**
     * The boundary values as one function with two components (g, g2):
     * component i is the boundary value of membrane i.
     */
    const Function<dim> &
    boundary_values() const;

    /**
     * Check g ≥ 0 and g − g2 ≥ 0 at points along every boundary face of
     * @p triangulation; an InputError naming `Problem/g` or `Problem/g2`
     * otherwise.
     */
    void
    check_boundary_data(const Triangulation<dim> &triangulation) const;

    /**
     * Evaluate the exact solution (u1, u2, their gradients, λ), when it is
     * known, at the points of @p quadrature on every locally owned cell of
     * @p triangulation (mapped by @p mapping): an expression that is not
     * finite there is an InputError before anything is computed, not after
     * the first solve, where the error norms first evaluate it.
     */
    void
    check_exact_solution(const Triangulation<dim> &triangulation,
                         const Mapping<dim>       &mapping,
                         const Quadrature<dim>    &quadrature) const;

    /**
     * Set the step of the finite differences that give the gradients of the
     * exact displacements (those without a gradient entry in the scene).
     * The error norms set it relative to the cell they integrate over, so
     * that the difference stencil never leaves the neighbourhood of the
     * cell, however fine the mesh (near a re-entrant corner, a fixed step
     * would reach across the corner). The step holds for the calling
     * thread: each thread of a loop over cells sets its own.
     */
    void
    set_gradient_step(const double step) const;

    /** The exact solution at a list of points. */
    struct ExactValues
    {
      /** u_i at each point (i = 0 or 1 for membranes 1 and 2). */
      std::array<std::vector<double>, 2> u;
      /** ∇u_i at each point. */
      std::array<std::vector<Tensor<1, dim>>, 2> grad_u;
      /** λ at each point. */
      std::vector<double> lambda;
      /** The compiled group's values, kept between calls. */
      std::vector<double> group_values;
    };

    /**
     * The exact solution u1, u2, their gradients and λ at @p points, into
     * @p values (resized to them); only when known. With compiled
     * expressions one call evaluates all of them together at all points
     * (CompiledFunctions::Group), so that what u1 and u2 share (u1 = u2 +
     * a gap, say) is computed once.
     */
    void
    exact_solution_list(const std::vector<Point<dim>> &points,
                        ExactValues                   &values) const;

    /**
     * The exact λ alone at @p points, into @p values (resized to them);
     * only when known. For points where λ is wanted and u may be singular
     * (on the edges and at the vertices of the mesh: the slit, a re-entrant
     * corner).
     */
    void
    exact_action_list(const std::vector<Point<dim>> &points,
                      std::vector<double>           &values) const;

    /** μ1 and μ2 as `mu[0]`, `mu[1]`. */
    const std::array<double, 2> mu;

    /** μ̄ = μ1 μ2 / (μ1 + μ2), the tension of the obstacle problem for w. */
    const double mu_bar;

    /** Whether the exact solution is known (`Exact solution/Known`). */
    const bool exact_solution_known;

  private:
    class Expression;

    /** The expressions of the scene, and what compiling them asks for. */
    using Scene =
      std::vector<std::pair<Expression *, CompiledFunctions::Request>>;

    void
    compile(const Scene &scene, const std::map<std::string, double> &constants);

    void
    manufacture(const Scene &scene);

    std::unique_ptr<CompiledFunctions> compiled;

    /**
     * The compiled group of u1 and u2 (each value and gradient) and λ, when
     * the exact solution is known and compiled.
     */
    CompiledFunctions::GroupValues exact_group = nullptr;

    /**
     * The compiled group of the loads: f1 and f2, or with manufactured data
     * u1 and u2 (each value and Laplacian) and λ.
     */
    CompiledFunctions::GroupValues loads_group = nullptr;

    std::array<std::unique_ptr<Expression>, 2> f;
    std::unique_ptr<Expression>                g;
    std::unique_ptr<Expression>                g2;
    std::unique_ptr<Function<dim>>             g_and_g2;

    const bool                                 manufactured;
    std::array<std::unique_ptr<Expression>, 2> exact_u;
    std::unique_ptr<Expression>                exact_action;
  };
} // namespace membranes

#endif
