#ifndef membranes_compiled_function_h
#define membranes_compiled_function_h

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace membranes
{
  /**
   * The expressions of a scene as machine code. Each expression, in the
   * grammar of muparser as deal.II's FunctionParser sets it up, is
   * translated into a C++ function template of its variables
   * (translate_expression()), compiled into a shared object with the C++
   * compiler that built the program, or the command in the environment
   * variable `MEMBRANES_CXX` when set, and loaded with dlopen.
   *
   * The template is instantiated for double (the values), and for
   * forward-mode dual numbers: one level for the gradient, two nested levels
   * for the Laplacian (the sum of the second derivatives ∂²/∂x_d²), exact to
   * round-off where the expression is differentiable, with no step size.
   *
   * Expressions that are wanted at the same points (the exact solution
   * u1, u2 and λ in the error norms) can be asked for as one group: one
   * generated loop over the points evaluates all of them, so that the
   * compiler computes their common subexpressions once (cos(πx/2) of both
   * u1 and u2, say) and a list of points costs one call.
   *
   * The shared object is cached (under `MEMBRANES_CACHE_DIR` if set), named by
   * a hash of the generated source and of the compiler: a later run with the
   * same expressions loads it without compiling.
   */
  class CompiledFunctions
  {
  public:
    /**
     * Why the expressions could not be compiled (no working compiler, a
     * function such as rand() that has no compiled form, a cache directory
     * that cannot be written): one line.
     */
    class Unavailable : public std::runtime_error
    {
    public:
      using std::runtime_error::runtime_error;
    };

    /** One expression to compile, and whether its derivatives are needed. */
    struct Request
    {
      std::string expression;
      bool        gradient  = false;
      bool        laplacian = false;
    };

    /** One expression of a group, and which of its derivatives are wanted. */
    struct Member
    {
      unsigned int expression;
      bool         gradient  = false;
      bool         laplacian = false;
    };

    /**
     * Expressions evaluated together at the same points.
     *
     * With @p vector_math, the loop over the points may evaluate several
     * points at once, with the vector forms of sin, cos, exp, log and pow
     * that glibc provides (libmvec, on x86-64; benchmarks/choices.md, "Vector
     * math in the error norms"), but these
     * functions are accurate to a few units in the last place, where the
     * scalar ones, which the parser calls, are correctly rounded in
     * practice. So only for values that decide nothing in the discrete
     * problem: the exact solution of the error norms. Without it (the
     * loads), the values are those of the single expressions, bit for bit.
     */
    struct Group
    {
      std::vector<Member> members;
      bool                vector_math = false;
    };

    /** The value at the point p (its dim coordinates). */
    using Value = double (*)(const double *p);
    /** The dim derivatives at p, written to gradient. */
    using Gradient = void (*)(const double *p, double *gradient);
    /**
     * A group at @p n_points points (dim coordinates each, one after the
     * other), written to @p values: for each point, for each member in
     * turn, its value, then its dim derivatives and its Laplacian where
     * asked for.
     */
    using GroupValues = void (*)(const double      *points,
                                 const unsigned int n_points,
                                 double            *values);

    /**
     * Translate @p requests, expressions in the variables @p variables with
     * the named @p constants (substituted by their values), with the
     * @p groups of them evaluated together, and compile and load them (or
     * load them from the cache). Throws Unavailable.
     */
    CompiledFunctions(const std::vector<Request>          &requests,
                      const std::vector<std::string>      &variables,
                      const std::map<std::string, double> &constants,
                      const std::vector<Group>            &groups = {});

    ~CompiledFunctions();

    CompiledFunctions(const CompiledFunctions &) = delete;
    CompiledFunctions &
    operator=(const CompiledFunctions &) = delete;

    /** The value of expression @p i. */
    Value
    value(const unsigned int i) const
    {
      return reinterpret_cast<Value>(symbol("value", i));
    }

    /** The gradient of expression @p i; only if requested. */
    Gradient
    gradient(const unsigned int i) const
    {
      return reinterpret_cast<Gradient>(symbol("gradient", i));
    }

    /** The Laplacian of expression @p i; only if requested. */
    Value
    laplacian(const unsigned int i) const
    {
      return reinterpret_cast<Value>(symbol("laplacian", i));
    }

    /** Group @p g. */
    GroupValues
    group(const unsigned int g) const
    {
      return reinterpret_cast<GroupValues>(symbol("group", g));
    }

    /**
     * Whether the shared object was compiled by this run (false: found in
     * the cache), and the wall time that compiling or loading took.
     */
    bool   compiled_now = false;
    double seconds      = 0;

  private:
    /** The entry point membranes_<kind>_<i>; Unavailable if absent. */
    void *
    symbol(const std::string &kind, const unsigned int i) const;

    void *handle = nullptr;
  };
} // namespace membranes

#endif
