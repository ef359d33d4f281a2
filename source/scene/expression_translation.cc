#include <cctype>
#include <cmath>
#include <locale>
#include <membranes/scene/expression_translation.h>
#include <sstream>

namespace membranes
{
  namespace
  {
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
        const std::string condition = logical(&Translator::logical_and, "||");
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
  } // namespace



  std::string
  translate_expression(const std::string                   &text,
                       const std::vector<std::string>      &variables,
                       const std::map<std::string, double> &constants)
  {
    return Translator(text, variables, constants).translate();
  }
} // namespace membranes
