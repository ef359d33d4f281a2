# Exact gradients, and the expressions of the scenes compiled into C++
# against deal.II's FunctionParser.

# Exact gradients (Exact solution/u1 gradient and u2 gradient, which the
# scenes with an exact solution give for the H1 errors): case M with the
# gradients of its scene and with central finite differences of u1 and u2
# (the entries emptied) has the same H1 errors on every cycle, to the
# accuracy of the differences (measured: 1.9e-9 relative here, at most
# 3.7e-9 on the shipped scenes; bound 1e-7). Catches: a wrong derivative
# in the scene, which changes them at O(1).
foreach(gradient exact differences)
  set(settings)
  if(gradient STREQUAL "differences")
    set(settings Exact\ solution/u1\ gradient= Exact\ solution/u2\ gradient=)
  endif()
  membranes_scene_test(gradient_${gradient} case-m-quadrilateral.prm
    SETTINGS Refinement/Cycles=5 Output/Write\ vtu=false ${settings})
endforeach()
membranes_compare(gradient_exact_vs_differences gradient_exact
  gradient_differences COLUMNS err_u1_H1,err_u2_H1 RTOL 1e-7)

# Compiled expressions (Problem/Expression evaluation = compiled, the
# default auto where a compiler works) against the parser: every shipped
# scene on a few cycles, with every column of report.csv that is not a
# time. Each run is short (3 cycles, 4 on adaptive scenes). Catches: a
# compiled load, boundary value or exact solution that differs from the
# parser's.
# - The meshes, decisions and errors to 1e-10 relative: the compiled code
#   evaluates the same operations as muparser, except integer powers, which
#   it multiplies out (a few units in the last place); with the gradients
#   of the exact solution by dual numbers where the parser takes the
#   scene's gradient entries or finite differences (those differ at 1e-9,
#   see gradient_exact_vs_differences: the H1 errors are compared to 1e-7
#   where the scene has no gradient entries).
# - The quantities near round-off (min_w, min_lambda, the identity
#   defects) to 1e-10 absolute: absolute values of size 1 of the data. (The
#   KKT residual and the defects of Prop. 12 and (4.8) are not compared:
#   both runs bound them by Solver/Tolerance = 1e-10, so they always agree
#   to 1e-10.)
set(EVALUATION_VALUES_COLUMNS
  cycle,cells,dofs,levels,active_set_iterations,active_vertices,processes,err_u1_L2,err_u2_L2,err_lambda_L2,err_lambda_L2_omega_h,estimator,flux_estimator,flux_estimator_flux,flux_estimator_oscillation,flux_estimator_contact,flux_estimator_boundary,eta_linearization,eta_algebraic)
set(EVALUATION_H1_COLUMNS
  err_u1_H1,err_u2_H1,err_energy,effectivity,flux_effectivity)
set(EVALUATION_ROUND_OFF_COLUMNS
  min_w,min_lambda,measure_defect,conservation_defect,balance_defect)

# What a scene does not compute, and its evaluation comparison names as
# empty in both runs (compare_reports.py --empty): the flux estimator
# (Refinement/Estimator = flux), the identity defects of the flux
# reconstruction (Output/Flux reconstruction, in no shipped scene), eta_lin
# and eta_alg (Solver/Stopping = balanced, in none), the errors (no exact
# solution), and the residual estimator of a uniform run without one.
set(EMPTY_FLUX flux_estimator flux_estimator_flux flux_estimator_oscillation
  flux_estimator_contact flux_estimator_boundary flux_effectivity)
set(EMPTY_NOT_SHIPPED eta_linearization eta_algebraic measure_defect
  conservation_defect balance_defect)
set(EMPTY_ERRORS err_u1_L2 err_u2_L2 err_lambda_L2 err_lambda_L2_omega_h
  err_u1_H1 err_u2_H1 err_energy effectivity flux_effectivity)
set(EMPTY_RESIDUAL_FLUX ${EMPTY_FLUX} ${EMPTY_NOT_SHIPPED})
set(EMPTY_FLUX_ESTIMATOR ${EMPTY_NOT_SHIPPED})
set(EMPTY_UNKNOWN_ADAPTIVE ${EMPTY_ERRORS} ${EMPTY_FLUX} ${EMPTY_NOT_SHIPPED})
set(EMPTY_UNKNOWN_UNIFORM estimator ${EMPTY_UNKNOWN_ADAPTIVE})

# membranes_compare_columns(OUT COLUMNS EMPTY): the arguments of
# membranes_compare for the comma separated COLUMNS: those of the list
# EMPTY as EMPTY (expected empty), the others as COLUMNS (compared).
function(membranes_compare_columns out columns empty)
  string(REPLACE "," ";" columns "${columns}")
  set(compared)
  set(expected)
  foreach(column ${columns})
    if(column IN_LIST empty)
      list(APPEND expected ${column})
    else()
      list(APPEND compared ${column})
    endif()
  endforeach()
  set(arguments)
  foreach(option COLUMNS EMPTY)
    set(names ${compared})
    if(option STREQUAL "EMPTY")
      set(names ${expected})
    endif()
    if(names)
      string(REPLACE ";" "," names "${names}")
      list(APPEND arguments ${option} ${names})
    endif()
  endforeach()
  set(${out} ${arguments} PARENT_SCOPE)
endfunction()

# membranes_evaluation_comparison(NAME SCENE CYCLES H1_RTOL
#                                 [PARSER_SCENE scene] [EMPTY columns...]
#                                 [settings...]):
# SCENE compiled against PARSER_SCENE (default SCENE) with the parser;
# EMPTY the columns the scene does not compute.
function(membranes_evaluation_comparison name scene cycles h1_rtol)
  cmake_parse_arguments(ARG "" "PARSER_SCENE" "EMPTY" ${ARGN})
  if(NOT ARG_PARSER_SCENE)
    set(ARG_PARSER_SCENE ${scene})
  endif()
  foreach(evaluation compiled parser)
    set(this_scene ${scene})
    if(evaluation STREQUAL "parser")
      set(this_scene ${ARG_PARSER_SCENE})
    endif()
    membranes_scene_test(evaluation_${name}_${evaluation} ${this_scene}
      SETTINGS Problem/Expression\ evaluation=${evaluation}
               Refinement/Cycles=${cycles} Output/Write\ vtu=false
               ${ARG_UNPARSED_ARGUMENTS})
  endforeach()
  set(runs evaluation_${name}_compiled evaluation_${name}_parser)
  foreach(part values h1 round_off)
    string(TOUPPER ${part} PART)
    membranes_compare_columns(columns "${EVALUATION_${PART}_COLUMNS}"
      "${ARG_EMPTY}")
    set(tolerances RTOL 1e-10)
    if(part STREQUAL "h1")
      set(tolerances RTOL ${h1_rtol})
    elseif(part STREQUAL "round_off")
      set(tolerances RTOL 1e-10 ATOL 1e-10)
    endif()
    membranes_compare(evaluation_${name}_same_${part} ${runs} ${columns}
      ${tolerances})
  endforeach()
endfunction()

# Global refinement (3 cycles) and adaptive (4); scenes with gradient
# entries, and those without; by what they compute: the residual
# estimator, also the flux estimator, no exact solution.
foreach(group
    "3;1e-10;RESIDUAL_FLUX;case-m-gmsh-triangles;case-m-quadrilateral;case-m-triangle;full-contact"
    "4;1e-10;RESIDUAL_FLUX;default;lshape;slit"
    "4;1e-10;FLUX_ESTIMATOR;disk-contact;straight-free-boundary"
    "3;1e-7;RESIDUAL_FLUX;no-contact;stability/case-m;stability/degenerate;stability/degenerate-straight"
    "3;1e-7;UNKNOWN_UNIFORM;stability/g-zero;stability/islands"
    "4;1e-7;UNKNOWN_ADAPTIVE;own-scene;stability/graded")
  list(POP_FRONT group cycles h1_rtol empty)
  foreach(scene ${group})
    string(REGEX REPLACE "[/-]" "_" name ${scene})
    membranes_evaluation_comparison(${name} ${scene}.prm ${cycles} ${h1_rtol}
      EMPTY ${EMPTY_${empty}})
  endforeach()
endforeach()

# Manufactured data (Exact solution/Manufactured data): the loads and
# boundary heights derived from u1, u2, lambda by the compiled code equal
# those written out by hand (with the parser), and the scenes that use it
# converge at the optimal rates (catches a wrong derivative in the
# manufactured loads).
membranes_evaluation_comparison(shifted_circle shifted-circle.prm 3 1e-7
  PARSER_SCENE ${CMAKE_CURRENT_SOURCE_DIR}/scenes/shifted-circle-loads.prm
  EMPTY ${EMPTY_RESIDUAL_FLUX})
membranes_evaluation_comparison(degenerate_free_boundary
  degenerate-free-boundary.prm 3 1e-10
  PARSER_SCENE ${CMAKE_CURRENT_SOURCE_DIR}/scenes/degenerate-free-boundary-loads.prm
  EMPTY ${EMPTY_RESIDUAL_FLUX})
membranes_scene_test(shifted_circle shifted-circle.prm
  SETTINGS Refinement/Cycles=5 Output/Write\ vtu=false
  CHECKS ${DISPLACEMENT_RATES} --rate err_lambda_L2>=0.9 ${NESTED_ITERATION})

# Without a working compiler: auto evaluates with the parser and says so
# in one line (the same report as compiled), compiled is refused in one
# line before any cycle. Catches: a silent fallback, or a run that starts
# without the compiler it was told to use.
membranes_scene_test(evaluation_fallback_auto case-m-triangle.prm
  SETTINGS Refinement/Cycles=3 Output/Write\ vtu=false)
set_tests_properties(evaluation_fallback_auto.run PROPERTIES
  ENVIRONMENT MEMBRANES_CXX=/bin/false
  PASS_REGULAR_EXPRESSION
  "Note: Problem/Expression evaluation = auto: the C\\+\\+ compiler '/bin/false' failed[^\n]*; the parser evaluates the expressions\nCycle 0")
membranes_compare_columns(fallback_columns
  "${EVALUATION_VALUES_COLUMNS},${EVALUATION_H1_COLUMNS}" "${EMPTY_RESIDUAL_FLUX}")
membranes_compare(evaluation_fallback_auto_same_values
  evaluation_fallback_auto evaluation_case_m_triangle_parser
  ${fallback_columns} RTOL 0)
add_test(NAME evaluation_fallback_compiled
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/run_failing_scene.py
          ${CMAKE_CURRENT_BINARY_DIR}/evaluation_fallback_compiled
          "Problem/Expression evaluation = 'compiled'|no-such-compiler|could not be run|auto or parser"
          $<TARGET_FILE:membranes> --set Problem/Expression\ evaluation=compiled
          ${SCENES}/case-m-triangle.prm)
add_test(NAME evaluation_fallback_manufactured
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/run_failing_scene.py
          ${CMAKE_CURRENT_BINARY_DIR}/evaluation_fallback_manufactured
          "Exact solution/Manufactured data|no-such-compiler"
          $<TARGET_FILE:membranes> ${SCENES}/shifted-circle.prm)
set_tests_properties(evaluation_fallback_compiled
                     evaluation_fallback_manufactured PROPERTIES
  ENVIRONMENT MEMBRANES_CXX=${CMAKE_CURRENT_BINARY_DIR}/no-such-compiler
  LABELS quick)
