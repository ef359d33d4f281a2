#include <cctype>
#include <cmath>
#include <deal.II/base/utilities.h>
#include <iostream>
#include <membranes/problem_data.h>
#include <sstream>

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
          bool       ok =
            (name_value.size() == 2 && !name_value[0].empty() &&
             std::isalpha(static_cast<unsigned char>(name_value[0][0])));
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
              "expected comma separated name=value pairs with finite values");
          constants[name_value[0]] = value;
        }
      return constants;
    }



    /**
     * A FunctionParser for the expression of entry @p entry. It is evaluated
     * once at the origin so that a syntax error or an unknown name surfaces
     * here, as an InputError naming the entry, rather than mid-run.
     */
    template <int dim>
    std::unique_ptr<FunctionParser<dim>>
    make_function(const std::string                   &entry,
                  const std::string                   &expression,
                  const std::map<std::string, double> &constants)
    {
      const double step = 1e-5;
      auto function     = std::make_unique<FunctionParser<dim>>(1, 0.0, step);
      function->set_formula(AutoDerivativeFunction<dim>::Euler);
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
          function->initialize(FunctionParser<dim>::default_variable_names(),
                               expression,
                               constants);
          function->value(Point<dim>());
        }
      catch (const ExceptionBase &e)
        {
          std::ostringstream reason;
          e.print_info(reason);
          std::string text = reason.str();
          for (char &c : text)
            if (c == '\n')
              c = ' ';
          throw Parameters::invalid_entry(entry,
                                          expression,
                                          "not a valid expression in x, y (" +
                                            Utilities::trim(text) + ")");
        }
      return function;
    }
  } // namespace



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
    f[0]     = make_function<dim>("Problem/f1", problem.f1, constants);
    f[1]     = make_function<dim>("Problem/f2", problem.f2, constants);
    g        = make_function<dim>("Problem/g", problem.g, constants);
    g2       = make_function<dim>("Problem/g2", problem.g2, constants);
    g_and_g2 = std::make_unique<BoundaryValues>(*g, *g2);
    if (known)
      {
        exact_u[0] =
          make_function<dim>("Exact solution/u1", exact.u1, constants);
        exact_u[1] =
          make_function<dim>("Exact solution/u2", exact.u2, constants);
        exact_action =
          make_function<dim>("Exact solution/lambda", exact.lambda, constants);
      }
  }



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
    // Vertices and a few points on every boundary face of the coarse mesh
    // (the straight chord between two vertices is where g_h lives).
    const unsigned int n_points_per_face = 8;
    for (const auto &face : triangulation.active_face_iterators())
      if (face->at_boundary())
        for (unsigned int k = 0; k <= n_points_per_face; ++k)
          {
            const double     t = static_cast<double>(k) / n_points_per_face;
            const Point<dim> p =
              (1 - t) * face->vertex(0) + t * face->vertex(1);
            const double       g_value  = g->value(p);
            const double       g2_value = g2->value(p);
            std::ostringstream where;
            where << " at (" << p << ")";
            if (!std::isfinite(g_value) || g_value < 0)
              throw Parameters::invalid_entry(
                "Problem/g",
                std::to_string(g_value) + where.str(),
                "g must be finite and >= 0 on the boundary");
            if (!std::isfinite(g2_value) || g_value - g2_value < 0)
              throw Parameters::invalid_entry(
                "Problem/g2",
                std::to_string(g2_value) + where.str(),
                "g2 must be finite and g - g2 >= 0 on the boundary");
          }
  }



  template <int dim>
  void
  ProblemData<dim>::set_gradient_step(const double step) const
  {
    for (const auto &u : exact_u)
      if (u)
        u->set_h(step);
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
