#include <algorithm>
#include <cmath>
#include <deal.II/base/auto_derivative_function.h>
#include <deal.II/base/function_parser.h>
#include <deal.II/base/thread_local_storage.h>
#include <deal.II/base/utilities.h>
#include <deal.II/grid/manifold.h>
#include <functional>
#include <membranes/scene/compiled_function.h>
#include <membranes/scene/expression_entry.h>
#include <membranes/scene/problem_data.h>
#include <muParser.h>
#include <regex>
#include <sstream>
#include <tuple>

namespace membranes
{
  namespace
  {
    /**
     * The constants of every expression: the scene's `Function constants`
     * (`name=value` pairs separated by commas), and mu1, mu2 and pi.
     */
    std::map<std::string, double>
    parse_constants(const Parameters::Problem &problem)
    {
      std::map<std::string, double> constants{{"mu1", problem.mu1},
                                              {"mu2", problem.mu2},
                                              {"pi", numbers::PI}};
      for (const std::string &pair :
           Utilities::split_string_list(problem.function_constants, ','))
        {
          const auto name_value = Utilities::split_string_list(pair, '=');
          double     value      = 0;
          // A name as muparser takes it, other than a variable (muparser
          // aborts the program on those).
          bool ok = name_value.size() == 2 &&
                    std::regex_match(name_value[0],
                                     std::regex("[A-Za-z][A-Za-z0-9_]*")) &&
                    name_value[0] != "x" && name_value[0] != "y";
          if (ok)
            {
              std::istringstream in(name_value[1]);
              ok = static_cast<bool>(in >> value) && in.eof() &&
                   std::isfinite(value);
            }
          if (!ok)
            throw Parameters::invalid_entry(
              "Problem/Function constants",
              problem.function_constants,
              "expected comma separated name=value pairs: names of letters, "
              "digits and '_' other than x and y, finite values");
          constants[name_value[0]] = value;
        }
      return constants;
    }


    /** The position of @p expression among the expressions of @p scene. */
    template <typename Scene, typename Expression>
    unsigned int
    position(const Scene &scene, const Expression *expression)
    {
      return static_cast<unsigned int>(
        std::find_if(scene.begin(),
                     scene.end(),
                     [&](const auto &e) { return e.first == expression; }) -
        scene.begin());
    }


    /**
     * The manufactured load of membrane @p i (0 or 1) of tension @p mu from
     * its Laplacian Δu_i and λ: f1 = −μ1Δu1 − λ, f2 = −μ2Δu2 + λ.
     */
    double
    manufactured_load(const unsigned int i,
                      const double       mu,
                      const double       laplacian,
                      const double       lambda)
    {
      return -mu * laplacian + (i == 0 ? -1. : 1.) * lambda;
    }
  } // namespace



  /**
   * The function of one expression of the scene, evaluated and checked as
   * the class comment of ProblemData says. All uses of the data go through
   * here, on every mesh, so that a NaN or an infinity never enters a
   * computation unnoticed, wherever the expression produces it. An
   * expression that is only derived (the manufactured loads) has compiled
   * values only.
   *
   * The loops over cells run on several threads (WorkStream). Compiled
   * code has no state; a muparser object evaluates at the point its
   * variables are bound to: so every thread has its own parsers and point,
   * made on its first evaluation.
   */
  template <int dim>
  class ProblemData<dim>::Expression : public Function<dim>,
                                       public ExpressionEntry<dim>
  {
  public:
    /**
     * The expression @p expression of entry @p entry, and, if
     * @p gradient_expression is not empty, its gradient from entry
     * @p gradient_entry. They are parsed here, so that a syntax error is an
     * InputError on construction.
     */
    Expression(const std::string                   &entry,
               const std::string                   &expression,
               const std::map<std::string, double> &constants,
               const std::string                   &gradient_entry      = "",
               const std::string                   &gradient_expression = "")
      : ExpressionEntry<dim>(entry, expression)
      , constants(constants)
      , gradient_entry(gradient_entry)
      , gradient_expression(gradient_expression)
    {
      parsers();
    }

    /**
     * An expression derived from others, described by @p description in
     * the messages about entry @p entry, with the values @p compiled_value.
     */
    Expression(const std::string                              &entry,
               const std::string                              &description,
               const std::function<double(const Point<dim> &)> compiled_value)
      : ExpressionEntry<dim>(entry, description)
      , compiled_value(compiled_value)
    {}

    /**
     * Evaluate by @p value and, if not empty, the gradient by @p gradient
     * from now on.
     */
    void
    use_compiled(
      const std::function<double(const Point<dim> &)>         &value,
      const std::function<Tensor<1, dim>(const Point<dim> &)> &gradient)
    {
      compiled_value    = value;
      compiled_gradient = gradient;
    }

    double
    value(const Point<dim> &p, const unsigned int = 0) const override
    {
      const double result =
        compiled_value ? compiled_value(p) : parsers().value(p);
      this->check(result, p);
      return result;
    }

    void
    value_list(const std::vector<Point<dim>> &points,
               std::vector<double>           &values,
               const unsigned int = 0) const override
    {
      const ThreadParsers *local = compiled_value ? nullptr : &parsers();
      for (unsigned int q = 0; q < points.size(); ++q)
        {
          values[q] =
            local ? local->value(points[q]) : compiled_value(points[q]);
          this->check(values[q], points[q]);
        }
    }

    Tensor<1, dim>
    gradient(const Point<dim> &p, const unsigned int = 0) const override
    {
      if (!compiled_gradient)
        return parsers().gradient(p);
      const Tensor<1, dim> result = compiled_gradient(p);
      this->check(result, p);
      return result;
    }

    void
    gradient_list(const std::vector<Point<dim>> &points,
                  std::vector<Tensor<1, dim>>   &gradients,
                  const unsigned int = 0) const override
    {
      if (compiled_gradient)
        for (unsigned int q = 0; q < points.size(); ++q)
          {
            gradients[q] = compiled_gradient(points[q]);
            this->check(gradients[q], points[q]);
          }
      else
        {
          const ThreadParsers &local = parsers();
          for (unsigned int q = 0; q < points.size(); ++q)
            gradients[q] = local.gradient(points[q]);
        }
    }

    /**
     * With a compiled gradient (that of the dual numbers), a gradient entry
     * of the scene is a check of the user's own derivatives: at @p p it
     * must agree with them to 1e-8 relative to the larger of the two, or to
     * 1e-8 where both are below 1.
     */
    void
    check_gradient_entry(const Point<dim> &p) const
    {
      if (!compiled_gradient || Utilities::trim(gradient_expression).empty())
        return;
      const Tensor<1, dim> entry      = parsers().gradient(p);
      const Tensor<1, dim> derivative = gradient(p);
      const double scale = std::max({1., entry.norm(), derivative.norm()});
      if (!((entry - derivative).norm() <= 1e-8 * scale))
        {
          std::ostringstream allowed;
          allowed << "at " << point_text(p) << " it is (" << entry
                  << ") but the derivative of the exact solution is ("
                  << derivative << ")";
          throw Parameters::invalid_entry(gradient_entry,
                                          gradient_expression,
                                          allowed.str());
        }
    }

    /**
     * The step of the finite differences that give gradient(), on the
     * calling thread (without a compiled gradient).
     */
    void
    set_gradient_step(const double step) const
    {
      if (!compiled_gradient)
        parsers().set_h(step);
    }

  private:
    /**
     * The parsers of one thread, bound to that thread's point. Without a
     * gradient entry, the gradient is deal.II's central differences
     * (AutoDerivativeFunction, formula Euler) of value(), with the step of
     * set_gradient_step() on this thread.
     */
    struct ThreadParsers : public AutoDerivativeFunction<dim>
    {
      explicit ThreadParsers(const Expression &e)
        : AutoDerivativeFunction<dim>(1e-5)
        , function(e.entry, e.text, 1, e.constants, point)
      {
        if (!Utilities::trim(e.gradient_expression).empty())
          exact_gradient = std::make_unique<ParsedExpressionEntry<dim>>(
            e.gradient_entry, e.gradient_expression, dim, e.constants, point);
      }

      /** The parsers hold the address of #point. */
      ThreadParsers(const ThreadParsers &) = delete;

      /** The value at @p p, unchecked (Expression checks it). */
      double
      value(const Point<dim> &p, const unsigned int = 0) const override
      {
        point = p;
        return function.evaluate(0);
      }

      Tensor<1, dim>
      gradient(const Point<dim> &p, const unsigned int = 0) const override
      {
        if (!exact_gradient)
          {
            const Tensor<1, dim> gradient =
              AutoDerivativeFunction<dim>::gradient(p);
            for (unsigned int d = 0; d < dim; ++d)
              function.check(gradient[d],
                             p,
                             "gradient (by finite differences)");
            return gradient;
          }
        Tensor<1, dim> gradient;
        point = p;
        for (unsigned int d = 0; d < dim; ++d)
          gradient[d] = exact_gradient->evaluate(d);
        exact_gradient->check(gradient, p);
        return gradient;
      }

      /** The variables x, y of every expression. */
      mutable Point<dim> point;

      ParsedExpressionEntry<dim>                  function;
      std::unique_ptr<ParsedExpressionEntry<dim>> exact_gradient;
    };

    /** The parsers of the calling thread, made on its first call. */
    ThreadParsers &
    parsers() const
    {
      std::shared_ptr<ThreadParsers> &local = thread_parsers.get();
      if (!local)
        local = std::make_shared<ThreadParsers>(*this);
      return *local;
    }

    const std::map<std::string, double> constants;
    const std::string                   gradient_entry, gradient_expression;
    mutable Threads::ThreadLocalStorage<std::shared_ptr<ThreadParsers>>
      thread_parsers;

    std::function<double(const Point<dim> &)>         compiled_value;
    std::function<Tensor<1, dim>(const Point<dim> &)> compiled_gradient;
  };



  template <int dim>
  ProblemData<dim>::ProblemData(const Parameters::Problem       &problem,
                                const Parameters::ExactSolution &exact,
                                const ConditionalOStream        &pcout)
    : mu{{problem.mu1, problem.mu2}}
    , mu_bar(problem.mu1 * problem.mu2 / (problem.mu1 + problem.mu2))
    , exact_solution_known(exact.known)
    , manufactured(exact.manufactured)
  {
    const auto constants = parse_constants(problem);
    // Each expression parsed (a syntax error is an InputError here, with
    // muparser's message, however they are then evaluated).
    Scene      scene;
    const auto add = [&](std::unique_ptr<Expression> &expression,
                         const std::string           &entry,
                         const std::string           &text,
                         const bool                   gradient,
                         const bool                   laplacian,
                         const std::string           &gradient_entry = "",
                         const std::string           &gradient_text  = "") {
      expression = std::make_unique<Expression>(
        entry, text, constants, gradient_entry, gradient_text);
      scene.emplace_back(expression.get(),
                         CompiledFunctions::Request{text, gradient, laplacian});
    };
    if (!exact.manufactured)
      {
        add(f[0], "Problem/f1", problem.f1, false, false);
        add(f[1], "Problem/f2", problem.f2, false, false);
        add(g, "Problem/g", problem.g, false, false);
        add(g2, "Problem/g2", problem.g2, false, false);
      }
    if (exact_solution_known || exact.manufactured)
      {
        const std::array<std::string, 2> u{{exact.u1, exact.u2}};
        const std::array<std::string, 2> gradient{
          {exact.u1_gradient, exact.u2_gradient}};
        for (unsigned int i = 0; i < 2; ++i)
          {
            const std::string entry =
              "Exact solution/u" + std::to_string(i + 1);
            add(exact_u[i],
                entry,
                u[i],
                true,
                exact.manufactured,
                entry + " gradient",
                gradient[i]);
          }
        add(exact_action, "Exact solution/lambda", exact.lambda, false, false);
      }

    if (problem.expression_evaluation !=
        Parameters::ExpressionEvaluation::parser)
      try
        {
          compile(scene, constants);
        }
      catch (const CompiledFunctions::Unavailable &e)
        {
          if (exact.manufactured)
            throw Parameters::invalid_entry("Exact solution/Manufactured data",
                                            "true",
                                            "needs compiled expressions, but " +
                                              std::string(e.what()));
          if (problem.expression_evaluation ==
              Parameters::ExpressionEvaluation::compiled)
            throw Parameters::invalid_entry(
              "Problem/Expression evaluation",
              "compiled",
              "needs a working C++ compiler, but " + std::string(e.what()) +
                "; or use auto or parser");
          pcout << "Note: Problem/Expression evaluation = auto: " << e.what()
                << "; the parser evaluates the expressions" << std::endl;
        }
    if (exact.manufactured)
      manufacture(scene);
    g_and_g2 = std::make_unique<FunctionFromFunctionObjects<dim>>(
      std::vector<std::function<double(const Point<dim> &)>>{
        [this](const Point<dim> &p) { return g->value(p); },
        [this](const Point<dim> &p) { return g2->value(p); }});
  }



  /**
   * Compile the expressions of @p scene (with @p constants and those that
   * muparser defines, _pi and _e) and evaluate them by the compiled code
   * from now on, their gradients (where asked for) by its dual numbers.
   */
  template <int dim>
  void
  ProblemData<dim>::compile(const Scene                         &scene,
                            const std::map<std::string, double> &constants)
  {
    std::map<std::string, double> all_constants = constants;
    const mu::Parser              parser;
    for (const auto &[name, value] : parser.GetConst())
      all_constants.emplace(name, value);
    std::vector<CompiledFunctions::Request> requests;
    for (const auto &expression : scene)
      requests.push_back(expression.second);
    // The loads at the same points: f1 and f2, or what the manufactured
    // loads are made of. The error norms want u1, u2 with their gradients
    // and λ at the same points. The loads decide the discrete solution:
    // evaluated point by point, as the parser does; the exact solution only
    // enters the error norms: with vector math.
    std::vector<CompiledFunctions::Group> groups;
    if (manufactured)
      groups.push_back({{{position(scene, exact_u[0].get()), false, true},
                         {position(scene, exact_u[1].get()), false, true},
                         {position(scene, exact_action.get())}}});
    else
      groups.push_back(
        {{{position(scene, f[0].get())}, {position(scene, f[1].get())}}});
    if (exact_solution_known)
      groups.push_back({{{position(scene, exact_u[0].get()), true},
                         {position(scene, exact_u[1].get()), true},
                         {position(scene, exact_action.get())}},
                        true});
    compiled = std::make_unique<CompiledFunctions>(
      requests,
      Utilities::split_string_list(
        FunctionParser<dim>::default_variable_names()),
      all_constants,
      groups);
    loads_group = compiled->group(0);
    if (exact_solution_known)
      exact_group = compiled->group(1);
    for (unsigned int i = 0; i < scene.size(); ++i)
      {
        const CompiledFunctions::Value value = compiled->value(i);
        std::function<Tensor<1, dim>(const Point<dim> &)> gradient;
        if (requests[i].gradient)
          gradient = [derivatives =
                        compiled->gradient(i)](const Point<dim> &p) {
            Tensor<1, dim> result;
            derivatives(&p[0], &result[0]);
            return result;
          };
        scene[i].first->use_compiled(
          [value](const Point<dim> &p) { return value(&p[0]); }, gradient);
      }
  }



  /**
   * The manufactured data (Exact solution/Manufactured data): from the
   * compiled u1, u2 and λ of @p scene, f1 = −μ1Δu1 − λ, f2 = −μ2Δu2 + λ
   * (Laplacians by the second-order dual numbers), g = u1 and g2 = u2.
   */
  template <int dim>
  void
  ProblemData<dim>::manufacture(const Scene &scene)
  {
    const CompiledFunctions::Value lambda =
      compiled->value(position(scene, exact_action.get()));
    const std::string entry = "Exact solution/Manufactured data";
    for (unsigned int i = 0; i < 2; ++i)
      {
        const unsigned int             u = position(scene, exact_u[i].get());
        const CompiledFunctions::Value laplacian = compiled->laplacian(u);
        const CompiledFunctions::Value value     = compiled->value(u);
        const std::string              n         = std::to_string(i + 1);
        f[i]                                     = std::make_unique<Expression>(
          entry,
          "f" + n + " = -mu" + n + " Laplace(u" + n + ") " +
            (i == 0 ? "-" : "+") + " lambda",
          [laplacian, lambda, i, mu = mu[i]](const Point<dim> &p) {
            return manufactured_load(i, mu, laplacian(&p[0]), lambda(&p[0]));
          });
        (i == 0 ? g : g2) = std::make_unique<Expression>(
          "Exact solution/u" + n,
          "g" + std::string(i == 0 ? "" : "2") + " = u" + n,
          [value](const Point<dim> &p) { return value(&p[0]); });
      }
  }



  template <int dim>
  ProblemData<dim>::~ProblemData() = default;



  template <int dim>
  void
  ProblemData<dim>::load_list(const std::vector<Point<dim>> &points,
                              LoadValues                    &values) const
  {
    const unsigned int n_points = points.size();
    for (unsigned int i = 0; i < 2; ++i)
      values.f[i].resize(n_points);
    if (loads_group == nullptr)
      {
        for (unsigned int i = 0; i < 2; ++i)
          f[i]->value_list(points, values.f[i]);
        return;
      }

    // Per point f1, f2; with manufactured data u1, Δu1, u2, Δu2, λ, of
    // which the loads need Δu_i (at laplacian_slot[i]) and λ.
    static_assert(sizeof(Point<dim>) == dim * sizeof(double));
    constexpr std::array<unsigned int, 2> laplacian_slot{{1, 3}};
    constexpr unsigned int                lambda_slot = 4;
    const unsigned int                    n_values    = manufactured ? 5 : 2;
    values.group_values.resize(n_points * n_values);
    loads_group(&points[0][0], n_points, values.group_values.data());
    for (unsigned int q = 0; q < n_points; ++q)
      {
        const double *group_value = &values.group_values[q * n_values];
        for (unsigned int i = 0; i < 2; ++i)
          {
            values.f[i][q] = manufactured ?
                               manufactured_load(i,
                                                 mu[i],
                                                 group_value[laplacian_slot[i]],
                                                 group_value[lambda_slot]) :
                               group_value[i];
            f[i]->check(values.f[i][q], points[q]);
          }
      }
  }



  template <int dim>
  const Function<dim> &
  ProblemData<dim>::boundary_values() const
  {
    return *g_and_g2;
  }



  template <int dim>
  void
  ProblemData<dim>::check_boundary_data(
    const Triangulation<dim> &triangulation) const
  {
    // The vertices and points in between on every boundary face, on the
    // boundary as the manifold of the face describes it (the unit circle
    // for the disk): the vertices of every finer mesh, where g_h and g2_h
    // interpolate g and g2, lie there.
    const unsigned int n_points_per_face = 8;
    for (const auto &face : triangulation.active_face_iterators())
      if (face->at_boundary())
        for (unsigned int k = 0; k <= n_points_per_face; ++k)
          {
            const Point<dim> p = face->get_manifold().get_intermediate_point(
              face->vertex(0),
              face->vertex(1),
              static_cast<double>(k) / n_points_per_face);
            const double g_value  = g->value(p);
            const double g2_value = g2->value(p);
            for (const auto &[function, name, value] :
                 {std::tuple{g.get(), "g", g_value},
                  std::tuple{g2.get(), "g - g2", g_value - g2_value}})
              if (value < 0)
                {
                  std::ostringstream allowed;
                  allowed << name << " = " << value << " < 0 at "
                          << point_text(p) << " on the boundary; " << name
                          << " must be >= 0 there";
                  throw function->invalid(allowed.str());
                }
          }
  }



  template <int dim>
  void
  ProblemData<dim>::check_exact_solution(
    const Triangulation<dim> &triangulation,
    const Mapping<dim>       &mapping,
    const Quadrature<dim>    &quadrature) const
  {
    if (!exact_solution_known)
      return;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          set_gradient_step(1e-4 * cell->diameter());
          for (const Point<dim> &unit_point : quadrature.get_points())
            {
              const Point<dim> p =
                mapping.transform_unit_to_real_cell(cell, unit_point);
              for (const auto &u : exact_u)
                {
                  u->value(p);
                  u->gradient(p);
                }
              exact_action->value(p);
              for (const auto &u : exact_u)
                u->check_gradient_entry(p);
            }
        }
  }



  template <int dim>
  void
  ProblemData<dim>::set_gradient_step(const double step) const
  {
    for (const auto &u : exact_u)
      if (u)
        u->set_gradient_step(step);
  }



  template <int dim>
  void
  ProblemData<dim>::exact_solution_list(const std::vector<Point<dim>> &points,
                                        ExactValues &values) const
  {
    Assert(exact_solution_known, ExcInternalError());
    const unsigned int n_points = points.size();
    values.lambda.resize(n_points);
    for (unsigned int i = 0; i < 2; ++i)
      {
        values.u[i].resize(n_points);
        values.grad_u[i].resize(n_points);
      }
    if (exact_group == nullptr)
      {
        for (unsigned int i = 0; i < 2; ++i)
          {
            exact_u[i]->value_list(points, values.u[i]);
            exact_u[i]->gradient_list(points, values.grad_u[i]);
          }
        exact_action->value_list(points, values.lambda);
        return;
      }

    // The group reads the points as dim coordinates each, one point after
    // the other, and writes per point u1, ∇u1, u2, ∇u2, λ.
    static_assert(sizeof(Point<dim>) == dim * sizeof(double));
    values.group_values.resize(n_points * (2 * (1 + dim) + 1));
    exact_group(&points[0][0], n_points, values.group_values.data());
    const double *group_value = values.group_values.data();
    for (unsigned int q = 0; q < n_points; ++q)
      {
        for (unsigned int i = 0; i < 2; ++i)
          {
            values.u[i][q] = *group_value++;
            for (unsigned int d = 0; d < dim; ++d)
              values.grad_u[i][q][d] = *group_value++;
            exact_u[i]->check(values.u[i][q], points[q]);
            exact_u[i]->check(values.grad_u[i][q], points[q]);
          }
        values.lambda[q] = *group_value++;
        exact_action->check(values.lambda[q], points[q]);
      }
  }



  template <int dim>
  void
  ProblemData<dim>::exact_action_list(const std::vector<Point<dim>> &points,
                                      std::vector<double> &values) const
  {
    Assert(exact_solution_known, ExcInternalError());
    values.resize(points.size());
    exact_action->value_list(points, values);
  }



  template class ProblemData<2>;
} // namespace membranes
