# Adaptive refinement: rates in DoFs, the estimators that drive it, the
# target estimator, minimum growth and the markings.

# Adaptive refinement by the residual estimator.
# L-shape with a corner singularity: the energy error falls like N^(-1/2)
# (uniform refinement: N^(-1/3)); least-squares rate in DoFs over the last
# half of the cycles >= 0.45 (catches marking that does not follow the
# indicator). Expected values: the residual estimator of every cycle
# (catches a wrong sign, weight or dropped term of the estimator).
membranes_scene_test(lshape_adaptive lshape.prm EXPECTED QUICK
  SETTINGS Refinement/Cycles=13 Output/Write\ vtu=false
  CHECKS --dof-rate err_energy>=0.45 ${ADAPTIVE_CHECKS} ${NESTED_ITERATION})

# The slit domain (slit.prm): u ~ r^(1/2) sin(theta/2) at the tip of the
# slit [0,1) x {0}, whose two faces are boundary, and a contact zone.
# Uniform refinement converges like h^(1/2) in the energy norm (observed
# 0.53 on the last two of 6 Q1 cycles, 0.56 on 5 P1 cycles): the rate is
# checked from both sides (catches a slit whose faces are glued: the rate
# rises to 1). Adaptive refinement keeps N^(-1/2) (observed 0.54 over the
# last half of 13 cycles on both cell types).
foreach(cell_type quadrilateral triangle)
  set(expected)
  if(cell_type STREQUAL "triangle")
    set(expected EXPECTED)
  endif()
  membranes_scene_test(slit_uniform_${cell_type} slit.prm
    SETTINGS Geometry/Cell\ type=${cell_type} Refinement/Strategy=global
             Refinement/Cycles=5 Output/Write\ vtu=false
    CHECKS --rate err_energy>=0.45 --max-rate err_energy<=0.65
           --growth cells>=4 ${NESTED_ITERATION})
  membranes_scene_test(slit_adaptive_${cell_type} slit.prm ${expected}
    SETTINGS Geometry/Cell\ type=${cell_type} Refinement/Cycles=13
             Output/Write\ vtu=false
    CHECKS --dof-rate err_energy>=0.45 ${ADAPTIVE_CHECKS} ${NESTED_ITERATION})
endforeach()
# The same slit from a Gmsh file (parameters/meshes/slit-*.msh: the vertex
# at (1,0) twice, once for each face): on quadrilaterals the same meshes,
# active sets and errors (to 1e-8) as Domain = slit; on triangles (two per
# quadrilateral) the same rate. Catches: a mesh reader that merges the
# doubled vertex.
membranes_scene_test(slit_gmsh_quadrilateral slit.prm
  SETTINGS Geometry/Domain=file
           Geometry/Mesh\ file=meshes/slit-quadrilaterals.msh
           Refinement/Cycles=13 Output/Write\ vtu=false)
membranes_compare(slit_gmsh_vs_builtin
  slit_adaptive_quadrilateral slit_gmsh_quadrilateral
  COLUMNS dofs,active_vertices RTOL 0)
membranes_compare(slit_gmsh_vs_builtin_errors
  slit_adaptive_quadrilateral slit_gmsh_quadrilateral
  COLUMNS err_energy,err_lambda_L2,estimator RTOL 1e-8)
membranes_scene_test(slit_gmsh_triangle slit.prm
  SETTINGS Geometry/Domain=file Geometry/Mesh\ file=meshes/slit-triangles.msh
           Geometry/Cell\ type=triangle Refinement/Cycles=13
           Output/Write\ vtu=false
  CHECKS --dof-rate err_energy>=0.45 ${ADAPTIVE_CHECKS} ${NESTED_ITERATION})

# The table printed at the end gives rates in h for uniform runs, in DoFs
# for adaptive ones, equal to those of report.csv. Catches: a rate in the
# wrong unit.
foreach(unit dofs h)
  if(unit STREQUAL dofs)
    set(strategy adaptive)
  else()
    set(strategy global)
  endif()
  add_test(NAME terminal_rates_${unit}
    COMMAND ${Python3_EXECUTABLE}
            ${CMAKE_CURRENT_SOURCE_DIR}/check_terminal_rates.py
            ${CMAKE_CURRENT_BINARY_DIR}/terminal_rates_${unit} ${unit}
            $<TARGET_FILE:membranes> --set Refinement/Strategy=${strategy}
            --set Refinement/Cycles=6 --set Output/Write\ vtu=false
            ${SCENES}/slit.prm)
endforeach()

# Refinement/Target estimator: the run ends after the first cycle whose
# estimator is at most the target (0.5 is reached on cycle 11 of the slit
# with the scene's marking: estimator 0.437, 0.555 before), long before
# 'Cycles'; it stops a uniform run without exact solution too (the
# residual estimator is then computed for the target alone: 0.48 on cycle
# 4 of no-contact.prm, 0.96 before). Catches: a run that stops one cycle
# late or early, or computes no estimator for the target.
membranes_scene_test(target_estimator slit.prm EXPECTED
  SETTINGS Refinement/Cycles=40 Refinement/Target\ estimator=0.5
           Output/Write\ vtu=false
  CHECKS --rows 12 --max-last estimator<=0.5 --min-last estimator>=0.4)
membranes_scene_test(target_estimator_uniform no-contact.prm EXPECTED
  SETTINGS Refinement/Cycles=40 Refinement/Target\ estimator=0.5
           Exact\ solution/Known=false Output/Write\ vtu=false
  CHECKS --rows 5 --max-last estimator<=0.5)

# The scene of README's "Your own scene": a Gmsh mesh of a plate with a hole
# (parameters/meshes/plate-with-hole.msh), no exact solution, adaptive
# refinement until the estimator is at most 0.05 (observed: cycle 13, 0.048,
# 74 234 DoFs); its uniform reference run. Expected values: the estimator
# without an exact solution (catches an estimator that needs one).
membranes_scene_test(own_scene own-scene.prm EXPECTED
  SETTINGS Output/Write\ vtu=false
  CHECKS --max-last estimator<=0.05 --decreasing estimator ${NESTED_ITERATION})
membranes_scene_test(own_scene_uniform own-scene.prm EXPECTED
  SETTINGS Refinement/Strategy=global Refinement/Cycles=4
           Output/Write\ vtu=false
  CHECKS --decreasing estimator ${NESTED_ITERATION})

# Refinement/Minimum growth: the cells grow at least by the factor, the
# marking's cells first (it still refines towards the tip: rate >= 0.4).
# Catches: a growth that adds arbitrary cells, or none.
membranes_scene_test(minimum_growth slit.prm EXPECTED
  SETTINGS Refinement/Cycles=8 Refinement/Minimum\ growth=2.5
           Output/Write\ vtu=false
  CHECKS --growth cells>=2.45 --dof-rate err_energy>=0.4)

# Case M, adaptive, both cell types; on quadrilaterals with fixed-number
# marking and coarsening too (catches coarsening that transfers the
# solution wrongly: the iterations and values move).
foreach(cell_type quadrilateral triangle)
  membranes_scene_test(case_m_adaptive_${cell_type} case-m-${cell_type}.prm
    EXPECTED
    SETTINGS Refinement/Strategy=adaptive Refinement/Cycles=12
             Output/Write\ vtu=false
    CHECKS ${ADAPTIVE_CHECKS} ${NESTED_ITERATION})
endforeach()
membranes_scene_test(case_m_adaptive_coarsening case-m-quadrilateral.prm
  EXPECTED
  SETTINGS Refinement/Strategy=adaptive Refinement/Cycles=12
           Refinement/Marking=fixed\ number Refinement/Refinement\ fraction=0.3
           Refinement/Coarsen\ fraction=0.05 Output/Write\ vtu=false
  CHECKS --band effectivity<=2 --hanging-nodes 3 ${NESTED_ITERATION})

# A discrete solution that is exact (tests/scenes/flat-membranes.prm: flat
# membranes without load), so that every indicator is zero: the run says so
# in one line and ends after the first cycle instead of repeating its mesh,
# on one process with bulk marking and on two (triangles, fixed number,
# the flux estimator). Catches: cycles that repeat the same mesh, or a
# decision that differs between processes.
membranes_scene_test(exact_discrete_solution
  ${CMAKE_CURRENT_SOURCE_DIR}/scenes/flat-membranes.prm
  CHECKS --rows 1 --max estimator<=0)
membranes_scene_test(exact_discrete_solution_np2
  ${CMAKE_CURRENT_SOURCE_DIR}/scenes/flat-membranes.prm PROCESSES 2
  SETTINGS Geometry/Cell\ type=triangle Refinement/Marking=fixed\ number
           Refinement/Estimator=flux
  CHECKS --rows 1 --max flux_estimator<=0)
set_tests_properties(exact_discrete_solution.run exact_discrete_solution_np2.run
  PROPERTIES PASS_REGULAR_EXPRESSION
  "\nStopping: every refinement indicator is zero [^\n]*no cell to refine\n")
