#include <deal.II/base/function_parser.h>
#include <deal.II/base/mu_parser_internal.h>
#include <deal.II/base/utilities.h>
#include <membranes/scene/expression_entry.h>
#include <sstream>

namespace membranes
{
  template <int dim>
  std::string
  point_text(const Point<dim> &p)
  {
    std::ostringstream text;
    text << "(";
    for (unsigned int d = 0; d < dim; ++d)
      text << (d > 0 ? ", " : "") << p[d];
    text << ")";
    return text.str();
  }



  namespace
  {
    /**
     * Set up @p parser for @p expression as deal.II 9.4's FunctionParser
     * sets up its own muparser objects (internal::FunctionParser::
     * ParserImplementation::init_muparser()), so that an expression means
     * the same and gives the same values, to the last bit: the
     * @p constants, the variables x, y bound to the coordinates of
     * @p point, deal.II's functions if, int, ceil, floor, cot, csc, sec,
     * log, pow, erfc, rand, rand_seed and operators |, & (deal.II's own
     * definitions, with the same permission to fold constants), and the
     * blanks between a function name and its parenthesis removed.
     */
    template <int dim>
    void
    set_up(mu::Parser                          &parser,
           const std::string                   &expression,
           const std::map<std::string, double> &constants,
           Point<dim>                          &point)
    {
      namespace deal_ii = dealii::internal::FunctionParser;
      for (const auto &[name, value] : constants)
        parser.DefineConst(name, value);
      const auto names = Utilities::split_string_list(
        FunctionParser<dim>::default_variable_names());
      for (unsigned int d = 0; d < dim; ++d)
        parser.DefineVar(names[d], &point[d]);
      parser.DefineFun("if", deal_ii::mu_if, true);
      parser.DefineOprt("|", deal_ii::mu_or, 1);
      parser.DefineOprt("&", deal_ii::mu_and, 2);
      parser.DefineFun("int", deal_ii::mu_int, true);
      parser.DefineFun("ceil", deal_ii::mu_ceil, true);
      parser.DefineFun("cot", deal_ii::mu_cot, true);
      parser.DefineFun("csc", deal_ii::mu_csc, true);
      parser.DefineFun("floor", deal_ii::mu_floor, true);
      parser.DefineFun("sec", deal_ii::mu_sec, true);
      parser.DefineFun("log", deal_ii::mu_log, true);
      parser.DefineFun("pow", deal_ii::mu_pow, true);
      parser.DefineFun("erfc", deal_ii::mu_erfc, true);
      parser.DefineFun("rand_seed", deal_ii::mu_rand_seed, true);
      parser.DefineFun("rand", deal_ii::mu_rand, true);

      std::string text = expression;
      for (const std::string &name : deal_ii::get_function_names())
        for (auto at = text.find(name); at != std::string::npos;
             at      = text.find(name, at + name.size()))
          while (
            at + name.size() < text.size() &&
            (text[at + name.size()] == ' ' || text[at + name.size()] == '\t'))
            text.erase(at + name.size(), 1);
      parser.SetExpr(text);
    }
  } // namespace



  template <int dim>
  void
  ExpressionEntry<dim>::check(const Tensor<1, dim> &gradient,
                              const Point<dim>     &p) const
  {
    static const char *const derivatives[] = {"derivative by x",
                                              "derivative by y",
                                              "derivative by z"};
    for (unsigned int d = 0; d < dim; ++d)
      check(gradient[d], p, derivatives[d]);
  }



  template <int dim>
  Parameters::InputError
  ExpressionEntry<dim>::out_of_range(const double      value,
                                     const Point<dim> &p,
                                     const char       *what) const
  {
    std::ostringstream allowed;
    allowed << "its " << what << " at " << point_text(p) << " is " << value
            << "; an expression must be finite and at most "
            << Parameters::max_magnitude
            << " in magnitude wherever it is evaluated";
    return invalid(allowed.str());
  }



  template <int dim>
  ParsedExpressionEntry<dim>::ParsedExpressionEntry(
    const std::string                   &entry,
    const std::string                   &text,
    const unsigned int                   n_components,
    const std::map<std::string, double> &constants,
    Point<dim>                          &point)
    : ExpressionEntry<dim>(entry, text)
  {
    const auto expressions = Utilities::split_string_list(text, ';');
    if (expressions.size() != n_components)
      throw this->invalid("expected " + std::to_string(n_components) +
                          (n_components == 1 ?
                             " expression in x, y" :
                             " expressions in x, y separated by ';', "
                             "the derivatives by x and by y") +
                          ", found " + std::to_string(expressions.size()));
    for (unsigned int c = 0; c < n_components; ++c)
      try
        {
          parsers.push_back(std::make_unique<mu::Parser>());
          set_up(*parsers.back(), expressions[c], constants, point);
          point = Point<dim>();
          parsers.back()->Eval();
        }
      catch (const mu::ParserError &e)
        {
          throw this->invalid(
            "not a valid expression in x, y (" +
            (n_components == 1 ? "" : "'" + expressions[c] + "': ") +
            e.GetMsg() + ")");
        }
  }



  template std::string
  point_text(const Point<2> &);
  template class ExpressionEntry<2>;
  template class ParsedExpressionEntry<2>;
} // namespace membranes
