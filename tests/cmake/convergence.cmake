# Scenes with exact solutions under global refinement, and the
# expected values and rates they must reach.

# Case M on both cell types, global refinement (the default method,
# decoupled). Expected: every error and the estimator of every cycle.
# Rates catch a loss of convergence. lambda jumps across the circle
# r = 1/2, which no mesh line follows, so the piecewise constant lambda_h
# has an O(1) error on a strip of dual cells of width O(h):
# ||lambda - lambda_h||_L2 ~ h^(1/2), observed 0.49 (Q1) and 0.45 (P1);
# bound 0.4. In H^-1 (Theorem 21: order h on P1 under (4.28)) the same
# strip weighs less, order h^(3/2) (observed 1.5 to 1.7); bound 0.9, the
# theorem's order. The files catch a run that does not write its fields,
# or leaves a temporary file behind.
foreach(cell_type quadrilateral triangle)
  membranes_scene_test(case_m_${cell_type} case-m-${cell_type}.prm EXPECTED QUICK
    SETTINGS Refinement/Cycles=6
    CHECKS ${DISPLACEMENT_RATES} --rate err_lambda_L2>=0.4
           --rate err_lambda_Hm1>=0.9 ${NESTED_ITERATION}
    FILES --present solution-05.vtu --present solution.pvd
          --absent *.tmp)
endforeach()

# Meshes from Gmsh files and the L-shaped domain (case M shifted):
# rates. Catches: a mesh read with a wrong orientation or boundary
# indicator, a re-entrant corner that breaks the dual cells.
membranes_scene_test(case_m_gmsh_triangles case-m-gmsh-triangles.prm
  SETTINGS Refinement/Cycles=5 Output/Write\ vtu=false
  CHECKS ${DISPLACEMENT_RATES} ${NESTED_ITERATION})
membranes_scene_test(case_m_gmsh_quadrilaterals case-m-quadrilateral.prm
  SETTINGS Geometry/Domain=file
           Geometry/Mesh\ file=${SCENES}/meshes/square-quadrilaterals.msh
           Refinement/Cycles=5 Output/Write\ vtu=false
  CHECKS ${DISPLACEMENT_RATES} ${NESTED_ITERATION})
foreach(cell_type quadrilateral triangle)
  membranes_scene_test(case_m_lshape_${cell_type}
    ${CMAKE_CURRENT_SOURCE_DIR}/scenes/case-m-lshape.prm
    SETTINGS Geometry/Cell\ type=${cell_type} Output/Write\ vtu=false
    CHECKS ${DISPLACEMENT_RATES} ${NESTED_ITERATION})
endforeach()

# Full contact, lambda = 2 + xy >= 1 up to the boundary: lambda_h
# converges at rate 1 on omega_h. Expected values; the rate catches a
# lambda_a of the wrong order (a wrong d_a, or the mean of the two
# formulas of (4.5) taken with wrong weights). On omega, lambda_h = 0 on
# the strip along the boundary, where lambda >= 1: the error of (4.36)
# decreases like h^(1/2), and check_strip.py compares it with the norm of
# lambda on the strip computed by hand. In H^-1 the strip gives order
# h^(3/2); bound 0.9, the order of Theorem 21.
# The same on P1, the paper's setting.
foreach(cell_type quadrilateral triangle)
  set(name full_contact)
  if(cell_type STREQUAL triangle)
    set(name full_contact_triangle)
  endif()
  membranes_scene_test(${name} full-contact.prm EXPECTED
    SETTINGS Refinement/Cycles=6 Output/Write\ vtu=false
             Geometry/Cell\ type=${cell_type}
    CHECKS ${DISPLACEMENT_RATES} --rate err_lambda_L2_omega_h>=0.9
           --rate err_lambda_L2>=0.45 --max-rate err_lambda_L2<=0.55
           --rate err_lambda_Hm1>=0.9
           ${NESTED_ITERATION})
endforeach()
add_test(NAME full_contact.strip
  COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/check_strip.py
          ${CMAKE_CURRENT_BINARY_DIR}/full_contact/report.csv)
set_tests_properties(full_contact.strip PROPERTIES FIXTURES_REQUIRED full_contact)

# No contact: empty active set (catches a test that activates vertices
# with a positive gap) and lambda_h = 0 to solver accuracy (catches a
# lambda_a that is not the residual of (4.5)).
membranes_scene_test(no_contact no-contact.prm EXPECTED QUICK
  SETTINGS Refinement/Cycles=6 Output/Write\ vtu=false
  CHECKS ${DISPLACEMENT_RATES} --max active_vertices<=0
         --max err_lambda_L2<=1e-6)

# The default scene (case M on the disk, curved boundary) under global
# refinement, both cell types (observed on triangles, made by splitting the
# disk's quadrilaterals: 2 3 3 3 iterations after the first). Catches: a
# curved boundary lost under refinement (rates fall to 1.5 in L2).
foreach(cell_type quadrilateral triangle)
  membranes_scene_test(default_disk_${cell_type} default.prm
    SETTINGS Refinement/Strategy=global Refinement/Cycles=5
             Geometry/Cell\ type=${cell_type} Output/Write\ vtu=false
    CHECKS ${DISPLACEMENT_RATES} ${NESTED_ITERATION})
endforeach()

# A degenerate free boundary (degenerate-free-boundary.prm: u1 - u2 ~ dist^3
# and lambda ~ dist^2 at the circle r = 1/2, no strict complementarity):
# the discrete contact zone of each finer mesh reaches O(h^(-1/3)) layers
# of vertices beyond the one interpolated from the coarser mesh, and the
# active set iterations stay bounded only through the prediction of the
# next active set (ActiveSetSolver; without it 3 4 3 5 6 6 after the first
# on cycles 1-6). Observed with it, after the first cycle: P1 global
# 2 3 2 3 3 (cycles 1-5), Q1 global 2 2 2 2 3, Q1 and P1 adaptive at most
# 2. The iteration bound catches a lost prediction; rates of the smooth
# problem (u1 - u2 is C^2, lambda C^1); expected values on both cell types.
foreach(cell_type quadrilateral triangle)
  membranes_scene_test(degenerate_free_boundary_${cell_type}
    degenerate-free-boundary.prm EXPECTED
    SETTINGS Geometry/Cell\ type=${cell_type} Refinement/Cycles=6
             Output/Write\ vtu=false
    CHECKS ${DISPLACEMENT_RATES} --rate err_lambda_L2>=0.9
           ${NESTED_ITERATION})
  membranes_scene_test(degenerate_free_boundary_adaptive_${cell_type}
    degenerate-free-boundary.prm EXPECTED
    SETTINGS Geometry/Cell\ type=${cell_type} Refinement/Strategy=adaptive
             Refinement/Cycles=12 Output/Write\ vtu=false
    CHECKS --max-after-first active_set_iterations<=2)
endforeach()

# The ellipse scene of benchmarks/peer_snesvi.sh (SCENE=ellipse): loads
# written out by hand for u2 = sin(pi x) sin(pi y) and a gap and an action
# vanishing to third and second order at an ellipse off the centre. The
# rates of the smooth problem catch wrong loads; expected values.
membranes_scene_test(ellipse_contact
  ${CMAKE_CURRENT_SOURCE_DIR}/scenes/ellipse-contact.prm EXPECTED
  SETTINGS Refinement/Cycles=5 Output/Write\ vtu=false
  CHECKS ${DISPLACEMENT_RATES} ${NESTED_ITERATION})
