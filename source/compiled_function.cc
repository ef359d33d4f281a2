#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <dlfcn.h>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <locale>
#include <membranes/compiled_function.h>
#include <random>
#include <spawn.h>
#include <sstream>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

extern char **environ;

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
    friend MEMBRANES_INLINE Dual operator+(const Dual &a, const Dual &b)
    {
      Dual r;
      r.v = a.v + b.v;
      for (int i = 0; i < n; ++i)
        r.d[i] = a.d[i] + b.d[i];
      return r;
    }
    friend MEMBRANES_INLINE Dual operator-(const Dual &a, const Dual &b)
    {
      Dual r;
      r.v = a.v - b.v;
      for (int i = 0; i < n; ++i)
        r.d[i] = a.d[i] - b.d[i];
      return r;
    }
    friend MEMBRANES_INLINE Dual operator*(const Dual &a, const Dual &b)
    {
      Dual r;
      r.v = a.v * b.v;
      for (int i = 0; i < n; ++i)
        r.d[i] = a.d[i] * b.v + a.v * b.d[i];
      return r;
    }
    friend MEMBRANES_INLINE Dual operator/(const Dual &a, const Dual &b)
    {
      Dual r;
      r.v = a.v / b.v;
      for (int i = 0; i < n; ++i)
        r.d[i] = (a.d[i] - r.v * b.d[i]) / b.v;
      return r;
    }
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

  template <class T> Dual<T> atan2(const Dual<T> &a, const Dual<T> &b)
  {
    Dual<T> r;
    r.v = atan2(a.v, b.v);
    const T s = a.v * a.v + b.v * b.v;
    for (int i = 0; i < n; ++i)
      r.d[i] = (b.v * a.d[i] - a.v * b.d[i]) / s;
    return r;
  }
  template <class T> Dual<T> pow(const Dual<T> &a, const Dual<T> &b)
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
}
)";

    /**
     * The translation of one expression into a C++ expression of type T,
     * by recursive descent over the grammar of muparser 2.3 with deal.II's
     * operators, from the lowest precedence to the highest:
     *
     *     ternary := or ('?' ternary ':' ternary)?
     *     or      := and (('||' | '|') and)*
     *     and     := cmp (('&&' | '&') cmp)*
     *     cmp     := add (('<' | '>' | '<=' | '>=' | '==' | '!=') add)*
     *     add     := mul (('+' | '-') mul)*
     *     mul     := sign (('*' | '/') sign)*
     *     sign    := ('-' | '+') sign | power
     *     power   := primary ('^' sign)?
     *     primary := number | name | name '(' ternary (',' ternary)* ')'
     *              | '(' ternary ')'
     *
     * The expression has been accepted by muparser before: the translator
     * needs no error messages of its own for bad syntax, only the refusal
     * (Unavailable) of what has no compiled form.
     */
    class Translator
    {
    public:
      Translator(const std::string                   &text,
                 const std::vector<std::string>      &variables,
                 const std::map<std::string, double> &constants)
        : text(text)
        , variables(variables)
        , constants(constants)
      {}

      std::string
      translate()
      {
        const std::string result = ternary();
        skip_blanks();
        if (position != text.size())
          refuse("unexpected '" + text.substr(position) + "'");
        return result;
      }

    private:
      [[noreturn]] void
      refuse(const std::string &why) const
      {
        const std::size_t longest = 60;
        throw CompiledFunctions::Unavailable(
          "the expression '" +
          (text.size() <= longest ? text : text.substr(0, longest) + "...") +
          "' has no compiled form: " + why);
      }

      void
      skip_blanks()
      {
        while (position < text.size() &&
               std::isspace(static_cast<unsigned char>(text[position])))
          ++position;
      }

      /** Whether the next token is @p token; if so, it is consumed. */
      bool
      accept(const std::string &token)
      {
        skip_blanks();
        if (text.compare(position, token.size(), token) != 0)
          return false;
        // '|' is not the start of '||', '&' not that of '&&', '<' not
        // that of '<='.
        const std::size_t next = position + token.size();
        if (token.size() == 1 && next < text.size() &&
            ((token[0] == '|' && text[next] == '|') ||
             (token[0] == '&' && text[next] == '&') ||
             ((token[0] == '<' || token[0] == '>') && text[next] == '=')))
          return false;
        position = next;
        return true;
      }

      void
      expect(const std::string &token)
      {
        if (!accept(token))
          refuse("expected '" + token + "'");
      }

      /** The number @p c as a T, exactly (hexadecimal floating point). */
      static std::string
      number(const double c)
      {
        std::ostringstream out;
        out.imbue(std::locale::classic());
        out << "T(" << std::hexfloat << c << ")";
        return out.str();
      }

      std::string
      ternary()
      {
        // Each level of parentheses, arguments or exponents passes here:
        // deeper nesting is left to the parser rather than to the stack.
        if (++depth > 100)
          refuse("nested more than 100 levels deep");
        const std::string result = conditional();
        --depth;
        return result;
      }

      std::string
      conditional()
      {
        const std::string condition = logical_or();
        if (!accept("?"))
          return condition;
        const std::string if_true = ternary();
        expect(":");
        const std::string if_false = ternary();
        return "(value(" + condition + ") != 0 ? " + if_true + " : " +
               if_false + ")";
      }

      /**
       * A chain of muparser's @p op (`||` or `&&`: operands other than 0 are
       * true) and of deal.II's operator of its first character (`|` or `&`:
       * operands rounded to the nearest integer), with operands read by
       * @p operand.
       */
      std::string
      logical(std::string (Translator::*operand)(), const std::string &op)
      {
        std::string left = (this->*operand)();
        for (;;)
          {
            std::string test;
            if (accept(op))
              test = "nonzero";
            else if (accept(op.substr(0, 1)))
              test = "rounded_nonzero";
            else
              return left;
            const std::string right = (this->*operand)();
            left = "truth<T>(" + test + "(" + left + ") " + op + " " + test +
                   "(" + right + "))";
          }
      }

      std::string
      logical_or()
      {
        return logical(&Translator::logical_and, "||");
      }

      std::string
      logical_and()
      {
        return logical(&Translator::comparison, "&&");
      }

      std::string
      comparison()
      {
        std::string left = additive();
        for (;;)
          {
            std::string op;
            for (const char *candidate : {"<=", ">=", "==", "!=", "<", ">"})
              if (accept(candidate))
                {
                  op = candidate;
                  break;
                }
            if (op.empty())
              return left;
            left = "truth<T>(value(" + left + ") " + op + " value(" +
                   additive() + "))";
          }
      }

      /**
       * A chain of the left-associative operators @p ops (`+ -` or `* /`),
       * with operands read by @p operand, left to right as in C++: one pair
       * of parentheses around it, so that the text grows linearly with the
       * length of the chain.
       */
      std::string
      chain(std::string (Translator::*operand)(), const char (&ops)[2])
      {
        std::string       text = (this->*operand)();
        const std::size_t one  = text.size();
        for (;;)
          {
            const char *op = ops;
            while (op != ops + 2 && !accept(std::string(1, *op)))
              ++op;
            if (op == ops + 2)
              return text.size() == one ? text : "(" + text + ")";
            text += std::string(" ") + *op + " " + (this->*operand)();
          }
      }

      std::string
      additive()
      {
        return chain(&Translator::multiplicative, {'+', '-'});
      }

      std::string
      multiplicative()
      {
        return chain(&Translator::sign, {'*', '/'});
      }

      std::string
      sign()
      {
        if (depth > 100)
          refuse("nested more than 100 levels deep");
        if (accept("-"))
          return "(-" + sign() + ")";
        if (accept("+"))
          return sign();
        return power();
      }

      /**
       * a^b: std::pow, except for an integer exponent written as a number
       * of at most 64 in magnitude, which is a product of a few factors
       * (the same value to round-off, several times faster).
       */
      std::string
      power()
      {
        const std::string base = primary();
        if (!accept("^"))
          return base;
        skip_blanks();
        const std::size_t start = position;
        ++depth;
        const std::string exponent = sign();
        --depth;
        double             k = 0;
        std::istringstream in(text.substr(start, position - start));
        in.imbue(std::locale::classic());
        if ((in >> k) && (in >> std::ws).eof() && k == std::round(k) &&
            std::abs(k) <= 64)
          return "ipow<" + std::to_string(static_cast<int>(k)) + ">(" + base +
                 ")";
        return "pow(" + base + ", " + exponent + ")";
      }

      std::string
      primary()
      {
        skip_blanks();
        if (accept("("))
          {
            const std::string inner = ternary();
            expect(")");
            return inner;
          }
        if (position < text.size() &&
            (std::isdigit(static_cast<unsigned char>(text[position])) ||
             text[position] == '.'))
          {
            // As muparser reads a number: the longest prefix that a
            // stream reads as a double.
            std::istringstream in(text.substr(position));
            in.imbue(std::locale::classic());
            double c = 0;
            if (!(in >> c))
              refuse("not a number at '" + text.substr(position) + "'");
            position = in.eof() ?
                         text.size() :
                         position + static_cast<std::size_t>(in.tellg());
            return number(c);
          }
        const std::size_t start = position;
        while (position < text.size() &&
               (std::isalnum(static_cast<unsigned char>(text[position])) ||
                text[position] == '_'))
          ++position;
        const std::string name = text.substr(start, position - start);
        if (name.empty())
          refuse("unexpected '" + text.substr(start) + "'");
        if (accept("("))
          return call(name);
        for (unsigned int d = 0; d < variables.size(); ++d)
          if (name == variables[d])
            return "v[" + std::to_string(d) + "]";
        const auto constant = constants.find(name);
        if (constant == constants.end())
          refuse("unknown name '" + name + "'");
        return number(constant->second);
      }

      /** The call of function @p name, its '(' read. */
      std::string
      call(const std::string &name)
      {
        static const std::map<std::string, std::pair<int, int>> arities{
          {"sin", {1, 1}},   {"cos", {1, 1}},   {"tan", {1, 1}},
          {"asin", {1, 1}},  {"acos", {1, 1}},  {"atan", {1, 1}},
          {"sinh", {1, 1}},  {"cosh", {1, 1}},  {"tanh", {1, 1}},
          {"asinh", {1, 1}}, {"acosh", {1, 1}}, {"atanh", {1, 1}},
          {"atan2", {2, 2}}, {"log2", {1, 1}},  {"log10", {1, 1}},
          {"log", {1, 1}},   {"ln", {1, 1}},    {"exp", {1, 1}},
          {"sqrt", {1, 1}},  {"sign", {1, 1}},  {"rint", {1, 1}},
          {"abs", {1, 1}},   {"min", {1, 64}},  {"max", {1, 64}},
          {"sum", {1, 64}},  {"avg", {1, 64}},  {"if", {3, 3}},
          {"int", {1, 1}},   {"ceil", {1, 1}},  {"cot", {1, 1}},
          {"csc", {1, 1}},   {"floor", {1, 1}}, {"sec", {1, 1}},
          {"pow", {2, 2}},   {"erf", {1, 1}},   {"erfc", {1, 1}}};
        const auto arity = arities.find(name);
        if (arity == arities.end())
          refuse("function '" + name + "' is not compiled");
        std::vector<std::string> arguments;
        if (!accept(")"))
          {
            do
              arguments.push_back(ternary());
            while (accept(","));
            expect(")");
          }
        const int n = static_cast<int>(arguments.size());
        if (n < arity->second.first || n > arity->second.second)
          refuse("wrong number of arguments of '" + name + "'");
        // 'if' and 'int' are C++ keywords.
        std::string call =
          (name == "if" || name == "int" ? name + "_" : name) + "(";
        for (int i = 0; i < n; ++i)
          call += (i > 0 ? ", " : "") + arguments[i];
        return call + ")";
      }

      const std::string                    text;
      const std::vector<std::string>      &variables;
      const std::map<std::string, double> &constants;
      std::size_t                          position = 0;
      unsigned int                         depth    = 0;
    };



    /**
     * The generated source: the prelude, one function template per
     * expression, and the entry points (extern "C", so that dlsym finds
     * them by name) membranes_value_i, membranes_gradient_i and
     * membranes_laplacian_i, the latter two where requested.
     */
    std::string
    generate(const std::vector<CompiledFunctions::Request> &requests,
             const std::vector<std::string>                &variables,
             const std::map<std::string, double>           &constants)
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
              << Translator(requests[i].expression, variables, constants)
                   .translate()
              << "; }\n"
              << "extern \"C\" double membranes_value_" << s
              << "(const double *p) { return " << e << "(p); }\n";
          if (requests[i].gradient)
            out << "extern \"C\" void membranes_gradient_" << s
                << "(const double *p, double *g) {\n"
                << "  Dual<double> v[n];\n"
                << "  for (int d = 0; d < n; ++d) { v[d].v = p[d]; "
                   "v[d].d[d] = 1; }\n"
                << "  const Dual<double> r = " << e << "(v);\n"
                << "  for (int d = 0; d < n; ++d) g[d] = r.d[d];\n}\n";
          if (requests[i].laplacian)
            out << "extern \"C\" double membranes_laplacian_" << s
                << "(const double *p) {\n"
                << "  Dual<Dual<double>> v[n];\n"
                << "  for (int d = 0; d < n; ++d) { v[d].v.v = p[d]; "
                   "v[d].v.d[d] = 1; v[d].d[d].v = 1; }\n"
                << "  const Dual<Dual<double>> r = " << e << "(v);\n"
                << "  double laplacian = 0;\n"
                << "  for (int d = 0; d < n; ++d) laplacian += r.d[d].d[d];\n"
                << "  return laplacian;\n}\n";
        }
      return out.str();
    }



    /** The compiler: `MEMBRANES_CXX`, or the one that built the program. */
    std::string
    compiler()
    {
      const char *variable = std::getenv("MEMBRANES_CXX");
      return variable != nullptr && *variable != '\0' ? variable :
                                                        MEMBRANES_CXX_COMPILER;
    }

    const std::vector<std::string> compiler_flags{"-std=c++17",
                                                  "-O2",
                                                  "-fno-math-errno",
                                                  "-fPIC",
                                                  "-shared",
                                                  "-w"};

    /** FNV-1a, 64 bits, as 16 hexadecimal digits. */
    std::string
    hash(const std::string &text)
    {
      std::uint64_t h = 14695981039346656037ull;
      for (const unsigned char c : text)
        h = (h ^ c) * 1099511628211ull;
      std::ostringstream out;
      out << std::hex << std::setw(16) << std::setfill('0') << h;
      return out.str();
    }

    /**
     * What identifies the compiler in the cache key: its command, and the
     * size and time of modification of its file (when found), so that an
     * upgraded compiler compiles anew.
     */
    std::string
    compiler_identity(const std::string &command)
    {
      std::string identity = command;
      for (const auto &flag : compiler_flags)
        identity += " " + flag;
      struct stat status;
      if (stat(command.c_str(), &status) == 0)
        identity += " " + std::to_string(status.st_size) + " " +
                    std::to_string(status.st_mtime);
      return identity;
    }

    /**
     * Run @p arguments (no shell), its output to @p log; the exit status,
     * or -1 if it could not be started.
     */
    int
    run(const std::vector<std::string> &arguments, const std::string &log)
    {
      std::vector<char *> argv;
      for (const std::string &argument : arguments)
        argv.push_back(const_cast<char *>(argument.c_str()));
      argv.push_back(nullptr);
      posix_spawn_file_actions_t actions;
      posix_spawn_file_actions_init(&actions);
      posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
      posix_spawn_file_actions_addopen(
        &actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
      posix_spawn_file_actions_adddup2(&actions, 1, 2);
      pid_t     pid = 0;
      const int error =
        posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
      posix_spawn_file_actions_destroy(&actions);
      if (error != 0)
        return -1;
      int status = 0;
      while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR)
          return -1;
      return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }

    /** The first line of file @p name, if any. */
    std::string
    first_line(const std::string &name)
    {
      std::ifstream in(name);
      std::string   line;
      std::getline(in, line);
      return line;
    }

    /** Whether @p directory can be created (if needed) and written to. */
    bool
    usable(const std::filesystem::path &directory)
    {
      std::error_code error;
      std::filesystem::create_directories(directory, error);
      return std::filesystem::is_directory(directory, error) &&
             access(directory.c_str(), W_OK | X_OK) == 0;
    }

    /**
     * Compile @p source into the shared object @p target: under temporary
     * names of this process in the same directory, then renamed (atomic),
     * so that a concurrent run sees either no file or the whole one.
     */
    void
    compile(const std::string &source, const std::string &target)
    {
      std::random_device random;
      const std::string  stem = target + "." + std::to_string(getpid()) + "." +
                               std::to_string(random()) + ".tmp";
      const std::string source_file = stem + ".cc", object = stem + ".so",
                        log = stem + ".log";
      {
        std::ofstream out(source_file);
        out << source;
        if (!out.flush())
          throw CompiledFunctions::Unavailable(
            "cannot write the generated source '" + source_file + "'");
      }
      std::vector<std::string> command{compiler()};
      command.insert(command.end(),
                     compiler_flags.begin(),
                     compiler_flags.end());
      command.insert(command.end(), {source_file, "-o", object});
      const int         status  = run(command, log);
      const std::string message = first_line(log);
      std::remove(source_file.c_str());
      std::remove(log.c_str());
      if (status != 0 || std::rename(object.c_str(), target.c_str()) != 0)
        {
          std::remove(object.c_str());
          throw CompiledFunctions::Unavailable(
            "the C++ compiler '" + compiler() + "' " +
            (status < 0 ? std::string("could not be run") :
                          "failed (exit status " + std::to_string(status) +
                            (message.empty() ? "" : ": " + message) + ")") +
            "; set MEMBRANES_CXX to a working one");
        }
    }
  } // namespace



  std::string
  CompiledFunctions::cache_directory()
  {
    std::vector<std::filesystem::path> candidates;
    if (const char *variable = std::getenv("MEMBRANES_CACHE_DIR");
        variable != nullptr && *variable != '\0')
      candidates.emplace_back(variable);
    else
      {
        if (const char *xdg = std::getenv("XDG_CACHE_HOME");
            xdg != nullptr && *xdg == '/')
          candidates.emplace_back(std::filesystem::path(xdg) / "membranes");
        if (const char *home = std::getenv("HOME");
            home != nullptr && *home == '/')
          candidates.emplace_back(std::filesystem::path(home) / ".cache" /
                                  "membranes");
      }
    for (const auto &candidate : candidates)
      if (usable(candidate))
        return candidate.string();

    // A directory of this user only: another user could place an object
    // to be loaded in a directory that is not.
    std::error_code             error;
    const std::filesystem::path temporary =
      std::filesystem::temp_directory_path(error) /
      ("membranes-" + std::to_string(getuid()));
    mkdir(temporary.c_str(), 0700);
    struct stat status;
    if (!error && lstat(temporary.c_str(), &status) == 0 &&
        S_ISDIR(status.st_mode) && status.st_uid == getuid() &&
        (status.st_mode & 022) == 0 && usable(temporary))
      return temporary.string();
    throw Unavailable("no cache directory can be written (set "
                      "MEMBRANES_CACHE_DIR to one)");
  }



  CompiledFunctions::CompiledFunctions(
    const std::vector<Request>          &requests,
    const std::vector<std::string>      &variables,
    const std::map<std::string, double> &constants)
  {
    const auto        start  = std::chrono::steady_clock::now();
    const std::string source = generate(requests, variables, constants);
    const std::string target = cache_directory() + "/expressions-" +
                               hash(source + compiler_identity(compiler())) +
                               ".so";
    if (access(target.c_str(), R_OK) != 0)
      {
        compile(source, target);
        compiled_now = true;
      }
    handle = dlopen(target.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr && !compiled_now)
      {
        // A cached object that does not load (from another system, say):
        // compiled anew in its place.
        compile(source, target);
        compiled_now = true;
        handle       = dlopen(target.c_str(), RTLD_NOW | RTLD_LOCAL);
      }
    if (handle == nullptr)
      throw Unavailable("cannot load '" + target + "': " + dlerror());
    seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
        .count();
  }



  CompiledFunctions::~CompiledFunctions()
  {
    dlclose(handle);
  }



  void *
  CompiledFunctions::symbol(const std::string &name) const
  {
    void *address = dlsym(handle, name.c_str());
    if (address == nullptr)
      throw Unavailable("the compiled expressions have no '" + name + "'");
    return address;
  }



  CompiledFunctions::Value
  CompiledFunctions::value(const unsigned int i) const
  {
    return reinterpret_cast<Value>(
      symbol("membranes_value_" + std::to_string(i)));
  }



  CompiledFunctions::Gradient
  CompiledFunctions::gradient(const unsigned int i) const
  {
    return reinterpret_cast<Gradient>(
      symbol("membranes_gradient_" + std::to_string(i)));
  }



  CompiledFunctions::Value
  CompiledFunctions::laplacian(const unsigned int i) const
  {
    return reinterpret_cast<Value>(
      symbol("membranes_laplacian_" + std::to_string(i)));
  }
} // namespace membranes
