#include <membranes/scene/expression_translation.h>
#include <sstream>

namespace membranes
{
  namespace
  {
    /**
     * The definitions that every generated source starts with: the dual
     * numbers of forward-mode differentiation and the functions of the
     * grammar, for double and for dual numbers alike. Dual<T> holds a value
     * and its n derivatives, each a T: Dual<double> carries first
     * derivatives, Dual<Dual<double>> second ones. The semantics of each
     * function are those of muparser 2.3 and of deal.II's additions
     * (internal::FunctionParser: `if`, `int`, `|` and `&` round their
     * arguments to the nearest integer; `?:`, `&&`, `||` test against 0).
     */
    const char *const prelude = R"(#include <cmath>
// The vector forms of sin, cos, exp, log and pow in glibc's libmvec (x86-64),
// declared for GCC: a loop over points that it vectorizes then calls them,
// two to eight points at once (_ZGVdN4v_cos: four, with AVX2). The program
// compiles sin and cos as plain functions (-fno-builtin-sin and -cos), else
// GCC would merge the sin(x) and cos(x) of a dual number into one sincos,
// which has no vector form it calls.
#if defined(__x86_64__) && defined(__GLIBC__) && defined(__GNUC__) && \
  !defined(__clang__)
#define MEMBRANES_VECTOR_FORM __attribute__((simd("notinbranch"), const))
extern "C"
{
  MEMBRANES_VECTOR_FORM double sin(double) noexcept;
  MEMBRANES_VECTOR_FORM double cos(double) noexcept;
  MEMBRANES_VECTOR_FORM double exp(double) noexcept;
  MEMBRANES_VECTOR_FORM double log(double) noexcept;
  MEMBRANES_VECTOR_FORM double pow(double, double) noexcept;
}
#endif
// Every function of the prelude is small: inlined into the expression, so
// that a dual number's components stay in registers.
#define MEMBRANES_INLINE inline __attribute__((always_inline))
namespace
{
  using std::abs; using std::acos; using std::acosh; using std::asin;
  using std::asinh; using std::atan; using std::atan2; using std::atanh;
  using std::cos; using std::cosh; using std::erf; using std::erfc;
  using std::exp; using std::log; using std::log10; using std::log2;
  using std::pow; using std::sin; using std::sinh; using std::sqrt;
  using std::tan; using std::tanh;

  // The operators are friends of Dual<T>, found through it, so that a
  // double on either side converts to a constant Dual<T>.
  template <class T>
  struct Dual
  {
    Dual(const double c = 0) : v(c)
    {
      for (T &e : d)
        e = T(0.);
    }
    friend MEMBRANES_INLINE Dual operator-(const Dual &a)
    {
      Dual r;
      r.v = -a.v;
      for (int i = 0; i < n; ++i)
        r.d[i] = -a.d[i];
      return r;
    }
    // r = a op b, and its derivatives dr (which may use r.v).
#define MEMBRANES_BINARY(op, dr)                                         \
    friend MEMBRANES_INLINE Dual operator op(const Dual &a, const Dual &b) \
    {                                                                    \
      Dual r;                                                            \
      r.v = a.v op b.v;                                                  \
      for (int i = 0; i < n; ++i)                                        \
        r.d[i] = dr;                                                     \
      return r;                                                          \
    }
    MEMBRANES_BINARY(+, a.d[i] + b.d[i])
    MEMBRANES_BINARY(-, a.d[i] - b.d[i])
    MEMBRANES_BINARY(*, a.d[i] * b.v + a.v * b.d[i])
    MEMBRANES_BINARY(/, (a.d[i] - r.v * b.d[i]) / b.v)
#undef MEMBRANES_BINARY
    T v;
    T d[n];
  };

  inline double value(const double a) { return a; }
  template <class T> double value(const Dual<T> &a) { return value(a.v); }
  inline bool is_zero(const double a) { return a == 0; }
  template <class T> bool is_zero(const Dual<T> &a)
  {
    bool zero = is_zero(a.v);
    for (const T &e : a.d)
      zero = zero && is_zero(e);
    return zero;
  }

  // f(a) with f'(a) = df, by the chain rule.
  template <class T> MEMBRANES_INLINE Dual<T> chain(const Dual<T> &a, const T &f, const T &df)
  {
    Dual<T> r;
    r.v = f;
    for (int i = 0; i < n; ++i)
      r.d[i] = df * a.d[i];
    return r;
  }

#define MEMBRANES_UNARY(f, df)                                          \
  template <class T> MEMBRANES_INLINE Dual<T> f(const Dual<T> &a)                        \
  {                                                                     \
    const T &x = a.v;                                                   \
    return chain(a, T(f(x)), T(df));                                    \
  }
  MEMBRANES_UNARY(sin, cos(x))
  MEMBRANES_UNARY(cos, -sin(x))
  MEMBRANES_UNARY(tan, 1. / (cos(x) * cos(x)))
  MEMBRANES_UNARY(asin, 1. / sqrt(1. - x * x))
  MEMBRANES_UNARY(acos, -1. / sqrt(1. - x * x))
  MEMBRANES_UNARY(atan, 1. / (1. + x * x))
  MEMBRANES_UNARY(sinh, cosh(x))
  MEMBRANES_UNARY(cosh, sinh(x))
  MEMBRANES_UNARY(tanh, 1. - tanh(x) * tanh(x))
  MEMBRANES_UNARY(asinh, 1. / sqrt(x * x + 1.))
  MEMBRANES_UNARY(acosh, 1. / sqrt(x * x - 1.))
  MEMBRANES_UNARY(atanh, 1. / (1. - x * x))
  MEMBRANES_UNARY(exp, exp(x))
  MEMBRANES_UNARY(log, 1. / x)
  MEMBRANES_UNARY(log2, 1. / (x * 0.69314718055994530942))
  MEMBRANES_UNARY(log10, 1. / (x * 2.30258509299404568402))
  MEMBRANES_UNARY(sqrt, 0.5 / sqrt(x))
  MEMBRANES_UNARY(abs, value(x) < 0 ? -1. : value(x) > 0 ? 1. : 0.)
  MEMBRANES_UNARY(erf, 1.12837916709551257390 * exp(-x * x))
  MEMBRANES_UNARY(erfc, -1.12837916709551257390 * exp(-x * x))
#undef MEMBRANES_UNARY

  template <class T> MEMBRANES_INLINE Dual<T> atan2(const Dual<T> &a, const Dual<T> &b)
  {
    Dual<T> r;
    r.v = atan2(a.v, b.v);
    const T s = a.v * a.v + b.v * b.v;
    for (int i = 0; i < n; ++i)
      r.d[i] = (b.v * a.d[i] - a.v * b.d[i]) / s;
    return r;
  }
  template <class T> MEMBRANES_INLINE Dual<T> pow(const Dual<T> &a, const Dual<T> &b)
  {
    Dual<T> r;
    r.v = pow(a.v, b.v);
    bool constant_exponent = true;
    for (const T &e : b.d)
      constant_exponent = constant_exponent && is_zero(e);
    const T da = b.v * pow(a.v, b.v - 1.);
    for (int i = 0; i < n; ++i)
      r.d[i] = constant_exponent ? da * a.d[i] :
               da * a.d[i] + r.v * log(a.v) * b.d[i];
    return r;
  }
  template <class T> T ln(const T &a) { return log(a); }
  template <class T> T cot(const T &a) { return 1. / tan(a); }
  template <class T> T csc(const T &a) { return 1. / sin(a); }
  template <class T> T sec(const T &a) { return 1. / cos(a); }
  // a^k for an integer k, by repeated squaring, unrolled at compile time.
  template <int k, class T> MEMBRANES_INLINE T ipow(const T &a)
  {
    if constexpr (k < 0)
      return 1. / ipow<-k>(a);
    else if constexpr (k == 0)
      return T(1.);
    else if constexpr (k == 1)
      return a;
    else
      {
        const T half = ipow<k / 2>(a);
        if constexpr (k % 2 == 0)
          return half * half;
        else
          return half * half * a;
      }
  }
  template <class T> T min(const T &a) { return a; }
  template <class T, class... R> T min(const T &a, const R &...r)
  {
    const T b = min(r...);
    return value(b) < value(a) ? b : a;
  }
  template <class T> T max(const T &a) { return a; }
  template <class T, class... R> T max(const T &a, const R &...r)
  {
    const T b = max(r...);
    return value(b) > value(a) ? b : a;
  }
  template <class T, class... R> T sum(const T &a, const R &...r)
  {
    return (a + ... + r);
  }
  template <class T, class... R> T avg(const T &a, const R &...r)
  {
    return sum(a, r...) / double(1 + sizeof...(r));
  }
  // Functions whose derivative is 0 wherever it exists.
  inline int round_int(const double a)
  {
    return static_cast<int>(a + (a >= 0.0 ? 0.5 : -0.5));
  }
  template <class T> T sign(const T &a)
  {
    return value(a) < 0 ? -1. : value(a) > 0 ? 1. : 0.;
  }
  template <class T> T rint(const T &a) { return std::floor(value(a) + 0.5); }
  template <class T> T ceil(const T &a) { return std::ceil(value(a)); }
  template <class T> T floor(const T &a) { return std::floor(value(a)); }
  template <class T> T int_(const T &a) { return double(round_int(value(a))); }
  template <class T> T if_(const T &c, const T &a, const T &b)
  {
    return round_int(value(c)) != 0 ? a : b;
  }
  template <class T> T truth(const bool b) { return b ? 1. : 0.; }
  template <class T> bool nonzero(const T &a) { return value(a) != 0; }
  template <class T> bool rounded_nonzero(const T &a)
  {
    return round_int(value(a)) != 0;
  }

  // The variables at the point p as dual numbers: v[d] is x_d with the
  // derivative 1 by x_d (by x_d at both levels for the second derivatives).
  MEMBRANES_INLINE void seed(const double *p, Dual<double> *v)
  {
    for (int d = 0; d < n; ++d) { v[d].v = p[d]; v[d].d[d] = 1; }
  }
  MEMBRANES_INLINE void seed(const double *p, Dual<Dual<double>> *v)
  {
    for (int d = 0; d < n; ++d) { v[d].v.v = p[d]; v[d].v.d[d] = 1; v[d].d[d].v = 1; }
  }
  MEMBRANES_INLINE double laplacian(const Dual<Dual<double>> &r)
  {
    double sum = 0;
    for (int d = 0; d < n; ++d) sum += r.d[d].d[d];
    return sum;
  }
}
)";

    /**
     * The evaluation of group @p group at the point p: each member in the
     * number type its derivatives need, written to out, one value after the
     * other. The coordinates of p are read once into x (a local copy that
     * a vectorized loop reads whole, whichever branch of a conditional it
     * takes), and seeded as dual numbers once for all members (first
     * derivatives in v1, second ones in v2).
     */
    std::string
    group_member_lines(const CompiledFunctions::Group &group)
    {
      bool first = false, second = false;
      for (const CompiledFunctions::Member &member : group.members)
        {
          first  = first || (member.gradient && !member.laplacian);
          second = second || member.laplacian;
        }
      std::ostringstream out;
      out << "    double x[n];\n    for (int d = 0; d < n; ++d) x[d] = p[d];\n";
      if (first)
        out << "    Dual<double> v1[n];\n    seed(x, v1);\n";
      if (second)
        out << "    Dual<Dual<double>> v2[n];\n    seed(x, v2);\n";
      for (const CompiledFunctions::Member &member : group.members)
        {
          const std::string e =
            "expression_" + std::to_string(member.expression);
          if (member.laplacian)
            out << "    {\n      const Dual<Dual<double>> r = " << e
                << "(v2);\n      *out++ = r.v.v;\n"
                << (member.gradient ?
                      "      for (int d = 0; d < n; ++d) *out++ = r.v.d[d];\n" :
                      "")
                << "      *out++ = laplacian(r);\n    }\n";
          else if (member.gradient)
            out
              << "    {\n      const Dual<double> r = " << e
              << "(v1);\n      *out++ = r.v;\n"
              << "      for (int d = 0; d < n; ++d) *out++ = r.d[d];\n    }\n";
          else
            out << "    *out++ = " << e << "(x);\n";
        }
      return out.str();
    }



    /**
     * Group @p g as the function membranes_group_g: a loop over the points.
     * With vector math the members are inlined into the body of the loop,
     * which the compiler may then vectorize; without, the body is a function
     * of its own, called once per point, so that every point is evaluated
     * alone with the scalar functions.
     */
    std::string
    group_function(const CompiledFunctions::Group &group, const unsigned int g)
    {
      const std::string  s = std::to_string(g);
      std::ostringstream out;
      if (group.vector_math)
        out << "extern \"C\" void membranes_group_" << s
            << "(const double *__restrict points, const unsigned int "
               "n_points, double *__restrict out) {\n"
            << "  for (unsigned int q = 0; q < n_points; ++q) {\n"
            << "    const double *p = points + n * q;\n"
            << group_member_lines(group) << "  }\n}\n";
      else
        out << "static __attribute__((noinline)) double *group_point_" << s
            << "(const double *p, double *out) {\n"
            << group_member_lines(group) << "  return out;\n}\n"
            << "extern \"C\" void membranes_group_" << s
            << "(const double *points, const unsigned int n_points, "
               "double *out) {\n"
            << "  for (unsigned int q = 0; q < n_points; ++q)\n"
            << "    out = group_point_" << s << "(points + n * q, out);\n}\n";
      return out.str();
    }

  } // namespace



  std::string
  generated_source(const std::vector<CompiledFunctions::Request> &requests,
                   const std::vector<std::string>                &variables,
                   const std::map<std::string, double>           &constants,
                   const std::vector<CompiledFunctions::Group>   &groups)
  {
    const std::string  n = std::to_string(variables.size());
    std::ostringstream out;
    out << "constexpr int n = " << n << ";\n" << prelude;
    for (unsigned int i = 0; i < requests.size(); ++i)
      {
        const std::string e = "expression_" + std::to_string(i);
        const std::string s = std::to_string(i);
        out << "template <class T> MEMBRANES_INLINE T " << e
            << "(const T *v) { return "
            << translate_expression(requests[i].expression,
                                    variables,
                                    constants)
            << "; }\n"
            << "extern \"C\" double membranes_value_" << s
            << "(const double *p) { return " << e << "(p); }\n";
        if (requests[i].gradient)
          out << "extern \"C\" void membranes_gradient_" << s
              << "(const double *p, double *g) {\n"
              << "  Dual<double> v[n];\n  seed(p, v);\n"
              << "  const Dual<double> r = " << e << "(v);\n"
              << "  for (int d = 0; d < n; ++d) g[d] = r.d[d];\n}\n";
        if (requests[i].laplacian)
          out << "extern \"C\" double membranes_laplacian_" << s
              << "(const double *p) {\n"
              << "  Dual<Dual<double>> v[n];\n  seed(p, v);\n"
              << "  return laplacian(" << e << "(v));\n}\n";
      }
    // One loop per group over its points: the members are evaluated in the
    // same body, where the compiler computes what they share once.
    for (unsigned int g = 0; g < groups.size(); ++g)
      out << group_function(groups[g], g);
    return out.str();
  }
} // namespace membranes
