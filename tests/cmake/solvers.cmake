# The linear solvers, the coupled and decoupled methods and the stopping
# tests: each pair solves the same discrete problem, to stated tolerances.

# The direct (Trilinos Amesos) and iterative (CG + AMG, forced at these
# sizes) linear solvers give the same discrete solution: same active sets,
# errors equal to 1e-8. Catches: a CG tolerance on the wrong scale.
foreach(solver direct cg-amg)
  membranes_scene_test(solver_${solver} case-m-triangle.prm
    SETTINGS Refinement/Cycles=5 Solver/Linear\ solver=${solver}
             Output/Write\ vtu=false
    CHECKS ${NESTED_ITERATION})
endforeach()
membranes_compare(solver_direct_vs_cg_amg solver_direct solver_cg-amg
  COLUMNS dofs,active_vertices RTOL 0)
membranes_compare(solver_direct_vs_cg_amg_errors solver_direct solver_cg-amg
  COLUMNS ${ERRORS} RTOL 1e-8)

# The direct solver factorizes the distributed matrix on any number of
# processes: on two as on one, every column of the report (REPORT: the
# same active set iterations and active sets, errors equal to round-off,
# bound 1e-10; the DoFs are numbered differently, and so are the
# operations of the factorization). The run on two processes has expected
# values. Catches: a distributed matrix or right-hand side that misses the
# entries of another process.
foreach(processes 1 2)
  set(expected)
  if(processes EQUAL 2)
    set(expected EXPECTED)
  endif()
  membranes_scene_test(solver_direct_np${processes} case-m-quadrilateral.prm
    PROCESSES ${processes} ${expected}
    SETTINGS Refinement/Cycles=5 Solver/Linear\ solver=direct
             Output/Write\ vtu=false)
endforeach()
membranes_compare(solver_direct_np1_vs_np2 solver_direct_np1 solver_direct_np2
  REPORT RTOL 1e-10 FACTOR 10)

# Solver/Method = decoupled (the linear problem for s = mu1 u1 + mu2 u2
# once, then the obstacle problem for w = u1 - u2) solves the same discrete
# problem as the coupled method: the decoupling is exact for (3.4). Each
# comparison runs a scene with both methods (both with expected values)
# and compares them with membranes_compare_runs. With the direct solver
# (set where the tolerance is 1e-8) the measured differences are at
# most 7e-14 (u) and 2e-12 (lambda_a, a residual divided by d_a ~ h^2).
# With CG they are set by the CG tolerances, Tolerance times the force
# scale of each of the problems for s and w: bound 1e-7.
#
# Adaptive meshes compare only if the marking sees no ties in eta_K: on
# meshes and data with mirror symmetries, round-off differences (between
# the two methods as between the direct and CG solvers) decide which of two
# equal indicators is marked. The disk scene on quadrilaterals shows none;
# on triangles, membrane 2 is held at a height g2 without symmetry.
#
# membranes_method_comparison(NAME SCENE CYCLES RTOL [ERRORS columns]
#                             [settings...]): ERRORS the error columns
# compared, by default the errors and the estimator.
function(membranes_method_comparison name scene cycles rtol)
  cmake_parse_arguments(ARG "" "ERRORS" "" ${ARGN})
  if(NOT ARG_ERRORS)
    set(ARG_ERRORS ${ERRORS},estimator)
  endif()
  foreach(method coupled decoupled)
    membranes_scene_test(${name}_${method} ${scene} EXPECTED
      SETTINGS ${ARG_UNPARSED_ARGUMENTS} Refinement/Cycles=${cycles}
               Solver/Method=${method}
               Output/Write\ vtu=false Output/Write\ nodal\ values=true)
  endforeach()
  membranes_compare_runs(${name} ${name}_coupled ${name}_decoupled ${cycles}
    ${rtol} ERRORS ${ARG_ERRORS})
endfunction()

foreach(cell_type quadrilateral triangle)
  membranes_method_comparison(decoupled_case_m_${cell_type}
    case-m-${cell_type}.prm 5 1e-8 Solver/Linear\ solver=direct)
endforeach()
membranes_method_comparison(decoupled_cg_amg case-m-quadrilateral.prm 5 1e-7
  Solver/Linear\ solver=cg-amg)
membranes_method_comparison(decoupled_adaptive_disk default.prm 8 1e-8)
membranes_method_comparison(decoupled_degenerate degenerate-free-boundary.prm 4
  1e-8 Solver/Linear\ solver=direct)
# Without exact solution only the estimator is compared.
membranes_method_comparison(decoupled_adaptive_triangle case-m-triangle.prm
  10 1e-8 ERRORS estimator Refinement/Strategy=adaptive
  Exact\ solution/Known=false "Problem/g2=0.1*exp(x+0.5*y)")

# Solver/Stopping = balanced stops the active set method and CG once the
# linearization and algebraic errors are below gamma = Balance fraction
# (0.1) of the discretization error expected on the mesh. On the same
# global meshes as Stopping = exact, it must
# - never take more active set or CG iterations, on any cycle (catches a
#   balanced test that never fires);
# - keep the energy error within the share gamma: err_energy(balanced) <=
#   err_energy(exact) + 0.1 max(both), i.e. at most 1.11 times that of
#   exact stopping (measured: at most 1 + 1e-4 on the degenerate scene, P1,
#   and 1.005 on case M, Q1 with CG-AMG, on its 162-DoF mesh); catches a
#   test that stops too early;
# - report eta_lin and eta_alg: expected values of the balanced runs (on
#   the first mesh, which stops exactly, they are empty).
# membranes_stopping_comparison(NAME SCENE CYCLES [settings...])
function(membranes_stopping_comparison name scene cycles)
  foreach(stopping exact balanced)
    set(expected)
    if(stopping STREQUAL "balanced")
      set(expected EXPECTED)
    endif()
    membranes_scene_test(${name}_${stopping} ${scene} ${expected}
      SETTINGS ${ARGN} Refinement/Cycles=${cycles}
               Solver/Stopping=${stopping} Output/Write\ vtu=false)
  endforeach()
  set(runs ${name}_exact ${name}_balanced)
  membranes_compare(${name}_same_meshes ${runs} COLUMNS cells,dofs RTOL 0)
  membranes_compare(${name}_no_more_iterations ${runs}
    COLUMNS active_set_iterations,linear_iterations RTOL 0 ONE_SIDED)
  membranes_compare(${name}_energy_error ${runs}
    COLUMNS err_energy RTOL 0.1 ONE_SIDED)
endfunction()

membranes_stopping_comparison(stopping_degenerate degenerate-free-boundary.prm
  6)
membranes_stopping_comparison(stopping_case_m case-m-quadrilateral.prm 5
  Solver/Linear\ solver=cg-amg)

# Linear solver = auto takes the direct solver, UMFPACK on one process, up
# to 1000 unknowns per scalar problem and CG-AMG above
# (LinearSolver::direct_solver_dof_limit, measured by
# benchmarks/solver_crossover.py): every active set iteration of case M, 5
# cycles (25 to 4225 unknowns), says so. Catches: a limit that is not the
# documented one, the size of the pair taken for that of one problem, or
# MUMPS on one process.
add_test(NAME solver_choice_auto
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/check_solver_choice.py
          1000 ${CMAKE_CURRENT_BINARY_DIR}/solver_choice_auto
          $<TARGET_FILE:membranes> ${SCENES}/case-m-quadrilateral.prm
          --set Refinement/Cycles=5 --set Output/Write\ vtu=false)
set_tests_properties(solver_choice_auto PROPERTIES LABELS quick)
