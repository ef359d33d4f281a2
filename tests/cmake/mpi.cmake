# Runs on two processes against one.

# MPI: the same scenes on two processes against one, every column of
# report.csv (membranes_compare_runs without ERRORS: compare_reports.py
# --report): the same meshes, active sets and active set iterations at
# every cycle, errors, estimators and their parts equal to R relative, the
# round-off columns (KKT residual, defects of Prop. 12 and (4.8), min_w,
# min_lambda) within 10 times their largest value on one process; the
# nodal values to R of their max norm. Not compared: processes, and
# linear_iterations (ML's AMG differs with the partition: up to 2 of 34
# CG iterations). Catches: a quantity summed over the locally owned cells
# only, a ghost value not updated, a marking that differs between
# processes, a column of the report read from the wrong entries of a
# distributed vector.
#
# Measured, the largest |np2 - np1| over the largest |np1| of a test:
# complementarity_defect 0.97, min_lambda 0.97, kkt_residual 0.69,
# prop12_defect 0.69 with the direct solver and 7.4 with CG (mpi_p1_cg_amg:
# CG stops at another iterate on each partition, and the defect carries
# its residual, which only Solver/Tolerance bounds). The contact part of
# the flux estimator, (2 B)^{1/2} with B the sum over the cells of
# max(∫ λ̃_h (u1h − u2h), 0), is a value (1e-2 to 0.3) plus the positive
# parts of the round-off or algebraic error of λ_a times w away from the
# contact zone: compared to 1000 R (measured: 1.3e-9 relative with the
# direct solver, 6.2e-7 with CG at Solver/Tolerance = 1e-10, at which one
# process and the same at 1e-14 differ by 5e-6).
#
# On quadrilaterals (p4est) with CG and AMG, the runs differ only in how
# the cells are distributed and in the order of floating point sums:
# errors and estimators to 1e-8 relative (measured: <= 2.1e-9, and the
# errors in the energy norm equal in the 12 digits of the report), nodal
# values to 1e-7 of their max norm (measured: 4e-12 for u1, u2 and 4e-9
# for lambda_a, which is a residual of (4.5) divided by d_a ~ h^2 and so
# carries the CG residual, as in the cg-amg method comparison above).
#
# membranes_process_comparison(NAME SCENE CYCLES [SOLVER S] [RTOL R]
#                              [EXPECTED] [settings...]):
# the values of the report compared to 1e-8 relative and the nodal values
# to 1e-7 of their max norm with CG (the default S = cg-amg), both to R
# with S = direct. CYCLES is the number of rows; a setting of
# Refinement/Cycles overrides it as the scene's number of cycles.
# EXPECTED: the run on two processes has expected values.
function(membranes_process_comparison name scene cycles)
  cmake_parse_arguments(ARG "EXPECTED" "SOLVER;RTOL" "" ${ARGN})
  if(NOT ARG_SOLVER)
    set(ARG_SOLVER cg-amg)
    set(ARG_RTOL 1e-8)
    set(nodal_rtol 1e-7)
  else()
    set(nodal_rtol ${ARG_RTOL})
  endif()
  foreach(processes 1 2)
    set(expected)
    if(ARG_EXPECTED AND processes EQUAL 2)
      set(expected EXPECTED)
    endif()
    membranes_scene_test(${name}_np${processes} ${scene}
      PROCESSES ${processes} ${expected}
      SETTINGS Refinement/Cycles=${cycles} Solver/Linear\ solver=${ARG_SOLVER}
               Output/Write\ nodal\ values=true ${ARG_UNPARSED_ARGUMENTS})
  endforeach()
  membranes_compare_runs(${name} ${name}_np1 ${name}_np2 ${cycles}
    ${nodal_rtol} RTOL ${ARG_RTOL})
endfunction()

# Global refinement with the decoupled solver path (its scalar DoFHandler
# on the distributed mesh); adaptive refinement with the coupled one, the
# flux reconstruction (ghost exchange of the half-edge fluxes at hanging
# nodes) and flux-driven marking (parallel bulk marking).
membranes_process_comparison(mpi_case_m_global case-m-quadrilateral.prm 5
  Solver/Method=decoupled)
membranes_process_comparison(mpi_case_m_adaptive case-m-quadrilateral.prm 10
  EXPECTED Refinement/Strategy=adaptive
  Output/Flux\ reconstruction=true Refinement/Estimator=flux)
# The coupled method under adaptive refinement: a cell of one process adds
# to the rows of another the columns of the parents of its hanging
# vertices, which the scaling of the coupled system must know (a scaling
# that read zero for them would solve another system, on which the active
# set method stalls).
membranes_process_comparison(mpi_coupled_adaptive shifted-circle.prm 10
  SOLVER direct RTOL 1e-10 EXPECTED
  Refinement/Strategy=adaptive Solver/Method=coupled
  Geometry/Cell\ type=quadrilateral)
# Balanced stopping, the one comparison with eta_linearization and
# eta_algebraic: with the direct solver both runs stop at the same iterate.
# (kkt_residual, min_w and min_lambda, round-off at convergence, are values
# of that iterate here, which 10 times their size on one process bounds
# loosely.) Catches: a stopping estimate summed over the locally owned
# part only, a stopping decision that differs between processes.
membranes_process_comparison(mpi_balanced case-m-quadrilateral.prm 5
  SOLVER direct RTOL 1e-10 Solver/Stopping=balanced)

# P1 on triangles: every process holds the whole mesh (a
# parallel::shared::Triangulation) and owns a part of its cells and DoFs.
# With the direct solver on both process counts (UMFPACK on one, MUMPS on
# two, each solving to round-off) the runs differ only by round-off:
# the same meshes and active sets, errors and estimators equal to 1e-10
# relative, nodal values to 1e-10 of their max norm (measured with MUMPS on
# both: <= 1.5e-11 for the errors and estimators, <= 1e-14 for u1h, u2h and
# <= 2.5e-11 for lambda_a, a residual divided by d_a). On the finest global
# mesh (16 641 vertices) err_u2_L2 = 2.7e-4 differs by 7e-14 between
# UMFPACK and MUMPS, 2.7e-10 relative: 1e-9 there. Global refinement with
# both methods on case M; adaptive refinement, driven by the residual and by
# the flux estimator, on the shifted circle, whose contact zone is off the
# centre: on a mesh and data with mirror symmetries, round-off differences
# decide which of two equal indicators is marked (see the method
# comparisons above), here the numbers of processes.
membranes_process_comparison(mpi_p1_global case-m-triangle.prm 6
  SOLVER direct RTOL 1e-9 Solver/Method=coupled)
membranes_process_comparison(mpi_p1_global_decoupled case-m-triangle.prm 6
  SOLVER direct RTOL 1e-9 Solver/Method=decoupled)
membranes_process_comparison(mpi_p1_residual shifted-circle.prm 10
  SOLVER direct RTOL 1e-10 EXPECTED Refinement/Strategy=adaptive
  Solver/Method=coupled)
membranes_process_comparison(mpi_p1_flux shifted-circle.prm 8
  SOLVER direct RTOL 1e-10 EXPECTED Refinement/Strategy=adaptive
  Refinement/Estimator=flux Output/Flux\ reconstruction=true)
# A Gmsh mesh, adaptive refinement with the flux estimator, the run ended
# by Target estimator (the flux estimator of cycle 6 is 1.49) before
# Cycles = 9.
membranes_process_comparison(mpi_p1_gmsh shifted-circle.prm 7
  SOLVER direct RTOL 1e-10 Refinement/Cycles=9 Geometry/Domain=file
  Geometry/Mesh\ file=meshes/square-triangles.msh
  Refinement/Strategy=adaptive Refinement/Estimator=flux
  Refinement/Target\ estimator=1.5)
# The slit domain (its doubled vertices), and CG-AMG, to the tolerances of
# the quadrilateral tests.
membranes_process_comparison(mpi_p1_slit slit.prm 8 SOLVER direct
  RTOL 1e-10 Geometry/Cell\ type=triangle)
membranes_process_comparison(mpi_p1_cg_amg shifted-circle.prm 10
  Refinement/Strategy=adaptive Solver/Method=decoupled)

# Symmetric scenes, on which cells that mirror each other carry indicators
# equal in exact arithmetic, refined adaptively by each estimator, with
# both markings, on both cell types: the same cells on one process and on
# two, and the errors and estimators to 1e-10 relative with the direct
# solver, to 1e-8 with CG at Solver/Tolerance = 1e-12 (mark_cells(): the
# thresholds from all indicators in one sorted order, ties within 1e-6
# marked together). Three processes, compared in every column as here:
# benchmarks/process_count.py.
# Catches: a marking that lets round-off, or the iterate at which CG stops
# on a partition, choose among tied cells. (Before, the P1 runs parted at
# cycle 2, with other cells of the same number, or another number.)
membranes_process_comparison(mpi_symmetric_p1_residual case-m-triangle.prm 8
  SOLVER direct RTOL 1e-10 Refinement/Strategy=adaptive)
membranes_process_comparison(mpi_symmetric_p1_flux case-m-triangle.prm 8
  SOLVER direct RTOL 1e-10 Refinement/Strategy=adaptive
  Refinement/Estimator=flux Output/Flux\ reconstruction=true)
membranes_process_comparison(mpi_symmetric_p1_fixed_number
  case-m-triangle.prm 7 Refinement/Strategy=adaptive
  Refinement/Marking=fixed\ number Solver/Tolerance=1e-12)
membranes_process_comparison(mpi_symmetric_q1_fixed_number
  case-m-quadrilateral.prm 7 Refinement/Strategy=adaptive
  Refinement/Marking=fixed\ number
  Refinement/Estimator=flux Output/Flux\ reconstruction=true
  Solver/Tolerance=1e-12)

# The output of a run on two processes: one piece per process, joined by a
# .pvtu record that the .pvd lists. Catches: a piece or record missing.
add_test(NAME mpi_case_m_global_np2.files
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/check_output_files.py
          ${CMAKE_CURRENT_BINARY_DIR}/mpi_case_m_global_np2
          --present solution-04.pvtu --present solution-04.0000.vtu
          --present solution-04.0001.vtu --present solution.pvd
          --absent *.tmp)
set_tests_properties(mpi_case_m_global_np2.files PROPERTIES
  FIXTURES_REQUIRED mpi_case_m_global_np2)
add_test(NAME mpi_p1_flux_np2.files
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/check_output_files.py
          ${CMAKE_CURRENT_BINARY_DIR}/mpi_p1_flux_np2
          --present solution-07.pvtu --present solution-07.0000.vtu
          --present solution-07.0001.vtu --present dual-mesh-07.pvtu
          --present solution.pvd --absent *.tmp)
set_tests_properties(mpi_p1_flux_np2.files PROPERTIES
  FIXTURES_REQUIRED mpi_p1_flux_np2)
