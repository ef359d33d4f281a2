#include <algorithm>
#include <cctype>
#include <cmath>
#include <deal.II/base/function_parser.h>
#include <deal.II/base/utilities.h>
#include <deal.II/grid/manifold.h>
#include <iostream>
#include <membranes/problem_data.h>
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
          bool ok =
            (name_value.size() == 2 && !name_value[0].empty() &&
             std::isalpha(static_cast<unsigned char>(name_value[0][0])) &&
             std::all_of(name_value[0].begin(),
                         name_value[0].end(),
                         [](const unsigned char c) {
                           return std::isalnum(c) || c == '_';
                         }) &&
             name_value[0] != "x" && name_value[0] != "y");
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



    /** A point as `(x, y)`. */
    template <int dim>
    std::string
    at(const Point<dim> &p)
    {
      std::ostringstream text;
      text << "(";
      for (unsigned int d = 0; d < dim; ++d)
        text << (d > 0 ? ", " : "") << p[d];
      text << ")";
      return text.str();
    }
  } // namespace



  /**
   * The function of one expression of the scene, which checks every value
   * it gives: one that is not finite, or larger than max_magnitude in
   * magnitude, is an InputError naming the entry and the point. All uses
   * of the data go through here (loads at the quadrature points of every
   * cell, boundary values at the boundary vertices, the exact solution and
   * its gradient in the error norms), on every mesh, so that a NaN or an
   * infinity never enters a computation unnoticed, wherever the expression
   * produces it.
   */
  template <int dim>
  class ProblemData<dim>::Expression : public Function<dim>
  {
  public:
    /**
     * Parse @p expression, the value of entry @p entry. It is evaluated
     * once at the origin so that a syntax error or an unknown name surfaces
     * here, as an InputError naming the entry, rather than mid-run; its
     * value there is not checked (the origin need not be in the domain:
     * the L-shape's loads are singular at its corner).
     */
    Expression(const std::string                   &entry,
               const std::string                   &expression,
               const std::map<std::string, double> &constants)
      : entry(entry)
      , expression(expression)
      , parser(1, 0.0, 1e-5) // a step for gradient(), see set_gradient_step()
    {
      parser.set_formula(AutoDerivativeFunction<dim>::Euler);
      // The parser reports syntax errors on std::cerr before it throws:
      // keep that text out of the program's one-line message.
      struct SilenceCerr
      {
        std::ostringstream sink;
        std::streambuf    *original = std::cerr.rdbuf(sink.rdbuf());
        ~SilenceCerr()
        {
          std::cerr.rdbuf(original);
        }
      } silence;
      try
        {
          parser.initialize(FunctionParser<dim>::default_variable_names(),
                            expression,
                            constants);
          parser.value(Point<dim>());
        }
      catch (const ExceptionBase &e)
        {
          throw invalid("not a valid expression in x, y (" +
                        Parameters::one_line_message(e) + ")");
        }
    }

    double
    value(const Point<dim> &p, const unsigned int = 0) const override
    {
      const double result = parser.value(p);
      check(result, p, "value");
      return result;
    }

    Tensor<1, dim>
    gradient(const Point<dim> &p, const unsigned int = 0) const override
    {
      const Tensor<1, dim> gradient = parser.gradient(p);
      for (unsigned int d = 0; d < dim; ++d)
        check(gradient[d], p, "gradient (by finite differences)");
      return gradient;
    }

    /** The step of the finite differences that give gradient(). */
    void
    set_gradient_step(const double step)
    {
      parser.set_h(step);
    }

    /** The InputError for this entry, which should be @p allowed. */
    Parameters::InputError
    invalid(const std::string &allowed) const
    {
      return Parameters::invalid_entry(entry, expression, allowed);
    }

  private:
    void
    check(const double       value,
          const Point<dim>  &p,
          const std::string &what) const
    {
      if (!(std::abs(value) <= Parameters::max_magnitude))
        {
          std::ostringstream allowed;
          allowed << "its " << what << " at " << at(p) << " is " << value
                  << "; an expression must be finite and at most "
                  << Parameters::max_magnitude
                  << " in magnitude wherever it is evaluated";
          throw invalid(allowed.str());
        }
    }

    const std::string   entry;
    const std::string   expression;
    FunctionParser<dim> parser;
  };



  template <int dim>
  class ProblemData<dim>::BoundaryValues : public Function<dim>
  {
  public:
    BoundaryValues(const Function<dim> &g, const Function<dim> &g2)
      : Function<dim>(2)
      , g(g)
      , g2(g2)
    {}

    double
    value(const Point<dim> &p, const unsigned int component) const override
    {
      return component == 0 ? g.value(p) : g2.value(p);
    }

  private:
    const Function<dim> &g;
    const Function<dim> &g2;
  };



  template <int dim>
  ProblemData<dim>::ProblemData(const Parameters::Problem       &problem,
                                const Parameters::ExactSolution &exact)
    : mu{{problem.mu1, problem.mu2}}
    , mu_bar(problem.mu1 * problem.mu2 / (problem.mu1 + problem.mu2))
    , known(exact.known)
  {
    const auto constants = parse_constants(problem);
    f[0] = std::make_unique<Expression>("Problem/f1", problem.f1, constants);
    f[1] = std::make_unique<Expression>("Problem/f2", problem.f2, constants);
    g    = std::make_unique<Expression>("Problem/g", problem.g, constants);
    g2   = std::make_unique<Expression>("Problem/g2", problem.g2, constants);
    g_and_g2 = std::make_unique<BoundaryValues>(*g, *g2);
    if (known)
      {
        exact_u[0]   = std::make_unique<Expression>("Exact solution/u1",
                                                  exact.u1,
                                                  constants);
        exact_u[1]   = std::make_unique<Expression>("Exact solution/u2",
                                                  exact.u2,
                                                  constants);
        exact_action = std::make_unique<Expression>("Exact solution/lambda",
                                                    exact.lambda,
                                                    constants);
      }
  }



  template <int dim>
  ProblemData<dim>::~ProblemData() = default;



  template <int dim>
  const Function<dim> &
  ProblemData<dim>::load(const unsigned int i) const
  {
    return *f[i];
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
                  allowed << name << " = " << value << " < 0 at " << at(p)
                          << " on the boundary; " << name
                          << " must be >= 0 there";
                  throw function->invalid(allowed.str());
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
  bool
  ProblemData<dim>::exact_solution_known() const
  {
    return known;
  }



  template <int dim>
  const Function<dim> &
  ProblemData<dim>::exact_displacement(const unsigned int i) const
  {
    Assert(known, ExcInternalError());
    return *exact_u[i];
  }



  template <int dim>
  const Function<dim> &
  ProblemData<dim>::exact_lambda() const
  {
    Assert(known, ExcInternalError());
    return *exact_action;
  }



  template class ProblemData<2>;
} // namespace membranes
