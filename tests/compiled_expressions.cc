// The compiled expressions (CompiledFunctions) against deal.II's
// FunctionParser, on expressions that use every operator and function of
// the grammar: the same values to round-off (1e-13 relative) at a few
// points; and their derivatives by dual numbers against finite differences
// of the values: gradients to 1e-6, Laplacians to 1e-4 relative to the
// size of the second derivatives (the error of the differences). Then all
// of them as one group, at all points in one call, against the functions
// of each expression: the same numbers, in the group's order, to 1e-14.

#include <deal.II/base/function_parser.h>
#include <deal.II/base/mpi.h>
#include <iostream>
#include <membranes/compiled_function.h>
#include <muParser.h>

using namespace dealii;

int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  // The constants of the scene, and those muparser defines (_pi, _e).
  std::map<std::string, double> constants{{"pi", numbers::PI},
                                          {"R", 0.5},
                                          {"mu1", 2.}};
  const mu::Parser              muparser;
  for (const auto &[name, value] : muparser.GetConst())
    constants[name] = value;
  const std::vector<std::string> expressions{
    "1 + 2*x - y/3 + -x*-y",
    "-x^2 + 2^-y^2 + (2+x)^3^0.5 - (x+2)^-3 + (1+y)^2.5",
    "x > 0.1 ? x*y : y > 0 ? 1 : 2",
    "(x < y) + (x <= y) + 2*(x > y) + 4*(x >= y) + 8*(x == x) + (x != y)",
    "(x > 0 && y > 0) + 2*(x > 0 || y > 0) + 4*(x | y) + 8*(x & 0.3)",
    "sin(x) + cos(y) + tan(x*y) + asin(x/2) + acos(y/2) + atan(x)",
    "sinh(x) + cosh(y) + tanh(x) + asinh(y) + acosh(2 + x) + atanh(y/2)",
    "atan2(y, x) + log2(2+x) + log10(2+y) + log(2+x) + ln(3+y) + exp(x*y)",
    "sqrt(2 + x) + sign(y) + rint(3*x) + abs(x - y) + int(4*y)",
    "min(x, y, 0.2) + max(x, y) + sum(x, y, 1) + avg(x, y)",
    "if(x - y, x, y) + ceil(3*x) + floor(3*y) + cot(1+x) + csc(1+y)",
    "sec(x) + pow(2 + x, y) + pow(x*x, 1.5) + erfc(x) + _pi*R + mu1*pi + _e",
    "-mu1*(1 - x^2 - y^2)^3 * (x^2 + y^2 > R^2 ? 1 : 0) + 1e-3*.5/2.",
    "cos(pi*x/2)*cos(pi*y/2) + ((x-0.2)^2 + (y+0.1)^2 - R^2)^3"};
  const std::vector<Point<2>> points{Point<2>(0.3, -0.7),
                                     Point<2>(-0.45, 0.61),
                                     Point<2>(0.77, 0.12)};

  // Every expression with both derivatives; in the group, the members ask
  // for none, the gradient, the Laplacian or both, in turn.
  std::vector<membranes::CompiledFunctions::Request> requests;
  membranes::CompiledFunctions::Group                group;
  for (unsigned int i = 0; i < expressions.size(); ++i)
    {
      requests.push_back({expressions[i], true, true});
      group.push_back({i, i % 2 == 1, i % 4 >= 2});
    }
  const membranes::CompiledFunctions compiled(requests,
                                              {"x", "y"},
                                              constants,
                                              {group});

  unsigned int failures = 0;
  const auto   compare  = [&](const std::string &what,
                           const std::string &expression,
                           const Point<2>    &p,
                           const double       a,
                           const double       b,
                           const double       tolerance) {
    if (!(std::abs(a - b) <= tolerance))
      {
        ++failures;
        std::cout << "FAIL " << what << " of '" << expression << "' at " << p
                  << ": " << a << " against " << b << std::endl;
      }
  };
  for (unsigned int i = 0; i < expressions.size(); ++i)
    {
      FunctionParser<2> parser(1);
      parser.initialize("x,y",
                        expressions[i],
                        {{"pi", numbers::PI}, {"R", 0.5}, {"mu1", 2.}});
      for (const Point<2> &p : points)
        {
          const double value = compiled.value(i)(&p[0]);
          compare("value",
                  expressions[i],
                  p,
                  value,
                  parser.value(p),
                  1e-13 * std::max(1., std::abs(value)));
          double gradient[2];
          compiled.gradient(i)(&p[0], gradient);
          double     laplacian = 0, scale = 1;
          const auto f = [&](const Point<2> &q) {
            return compiled.value(i)(&q[0]);
          };
          for (unsigned int d = 0; d < 2; ++d)
            {
              Tensor<1, 2> e;
              e[d]           = 1;
              const double h = 1e-6, H = 1e-3;
              compare("derivative " + std::to_string(d),
                      expressions[i],
                      p,
                      gradient[d],
                      (f(p + h * e) - f(p - h * e)) / (2 * h),
                      1e-6 * std::max(1., std::abs(gradient[d])));
              const double second =
                (f(p + H * e) - 2 * f(p) + f(p - H * e)) / (H * H);
              laplacian += second;
              scale += std::abs(second);
            }
          compare("Laplacian",
                  expressions[i],
                  p,
                  compiled.laplacian(i)(&p[0]),
                  laplacian,
                  1e-4 * scale);
        }
    }

  std::vector<double> group_values(points.size() * 4 * expressions.size());
  compiled.group(0)(&points[0][0], points.size(), group_values.data());
  const double *group_value = group_values.data();
  for (const Point<2> &p : points)
    for (const auto &member : group)
      {
        const std::string &expression = expressions[member.expression];
        const auto same = [&](const std::string &what, const double expected) {
          compare("group " + what,
                  expression,
                  p,
                  *group_value++,
                  expected,
                  1e-14 * std::max(1., std::abs(expected)));
        };
        same("value", compiled.value(member.expression)(&p[0]));
        if (member.gradient)
          {
            double gradient[2];
            compiled.gradient(member.expression)(&p[0], gradient);
            same("derivative 0", gradient[0]);
            same("derivative 1", gradient[1]);
          }
        if (member.laplacian)
          same("Laplacian", compiled.laplacian(member.expression)(&p[0]));
      }

  std::cout << (failures == 0 ? "PASS" : "FAIL") << ": " << expressions.size()
            << " expressions at " << points.size() << " points, "
            << (compiled.compiled_now ? "compiled" : "from the cache") << " in "
            << compiled.seconds << " s" << std::endl;
  return failures == 0 ? 0 : 1;
}
