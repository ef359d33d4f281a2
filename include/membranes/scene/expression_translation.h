#ifndef membranes_expression_translation_h
#define membranes_expression_translation_h

#include <map>
#include <membranes/scene/compiled_function.h>
#include <string>
#include <vector>

namespace membranes
{
  /**
   * The expression @p text, in the grammar of muparser 2.3 as deal.II's
   * FunctionParser sets it up, as a C++ expression of a number type T: the
   * variables @p variables become `v[0]`, `v[1]`, ... (of type T), the
   * @p constants their values, each operator and function the one of the
   * same name in the prelude of generated_source(), which has the semantics
   * of muparser and of deal.II's additions for double and for dual numbers
   * alike.
   *
   * The expression has been accepted by muparser before; what has no
   * compiled form (a function such as rand(), an unknown name) is refused
   * with CompiledFunctions::Unavailable.
   */
  std::string
  translate_expression(const std::string                   &text,
                       const std::vector<std::string>      &variables,
                       const std::map<std::string, double> &constants);

  /**
   * The C++ source that CompiledFunctions compiles for @p requests: the
   * prelude (the dual numbers of forward-mode differentiation and the
   * functions of the grammar), one function template per expression
   * (translate_expression()), and the entry points (extern "C", so that
   * dlsym finds them by name) membranes_value_i, membranes_gradient_i and
   * membranes_laplacian_i, the latter two where requested, and
   * membranes_group_g for each of @p groups.
   */
  std::string
  generated_source(const std::vector<CompiledFunctions::Request> &requests,
                   const std::vector<std::string>                &variables,
                   const std::map<std::string, double>           &constants,
                   const std::vector<CompiledFunctions::Group>   &groups);
} // namespace membranes

#endif
