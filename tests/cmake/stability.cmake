# The stability suite: scale invariance, extreme tension ratios, degenerate
# complementarity, contact at the boundary, graded meshes, and a cycle that
# does not converge.

# The stability suite: scenes in parameters/stability and the shipped
# full-contact and no-contact scenes; benchmarks/stability.sh runs the same
# cases further and prints one table.

# Scale invariance: case M with the loads and g multiplied by S = 1e8 and
# 1e-8, and with (mu1, mu2) = (1, 2) multiplied by 1e8 and 1e-8 (the loads
# of case M are written with mu1 and mu2, so they scale along and u does
# not change). The active set method decides relative to the data, so every
# run makes the same decisions as the unscaled one: equal active set
# iterations and active vertices on every cycle, and the same active set at
# every vertex of the last cycle (rtol 0). Catches: an absolute tolerance
# anywhere in the active set test or the stopping test.
#
# stability_case_m(NAME [settings...])
function(stability_case_m name)
  set(expected)
  if(name STREQUAL "unscaled")
    set(expected EXPECTED)
  endif()
  membranes_scene_test(stability_case_m_${name} ${STABILITY}/case-m.prm
    ${expected}
    SETTINGS ${ARGN} Refinement/Cycles=5 Output/Write\ vtu=false
             Output/Write\ nodal\ values=true
    CHECKS ${NESTED_ITERATION})
  if(name STREQUAL "unscaled")
    return()
  endif()
  set(runs stability_case_m_unscaled stability_case_m_${name})
  membranes_compare(stability_case_m_${name}_same_decisions ${runs}
    COLUMNS dofs,active_set_iterations,active_vertices RTOL 0)
  membranes_compare(stability_case_m_${name}_same_active_set ${runs}
    FILE nodal-values-04.csv COLUMNS x,y,active_set RTOL 0)
endfunction()
stability_case_m(unscaled)
stability_case_m(loads_1e8 "Problem/Function constants=R=0.5, S=1e8")
stability_case_m(loads_1e-8 "Problem/Function constants=R=0.5, S=1e-8")
stability_case_m(tensions_1e8 Problem/mu1=1e8 Problem/mu2=2e8)
stability_case_m(tensions_1e-8 Problem/mu1=1e-8 Problem/mu2=2e-8)

# Tension ratios mu1/mu2 = 1e-8 and 1e8 on case M (exact for every mu1,
# mu2): converged, and the optimal rates. Catches: a loss of accuracy of
# the softer membrane.
foreach(mu1 1e-8 1e8)
  membranes_scene_test(stability_case_m_ratio_${mu1} ${STABILITY}/case-m.prm
    SETTINGS Problem/mu1=${mu1} Problem/mu2=1 Refinement/Cycles=5
             Output/Write\ vtu=false
    CHECKS ${DISPLACEMENT_RATES} ${NESTED_ITERATION})
endforeach()

# Iterative solves at extreme tension ratios and data scales, on the hard
# class for the active set method: a degenerate straight free boundary
# (stability/degenerate-straight.prm), Linear solver = cg-amg from the
# first cycle (auto would take the direct solver at these sizes), both cell
# types (to 33 282 DoFs). Each variant (mu1/mu2 = 1e8, 1e-8, data x 1e8,
# 1e-8) converges with at most 4 iterations per cycle after the first and
# at most one active set iteration more than the ratio 1 run on each cycle
# (catches linear tolerances on the scale of one membrane only: with the
# linear tolerance on the scale of the stiffer membrane, mu1/mu2 = 1e-8 did
# not converge within 100 iterations on cycle 3 of P1 and cycle 4 of Q1).
# The decoupled method (the default) runs every variant; the coupled one
# the ratio 1 run and the ratio that failed. The ratio 1e-8 runs of both
# methods have the errors of the direct solver's run to 1e-6 relative
# (measured: at most 4e-8 on err_u1_L2, whose size is 1e-4 max|u_h|, from
# solves to the KKT tolerance 1e-10); the ratio 1 runs have expected
# values.
set(STRAIGHT ${STABILITY}/degenerate-straight.prm)
set(STRAIGHT_ratio_1 "Problem/mu1=1")
set(STRAIGHT_ratio_1e8 "Problem/mu1=1e8")
set(STRAIGHT_ratio_1e-8 "Problem/mu1=1e-8")
foreach(scale 1e8 1e-8)
  set(STRAIGHT_data_${scale}
    "Problem/Function constants=x0=0.333333333333333333, L=8, S=${scale}")
endforeach()
set(STRAIGHT_VARIANTS_decoupled ratio_1 ratio_1e8 ratio_1e-8 data_1e8
  data_1e-8)
set(STRAIGHT_VARIANTS_coupled ratio_1 ratio_1e-8)
foreach(cell_type triangle quadrilateral)
  set(cycles 5)
  if(cell_type STREQUAL "quadrilateral")
    set(cycles 6)
  endif()
  foreach(method decoupled coupled)
    set(prefix stability_straight_${cell_type}_${method})
    foreach(name ${STRAIGHT_VARIANTS_${method}})
      set(solvers cg-amg)
      set(expected)
      if(name STREQUAL "ratio_1e-8")
        set(solvers cg-amg direct)
      elseif(name STREQUAL "ratio_1")
        set(expected EXPECTED)
      endif()
      foreach(solver ${solvers})
        membranes_scene_test(${prefix}_${name}_${solver} ${STRAIGHT}
          ${expected}
          SETTINGS ${STRAIGHT_${name}} Geometry/Cell\ type=${cell_type}
                   Solver/Method=${method} Solver/Linear\ solver=${solver}
                   Refinement/Cycles=${cycles} Output/Write\ vtu=false
          CHECKS ${NESTED_ITERATION})
      endforeach()
      if(name STREQUAL "ratio_1e-8")
        membranes_compare(${prefix}_${name}_errors_as_direct
          ${prefix}_${name}_direct ${prefix}_${name}_cg-amg
          COLUMNS ${ERRORS} RTOL 1e-6)
      endif()
      if(NOT name STREQUAL "ratio_1")
        membranes_compare(${prefix}_${name}_iterations
          ${prefix}_ratio_1_cg-amg ${prefix}_${name}_cg-amg
          COLUMNS active_set_iterations RTOL 0 ATOL 1 ONE_SIDED)
      endif()
    endforeach()
  endforeach()
endforeach()

# Degenerate complementarity: lambda = 0 and u1 - u2 = 0 on the left half.
# Its vertices keep their status (the plain test flipped them on round-off
# for ever); observed: one active set iteration on every cycle. Catches: a
# test that flips vertices on round-off.
membranes_scene_test(stability_degenerate ${STABILITY}/degenerate.prm
  SETTINGS Refinement/Cycles=5 Output/Write\ vtu=false
  CHECKS ${DISPLACEMENT_RATES} --max active_set_iterations<=2)

# Contact reaching the boundary (g = 0), and many contact islands: expected
# active sets and iterations (no exact solution).
membranes_scene_test(stability_g_zero ${STABILITY}/g-zero.prm EXPECTED
  SETTINGS Refinement/Cycles=5 Output/Write\ vtu=false
  CHECKS ${NESTED_ITERATION})
membranes_scene_test(stability_islands ${STABILITY}/islands.prm EXPECTED
  SETTINGS Refinement/Cycles=6 Output/Write\ vtu=false
  CHECKS ${NESTED_ITERATION})

# A mesh graded over many levels towards a singular load: at least 15
# levels on the last cycle (observed 22 on cycle 19, 19 160 DoFs).
# Catches: refinement that stops following the singularity.
membranes_scene_test(stability_graded ${STABILITY}/graded.prm
  SETTINGS Output/Write\ vtu=false
  CHECKS ${NESTED_ITERATION} --hanging-nodes 3 --min-last levels>=15)

# No convergence within Solver/Max active set iterations: one error line
# naming the entry and the residual reached, exit status 1, the rows of the
# converged cycles kept, no row and no result file for the failed cycle,
# its last iterate in unconverged/. The contact-at-the-boundary scene needs
# 3 iterations on cycle 3 and 2 before. Catches: a failed cycle that
# writes a row or results, or loses those of the cycles before.
add_test(NAME stability_unconverged.run
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/run_failing_scene.py
          ${CMAKE_CURRENT_BINARY_DIR}/stability_unconverged
          "Solver/Max active set iterations = 2|cycle 3|relative KKT residual|unconverged"
          $<TARGET_FILE:membranes> --set Solver/Max\ active\ set\ iterations=2
          --set Refinement/Cycles=5 ${STABILITY}/g-zero.prm)
set_tests_properties(stability_unconverged.run
  PROPERTIES FIXTURES_SETUP stability_unconverged LABELS quick)
add_test(NAME stability_unconverged.check
  COMMAND ${CHECK} ${CMAKE_CURRENT_BINARY_DIR}/stability_unconverged/report.csv
          --rows 3)
add_test(NAME stability_unconverged.files
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/check_output_files.py
          ${CMAKE_CURRENT_BINARY_DIR}/stability_unconverged
          --present solution-02.vtu --absent solution-03.vtu
          --present unconverged/solution-03.vtu
          --present unconverged/nodal-values-03.csv
          --absent *.tmp --absent unconverged/*.tmp)
set_tests_properties(stability_unconverged.check stability_unconverged.files
  PROPERTIES FIXTURES_REQUIRED stability_unconverged LABELS quick)

# The same on two processes: the decision is global, so the program ends
# with one error line and exit status 1 from every process (no MPI_Abort),
# and the last iterate is a .pvtu record with its pieces.
set(unconverged_np2 ${CMAKE_CURRENT_BINARY_DIR}/stability_unconverged_np2)
add_test(NAME stability_unconverged_np2.run
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/run_failing_scene.py
          ${unconverged_np2}
          "Solver/Max active set iterations = 2|cycle 3|solution-03.pvtu"
          --launcher ${DEAL_II_MPIEXEC} ${DEAL_II_MPIEXEC_NUMPROC_FLAG} 2 --
          $<TARGET_FILE:membranes> --set Solver/Max\ active\ set\ iterations=2
          --set Refinement/Cycles=5 ${STABILITY}/g-zero.prm)
set_tests_properties(stability_unconverged_np2.run PROPERTIES
  FIXTURES_SETUP stability_unconverged_np2 PROCESSORS 2
  ENVIRONMENT "${MPI_ROOT_ENVIRONMENT}")
add_test(NAME stability_unconverged_np2.files
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/check_output_files.py
          ${unconverged_np2} --present unconverged/solution-03.pvtu
          --present unconverged/solution-03.0001.vtu
          --present unconverged/nodal-values-03.csv --absent solution-03.pvtu)
set_tests_properties(stability_unconverged_np2.files
  PROPERTIES FIXTURES_REQUIRED stability_unconverged_np2)
