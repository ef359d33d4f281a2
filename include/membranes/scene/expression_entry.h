#ifndef membranes_expression_entry_h
#define membranes_expression_entry_h

#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>
#include <map>
#include <membranes/scene/parameters.h>
#include <memory>
#include <muParser.h>
#include <string>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /** A point as `(x, y)`, for the messages about the data. */
  template <int dim>
  std::string
  point_text(const Point<dim> &p);

  /**
   * An entry of the scene that holds an expression, and the checks of its
   * values: one that is not finite, or larger than Parameters::max_magnitude
   * in magnitude, is an InputError naming the entry and the point.
   */
  template <int dim>
  class ExpressionEntry
  {
  public:
    ExpressionEntry(const std::string &entry, const std::string &text)
      : entry(entry)
      , text(text)
    {}

    /** The InputError for this entry, which should be @p allowed. */
    Parameters::InputError
    invalid(const std::string &allowed) const
    {
      return Parameters::invalid_entry(entry, text, allowed);
    }

    /**
     * Throw the InputError for @p what at @p p if @p value is not finite
     * or larger than max_magnitude in magnitude.
     */
    void
    check(const double      value,
          const Point<dim> &p,
          const char       *what = "value") const
    {
      if (!(std::abs(value) <= Parameters::max_magnitude))
        throw out_of_range(value, p, what);
    }

    /** Check the dim derivatives of @p gradient at @p p. */
    void
    check(const Tensor<1, dim> &gradient, const Point<dim> &p) const;

  private:
    /** The InputError of check(), kept out of its fast path. */
    Parameters::InputError
    out_of_range(const double      value,
                 const Point<dim> &p,
                 const char       *what) const;

  protected:
    const std::string entry;
    const std::string text;
  };



  /**
   * The expressions of one entry of the scene, separated by ';' (one for
   * a function, dim for a gradient, as deal.II's FunctionParser reads a
   * function with that many components), each in a muparser object set up
   * as deal.II 9.4's FunctionParser sets up its own, their variables bound
   * to the coordinates of one point.
   */
  template <int dim>
  class ParsedExpressionEntry : public ExpressionEntry<dim>
  {
  public:
    /**
     * Parse @p text, the value of entry @p entry, as @p n_components
     * expressions with @p constants and the variables bound to @p point.
     * Each is evaluated once at the origin, so that a syntax error or an
     * unknown name surfaces here, as an InputError naming the entry,
     * rather than mid-run; its value there is not checked (the origin
     * need not be in the domain: the L-shape's loads are singular at its
     * corner).
     */
    ParsedExpressionEntry(const std::string                   &entry,
                          const std::string                   &text,
                          const unsigned int                   n_components,
                          const std::map<std::string, double> &constants,
                          Point<dim>                          &point);

    /**
     * Expression @p c at the point that the variables are bound to: one
     * run of muparser's bytecode, with no lock and no lookup (unlike
     * FunctionParser::value(), which finds its parser in thread-local
     * storage on every call).
     */
    double
    evaluate(const unsigned int c) const
    {
      return parsers[c]->Eval();
    }

  private:
    std::vector<std::unique_ptr<mu::Parser>> parsers;
  };
} // namespace membranes

#endif
