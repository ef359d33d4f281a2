# Small programs on the library (label quick).

# Unit tests (label quick): small programs on the library.
# membranes_unit_test(NAME): tests/NAME.cc, run as the test NAME.
function(membranes_unit_test name)
  add_executable(${name} ${name}.cc)
  target_link_libraries(${name} membranes_lib)
  deal_ii_setup_target(${name})
  target_precompile_headers(${name} REUSE_FROM membranes_lib)
  add_test(NAME ${name} COMMAND ${name})
  set_tests_properties(${name} PROPERTIES LABELS quick)
endfunction()

# Cycling of the active set method and its remedy (ActiveSetHistory), on a
# 3x3 complementarity problem with a symmetric positive definite matrix on
# which the plain method cycles. Catches: a history that does not detect
# the cycle, or stops elsewhere than at the solution.
membranes_unit_test(active_set_cycles)

# What the history takes for a cycle (ActiveSetHistory): a set visited
# before over all processes, on one and on two processes. Catches: a
# fingerprint of the size of the set alone (a new set of the same size taken
# for a cycle), or of a process's own part alone.
membranes_unit_test(active_set_history)
add_test(NAME active_set_history_np2
  COMMAND ${DEAL_II_MPIEXEC} ${DEAL_II_MPIEXEC_NUMPROC_FLAG} 2
          $<TARGET_FILE:active_set_history>)
set_tests_properties(active_set_history_np2 PROPERTIES PROCESSORS 2
  ENVIRONMENT "${MPI_ROOT_ENVIRONMENT}" LABELS quick)

# The discrete identities on three tiny meshes (2x2 Q1, one hanging node,
# four triangles) against values computed by hand: d_a, c_a, lambda_a of
# (4.5) from both membranes and their weighted mean, Prop. 12, (4.8),
# (4.17), (4.18) and Lemma 17. Catches: a wrong d_a (a factor, the shares
# of hanging vertices), c_a, weight or sign in (4.5), dual cell or flux.
membranes_unit_test(discrete_identities)

# The H^{-1} norm of (4.20) through the Riesz representative of degree 2
# (the column err_lambda_Hm1): sin(pi x) sin(pi y) on the unit square
# against its closed form, on squares and triangles, and a density with
# the jumps of lambda - lambda_h against degree 3. Catches: a wrong inner
# product (seminorm for norm), boundary condition, quadrature of the
# density or lookup of lambda_h on the pieces of the dual cells.
membranes_unit_test(negative_norm)

# The translation of expressions into C++ (CompiledFunctions): every
# operator and function of the grammar gives deal.II's FunctionParser's
# values to round-off, and derivatives by dual numbers that agree with
# finite differences. Catches: a wrong translation or derivative rule.
membranes_unit_test(compiled_expressions)
