# A study resumes where it stopped (tests/resume.py): killed by SIGKILL at a
# random point of a cycle and resumed with --resume, or run for K cycles and
# extended to N, it writes the report.csv of the study run without
# interruption (integers exactly, values to 1e-10): on both cell types, on
# one and two processes, under global and adaptive refinement, with exact
# and balanced stopping, with CG-AMG, whose iterates depend on the
# numbering of the DoFs. Catches: a vector, indicator or refinement of the
# history not restored (a p4est mesh loaded as saved numbers its cells in
# p4est's order: CG-AMG then moves the L2 errors by 2e-9), a report row
# lost or repeated, balanced stopping without the previous estimator, a
# checkpoint left half-written by the kill.
function(membranes_resume_test name case scene processes k n)
  add_test(NAME resume.${name}
    COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/resume.py
            ${case} $<TARGET_FILE:membranes> ${SCENES}/${scene}
            ${CMAKE_CURRENT_BINARY_DIR}/resume/${name} ${processes} ${k} ${n}
            ${ARGN})
  set_tests_properties(resume.${name} PROPERTIES PROCESSORS ${processes}
    ENVIRONMENT "${MPI_ROOT_ENVIRONMENT};LAUNCHER=${DEAL_II_MPIEXEC} ${DEAL_II_MPIEXEC_NUMPROC_FLAG}")
endfunction()

membranes_resume_test(kill_q1_global kill case-m-quadrilateral.prm 1 5 7)
membranes_resume_test(kill_p1_adaptive kill default.prm 1 8 10
  Geometry/Cell\ type=triangle)
membranes_resume_test(kill_q1_adaptive_np2 kill default.prm 2 8 10)
membranes_resume_test(kill_p1_global_np2 kill case-m-triangle.prm 2 5 7)
membranes_resume_test(extend_q1_adaptive extend default.prm 1 6 9)
membranes_resume_test(extend_q1_balanced_np2 extend case-m-quadrilateral.prm
  2 4 7 Solver/Stopping=balanced)
membranes_resume_test(extend_p1_flux extend shifted-circle.prm 1 4 7
  Refinement/Strategy=adaptive Refinement/Estimator=flux)

# A resume that cannot be done ends in one line before any cycle and leaves
# report.csv alone: a directory without a study, another scene, a directory
# in use, a truncated checkpoint, no checkpoint. Catches: a crash in p4est
# on a damaged file, a scene resumed with other data, a report overwritten.
membranes_resume_test(hostile hostile case-m-quadrilateral.prm 1 3 5)
