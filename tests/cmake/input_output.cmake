# What a run reads and writes: only what a scene asks for, bad scenes and
# hostile input refused in one line, the output directory and the faults of
# writing it.

# A scene computes and writes only what it asks for: no exact solution, no
# error columns (absent from report.csv) and no time for them; no VTU when
# Write vtu = false; no nodal values by default.
# Catches: work a scene did not ask for.
membranes_scene_test(leaves_out case-m-quadrilateral.prm QUICK
  SETTINGS Refinement/Cycles=2 Exact\ solution/Known=false
           Output/Write\ vtu=false
  CHECKS --absent err_u1_H1 --absent err_u2_H1 --absent err_u1_L2
         --absent err_u2_L2 --absent err_lambda_L2
         --absent err_lambda_L2_omega_h --absent err_lambda_Hm1
         --absent err_energy --absent effectivity --absent flux_effectivity
         --empty estimator --empty flux_estimator --empty time_flux_s
         --empty time_errors_s --empty conservation_defect
  FILES --present report.csv --absent *.vtu --absent *.pvd --absent *.tmp
        --absent nodal-values-*.csv)

# Exact solution/Norms: a run computes the error columns its scene names and
# leaves the others out of report.csv; each computed column equals that of
# the run with every column (case_m_quadrilateral, which names all eight).
# Two subsets: one of each pass of ErrorNorms (a displacement norm and an
# L2 norm of the action) with the H^-1 norm, and the H^-1 norm alone: no
# pass of ErrorNorms, no err_energy, so no effectivity and, on a uniform
# run, no residual estimator either. Catches: a column written that was not
# asked for, a norm that changes when computed without the others (a wrong
# slot of the squares), an estimator computed for an effectivity that is
# not reported.
membranes_scene_test(norms_subset case-m-quadrilateral.prm QUICK
  SETTINGS Refinement/Cycles=6 Output/Write\ vtu=false
           "Exact solution/Norms=err_u2_L2, err_lambda_L2_omega_h, err_lambda_Hm1"
  CHECKS --absent err_u1_H1 --absent err_u2_H1 --absent err_u1_L2
         --absent err_lambda_L2 --absent err_energy --absent effectivity
         --absent flux_effectivity --filled err_u2_L2
         --filled err_lambda_L2_omega_h --filled err_lambda_Hm1
         --filled time_errors_s --empty estimator)
membranes_compare(norms_subset_same_values case_m_quadrilateral norms_subset
  COLUMNS dofs,active_vertices,err_u2_L2,err_lambda_L2_omega_h,err_lambda_Hm1
  RTOL 1e-12)
membranes_scene_test(norms_hm1_alone case-m-triangle.prm QUICK
  SETTINGS Refinement/Cycles=4 Output/Write\ vtu=false
           Exact\ solution/Norms=err_lambda_Hm1
  CHECKS --absent err_u1_H1 --absent err_u2_L2 --absent err_lambda_L2
         --absent err_lambda_L2_omega_h --absent err_energy
         --absent effectivity --filled err_lambda_Hm1 --empty estimator)

# Bad scenes: one-line error naming the parameter, non-zero exit, no output.
add_test(NAME bad_scenes
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/bad_scenes.py
          $<TARGET_FILE:membranes> ${CMAKE_CURRENT_BINARY_DIR}/bad_scenes
          "${DEAL_II_MPIEXEC} ${DEAL_II_MPIEXEC_NUMPROC_FLAG}")
set_tests_properties(bad_scenes PROPERTIES
  ENVIRONMENT "${MPI_ROOT_ENVIRONMENT}" LABELS quick)

# An output directory holds one run, all of it (tests/output_directory.py):
# a second run on the directory of a running one is refused, on one and on
# two processes, and the first completes untouched; a rerun with fewer
# cycles leaves no file of the earlier run and every file the program did
# not write; a run killed by SIGKILL, or one of its two processes, does not
# block the next one, and the launcher ends a run of which one process was
# killed; and the parameters.prm of a run makes the same run (same
# report.csv, time and memory columns aside). Catches: a lock not taken or
# not released, a process that waits forever for a dead one, a
# parameters.prm that omits a setting.
foreach(case race rerun kill kill_mpi reproduce)
  add_test(NAME output_directory.${case}
    COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/output_directory.py
            ${case} $<TARGET_FILE:membranes> ${SCENES}
            ${CMAKE_CURRENT_BINARY_DIR}/output_directory
            "${DEAL_II_MPIEXEC} ${DEAL_II_MPIEXEC_NUMPROC_FLAG}")
  set_tests_properties(output_directory.${case} PROPERTIES
    ENVIRONMENT "${MPI_ROOT_ENVIRONMENT}")
endforeach()
# The race runs the second run on two processes beside the first. The
# reproduction compares to the last digit: on a mesh from a file, round-off
# depends on the number of threads (doc/advanced.md, "Threads"), one for
# all its runs.
set_tests_properties(output_directory.race output_directory.kill_mpi
  PROPERTIES PROCESSORS 2)
set_tests_properties(output_directory.reproduce PROPERTIES
  ENVIRONMENT "${MPI_ROOT_ENVIRONMENT};DEAL_II_NUM_THREADS=1")

# An output file that cannot be written during the run (tests/io_faults.py):
# a file size limit, a full file system, the output directory removed or
# made read-only. Each ends the run with exit status 1 and one line naming
# the file and the system's reason, and leaves no partial file. A case that
# cannot be set up here (no mount of a tmpfs, no user to drop root
# privileges to) is skipped. Catches: a signal that ends the process
# (SIGXFSZ), a library's error paragraph instead of the line, a
# half-written row or temporary file.
foreach(case file_size no_space removed read_only)
  add_test(NAME io_faults.${case}
    COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/io_faults.py
            ${case} $<TARGET_FILE:membranes> ${SCENES}
            ${CMAKE_CURRENT_BINARY_DIR}/io_faults)
  set_tests_properties(io_faults.${case} PROPERTIES SKIP_RETURN_CODE 77)
endforeach()

# Hostile input: a few hundred generated malformed scenes, meshes, output
# directories and command lines (truncated shipped scenes, wrong types,
# extreme numbers, NaN and infinity in expressions, garbage and invalid
# meshes, unwritable directories). Each must end in time, without a crash,
# with one 'membranes: error:' line naming the parameter, or, where the
# input is still valid, a clean run; never with a partial output file. In
# three groups that ctest runs side by side.
foreach(group "truncated_scenes;command_line" "values" "expressions;meshes;output")
  string(REPLACE ";" "+" name "${group}")
  add_test(NAME hostile_input.${name}
    COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/hostile_input.py
            $<TARGET_FILE:membranes> ${CMAKE_SOURCE_DIR}
            ${CMAKE_CURRENT_BINARY_DIR}/hostile_input ${group})
  # The longest tests of the suite: started first.
  set_tests_properties(hostile_input.${name} PROPERTIES TIMEOUT 600 COST 1000)
endforeach()
