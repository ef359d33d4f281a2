# The functions and check lists that the tests of every file use:
# membranes_scene_test (a scene and its checks), membranes_compare and
# membranes_compare_runs (two runs against each other), and the checks of
# rates, iterations and identities that many scenes share.

# membranes_scene_test(NAME SCENE [SETTINGS <Section/Entry=value>...]
#                      [CHECKS <check_report.py args>...]
#                      [FILES <check_output_files.py args>...]
#                      [PROCESSES N] [EXPECTED] [QUICK])
# EXPECTED adds NAME.expected (label expected); QUICK puts the scene's
# tests in the label quick.
function(membranes_scene_test name scene)
  cmake_parse_arguments(ARG "EXPECTED;QUICK" "PROCESSES"
    "SETTINGS;CHECKS;FILES" ${ARGN})
  set(outdir ${CMAKE_CURRENT_BINARY_DIR}/${name})
  set(settings)
  foreach(setting ${ARG_SETTINGS})
    list(APPEND settings --set ${setting})
  endforeach()
  if(NOT IS_ABSOLUTE ${scene})
    set(scene ${SCENES}/${scene})
  endif()
  set(launcher)
  if(ARG_PROCESSES)
    set(launcher --launcher ${DEAL_II_MPIEXEC} ${DEAL_II_MPIEXEC_NUMPROC_FLAG}
                 ${ARG_PROCESSES} --)
  endif()
  add_test(NAME ${name}.run
    COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/run_scene.py
            ${outdir} ${launcher} $<TARGET_FILE:membranes> ${settings} ${scene})
  set_tests_properties(${name}.run PROPERTIES FIXTURES_SETUP ${name})
  if(ARG_PROCESSES)
    set_tests_properties(${name}.run PROPERTIES
      PROCESSORS ${ARG_PROCESSES} ENVIRONMENT "${MPI_ROOT_ENVIRONMENT}")
  endif()
  set(tests ${name}.run)
  if(ARG_EXPECTED)
    add_test(NAME ${name}.expected
      COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/check_expected.py
              ${outdir}/report.csv ${CMAKE_CURRENT_SOURCE_DIR}/expected/${name}.output)
    set_tests_properties(${name}.expected PROPERTIES
      FIXTURES_REQUIRED ${name} LABELS expected)
    list(APPEND tests ${name}.expected)
  endif()
  if(ARG_CHECKS)
    add_test(NAME ${name}.check
      COMMAND ${CHECK} ${outdir}/report.csv ${ARG_CHECKS})
    list(APPEND tests ${name}.check)
  endif()
  if(ARG_FILES)
    add_test(NAME ${name}.files
      COMMAND ${Python3_EXECUTABLE}
              ${CMAKE_CURRENT_SOURCE_DIR}/check_output_files.py ${outdir}
              ${ARG_FILES})
    list(APPEND tests ${name}.files)
  endif()
  foreach(test ${name}.check ${name}.files)
    if(test IN_LIST tests)
      set_tests_properties(${test} PROPERTIES FIXTURES_REQUIRED ${name})
    endif()
  endforeach()
  if(ARG_QUICK)
    set_property(TEST ${tests} APPEND PROPERTY LABELS quick)
  endif()
endfunction()

# membranes_compare(NAME A B COLUMNS c1,c2,... RTOL R [ATOL A] [FILE F]
#                   [EMPTY c1,c2,...] [SCALE column] [ONE_SIDED]),
# membranes_compare(NAME A B REPORT RTOL R FACTOR F):
# the file F (default report.csv) of the runs of the scene tests A and B
# agree in COLUMNS to the tolerances of compare_reports.py; EMPTY the
# columns expected empty in both. REPORT: every column of report.csv, as
# compare_reports.py --report classifies it (A on one process, B on more),
# values to R relative and round-off to F times its largest size in A.
function(membranes_compare name a b)
  cmake_parse_arguments(ARG "ONE_SIDED;REPORT"
    "COLUMNS;RTOL;ATOL;FILE;EMPTY;SCALE;FACTOR" "" ${ARGN})
  if(NOT ARG_FILE)
    set(ARG_FILE report.csv)
  endif()
  set(options --rtol ${ARG_RTOL})
  foreach(option COLUMNS ATOL EMPTY SCALE FACTOR)
    if(ARG_${option})
      string(TOLOWER ${option} flag)
      list(APPEND options --${flag} ${ARG_${option}})
    endif()
  endforeach()
  if(ARG_ONE_SIDED)
    list(APPEND options --one-sided)
  endif()
  if(ARG_REPORT)
    list(APPEND options --report)
  endif()
  add_test(NAME ${name}
    COMMAND ${COMPARE} ${CMAKE_CURRENT_BINARY_DIR}/${a}/${ARG_FILE}
            ${CMAKE_CURRENT_BINARY_DIR}/${b}/${ARG_FILE} ${options})
  set_tests_properties(${name} PROPERTIES FIXTURES_REQUIRED "${a};${b}")
endfunction()

# membranes_compare_runs(NAME A B CYCLES NODAL_RTOL [ERRORS c1,c2,...]
#                        [RTOL R]):
# the runs A and B (with Output/Write nodal values) solve the same discrete
# problems: with ERRORS, the same cells, dofs and active_vertices on every
# cycle (NAME_same_meshes) and ERRORS equal to R (default 1e-8) relative
# (NAME_same_errors); without, every column of report.csv (NAME_same_report,
# membranes_compare REPORT, A on one process); the same vertices and active
# set on the last cycle, and nodal values u1, u2, lambda_h equal to
# NODAL_RTOL relative to their max norm.
# Catches: a solver path, linear solver or process count that solves
# another discrete problem than its twin; with the whole report also a
# column computed from the wrong entries of a distributed vector
# (complementarity_defect, once read from a ghosted vector by owned
# position: 3e-3 to 9e-5 on two processes, 1e-17 to 1e-13 on one), and a
# column added to the report but to no kind of compare_reports.py.
function(membranes_compare_runs name a b cycles nodal_rtol)
  cmake_parse_arguments(ARG "" "ERRORS;RTOL" "" ${ARGN})
  if(NOT ARG_RTOL)
    set(ARG_RTOL 1e-8)
  endif()
  math(EXPR last "${cycles} - 1")
  if(last LESS 10)
    set(last 0${last})
  endif()
  set(nodal FILE nodal-values-${last}.csv)
  if(ARG_ERRORS)
    membranes_compare(${name}_same_meshes ${a} ${b}
      COLUMNS cells,dofs,active_vertices RTOL 0)
    membranes_compare(${name}_same_errors ${a} ${b}
      COLUMNS ${ARG_ERRORS} RTOL ${ARG_RTOL})
  else()
    membranes_compare(${name}_same_report ${a} ${b} REPORT RTOL ${ARG_RTOL}
      FACTOR 10)
  endif()
  membranes_compare(${name}_same_vertices ${a} ${b} ${nodal}
    COLUMNS x,y,active_set RTOL 0)
  membranes_compare(${name}_same_nodal_values ${a} ${b} ${nodal}
    COLUMNS u1,u2,lambda_h RTOL ${nodal_rtol} SCALE column)
endfunction()

set(ERRORS err_u1_H1,err_u2_H1,err_u1_L2,err_u2_L2,err_lambda_L2,err_lambda_L2_omega_h)

# Nested iteration: at most 4 active set iterations per cycle after the
# first. Catches: a cycle that does not start from the previous solution
# and active set (SolutionTransfer, the initial active set of a new mesh).
set(NESTED_ITERATION --max-after-first active_set_iterations<=4)

# Optimal rates for P1/Q1 on the last two cycles: H1 ~ h, L2 ~ h^2.
# Catches: a fault that leaves the first meshes plausible but spoils
# convergence (quadrature, boundary interpolation, a wrong load weight).
set(DISPLACEMENT_RATES
  --rate err_u1_H1>=0.95 --rate err_u2_H1>=0.95
  --rate err_u1_L2>=1.9 --rate err_u2_L2>=1.9)

# The flux estimator is an upper bound of the energy error, and within
# 1.1 of it on the finest mesh. Catches: a missing or mis-scaled part of
# the equilibrated flux sigma_ih or of the estimator's terms.
set(FLUX_EFFECTIVITY
  --min flux_effectivity>=1 --max-last flux_effectivity<=1.1)

# The identities of the flux reconstruction t_ih (Output/Flux
# reconstruction) on triangles, to round-off relative to d_a and to the
# force scale of (4.5): (4.17) meas(D_a) = d_a, (4.18) and the balance of
# Lemma 17 (observed <= 7e-16). Catches: a wrong dual cell, sub-triangle
# or normal flux of (4.13).
set(FLUX_IDENTITIES
  --max measure_defect<=1e-12
  --max conservation_defect<=1e-12
  --max balance_defect<=1e-12)

# Adaptive refinement: the effectivity index eta/|||e||| stays in a band
# max/min <= 2 (catches an estimator term with a wrong power of h), the
# last three meshes have hanging nodes (catches marking that refines
# everything), the energy error decreases.
set(ADAPTIVE_CHECKS
  --band effectivity<=2
  --hanging-nodes 3
  --decreasing err_energy)
