# The flux reconstruction of the paper's section 4.2 and the flux
# estimator.

# The flux reconstruction of the paper's section 4.2
# (Output/Flux reconstruction = true), with expected values of the flux
# estimator and its parts. On triangles the identities hold to round-off
# (FLUX_IDENTITIES), also with hanging nodes (condensed hat functions);
# the estimator's effectivity is observed 1.025 (P1) and 1.014 (Q1) on the
# last of six cycles of case M. The files catch a dual mesh not written.
membranes_scene_test(flux_case_m_triangle case-m-triangle.prm EXPECTED
  SETTINGS Refinement/Cycles=6 Output/Flux\ reconstruction=true
  CHECKS ${FLUX_IDENTITIES} ${FLUX_EFFECTIVITY}
  FILES --present dual-mesh-05.vtu --present dual-mesh.pvd --absent *.tmp)
# On quadrilaterals (4.18) is not exact: its defect is reported and falls
# like h^2 (observed 8.9e-3 on the first cycle, 2.5e-6 on the sixth); on
# the parallelograms of this mesh (4.17) still holds.
membranes_scene_test(flux_case_m_quadrilateral case-m-quadrilateral.prm
  EXPECTED
  SETTINGS Refinement/Cycles=6 Output/Flux\ reconstruction=true
           Output/Write\ vtu=false
  CHECKS --max measure_defect<=1e-12 --decreasing conservation_defect
         --max-last conservation_defect<=1e-5 ${FLUX_EFFECTIVITY})
# With hanging nodes: case M on triangles refined by the flux estimator
# (observed 1.042 on the last cycle).
membranes_scene_test(flux_case_m_adaptive_triangle case-m-triangle.prm
  EXPECTED
  SETTINGS Refinement/Strategy=adaptive Refinement/Cycles=10
           Refinement/Estimator=flux Output/Flux\ reconstruction=true
           Output/Write\ vtu=false
  CHECKS ${FLUX_IDENTITIES} ${FLUX_EFFECTIVITY} --band flux_effectivity<=2
         --hanging-nodes 3 --dof-rate err_energy>=0.45)
# Refinement/Estimator = flux on its own computes the fluxes, the flux
# estimator and its parts, and writes neither the identity defects nor
# the dual mesh (that is Output/Flux reconstruction's). Catches: the
# estimator's parts or the flux time not reported, or the reconstruction's
# output written unasked.
membranes_scene_test(flux_estimator_alone case-m-quadrilateral.prm
  SETTINGS Refinement/Strategy=adaptive Refinement/Cycles=4
           Refinement/Estimator=flux
  CHECKS --filled flux_estimator --filled flux_effectivity
         --filled flux_estimator_flux --filled flux_estimator_oscillation
         --filled flux_estimator_contact --filled flux_estimator_boundary
         --filled time_flux_s --empty measure_defect
         --empty conservation_defect --empty balance_defect
         --min flux_effectivity>=1
  FILES --present solution-03.vtu --absent dual-mesh-*.vtu
        --absent dual-mesh.pvd)
# The L-shape refined by the flux estimator keeps the optimal rate, and
# the estimator stays within 1.1 of the error: observed 1.057 (Q1, 13
# cycles) and 1.047 (P1, 11 cycles).
membranes_scene_test(lshape_adaptive_flux lshape.prm EXPECTED
  SETTINGS Refinement/Cycles=13 Refinement/Estimator=flux
           Output/Flux\ reconstruction=true Output/Write\ vtu=false
  CHECKS --dof-rate err_energy>=0.45 ${FLUX_EFFECTIVITY}
         --band flux_effectivity<=2 --hanging-nodes 3)
membranes_scene_test(lshape_adaptive_flux_triangle lshape.prm
  SETTINGS Geometry/Cell\ type=triangle Refinement/Cycles=11
           Refinement/Estimator=flux Output/Flux\ reconstruction=true
           Output/Write\ vtu=false
  CHECKS --dof-rate err_energy>=0.45 ${FLUX_EFFECTIVITY} ${FLUX_IDENTITIES})
# Effectivity of the flux estimator per class (cell type, uniform or
# adaptive), on the scenes of the two classes with exact solutions
# (benchmarks/flux_effectivity.sh measures every shipped scene to
# >= 2e4 DoFs): <= 1.1 on the last cycle, both cell types.
# A circular free boundary on the disk, loads that jump across it
# (measured 1.057 on P1, cycle 8; 1.031 on Q1, cycle 11); expected values
# of the contact part on P1:
membranes_scene_test(flux_disk_contact_p1_adaptive disk-contact.prm EXPECTED
  SETTINGS Geometry/Cell\ type=triangle Refinement/Cycles=9
           Output/Write\ vtu=false
  CHECKS ${FLUX_EFFECTIVITY})
membranes_scene_test(flux_disk_contact_q1_adaptive disk-contact.prm
  SETTINGS Refinement/Cycles=12 Output/Write\ vtu=false
  CHECKS ${FLUX_EFFECTIVITY})
# A straight free boundary on no mesh line, mu1 = mu2 (measured 1.027 on
# P1 adaptive, cycle 10, hanging nodes; 1.022 on Q1 uniform, cycle 5):
membranes_scene_test(flux_straight_free_boundary_p1_adaptive
  straight-free-boundary.prm
  SETTINGS Geometry/Cell\ type=triangle Refinement/Cycles=11
           Output/Write\ vtu=false
  CHECKS ${FLUX_EFFECTIVITY} --hanging-nodes 3)
membranes_scene_test(flux_straight_free_boundary_q1_uniform
  straight-free-boundary.prm
  SETTINGS Refinement/Strategy=global Refinement/Cycles=6
           Output/Write\ vtu=false
  CHECKS ${FLUX_EFFECTIVITY})
# Full contact meets the conditions under which the flux estimator is a
# guaranteed bound (boundary data linear on the boundary edges, loads of
# degree 2, convex cells): effectivity >= 1 on every cycle (measured
# 1.038 on P1 with 33 282 DoFs, 1.078 on Q1 with 33 282 DoFs on the last
# cycle), and no boundary term (catches a boundary term that does not
# vanish for linear boundary data).
foreach(cell_type quadrilateral triangle)
  if(cell_type STREQUAL quadrilateral)
    set(cycles 6)
  else()
    set(cycles 5)
  endif()
  membranes_scene_test(flux_full_contact_${cell_type} full-contact.prm
    SETTINGS Geometry/Cell\ type=${cell_type} Refinement/Cycles=${cycles}
             Refinement/Estimator=flux Output/Write\ vtu=false
    CHECKS ${FLUX_EFFECTIVITY} --max flux_estimator_boundary<=1e-12)
endforeach()
# The equilibrated flux reproduces linear displacements: with u1, u2
# linear (no contact), u_ih = u_i and sigma_ih = -mu_i grad u_ih exactly, so
# the flux estimator vanishes up to round-off and solver noise (observed:
# 2e-15 on Q1; on P1 the square root of the contact term of the lambda_a
# noise, 8.6e-7 on cycle 2). On the coupled method: the decoupled one
# recovers u1, u2 from two solves, which doubles the noise of lambda_a
# (min lambda_a -1.0e-12 against -6.8e-13), and the estimator reaches 1.1e-6.
# Also with hanging nodes: refined adaptively by the flux estimator (which
# then marks cells by its round-off; 19 to 43 cells on Q1), its flux part
# to round-off (observed <= 6.5e-15; 6.0e-3 while the fine side of an edge
# with a hanging node had one target density per half-edge), and the
# identities of the fluxes t_ih to round-off on both cell types (for
# linear u_ih (4.18) holds on quadrilaterals too). Catches: any term of
# the flux or of sigma_ih that is not exact for linear functions.
set(FLUX_LINEAR_SETTINGS Solver/Method=coupled Solver/Linear\ solver=direct
  Problem/f1=0 Problem/f2=0 Problem/g=x+y/2+3 Problem/g2=y/2-x
  Exact\ solution/u1=x+y/2+3 Exact\ solution/u2=y/2-x
  Output/Flux\ reconstruction=true Output/Write\ vtu=false)
foreach(cell_type quadrilateral triangle)
  membranes_scene_test(flux_linear_${cell_type} no-contact.prm QUICK
    SETTINGS Geometry/Cell\ type=${cell_type} Refinement/Cycles=3
             ${FLUX_LINEAR_SETTINGS}
    CHECKS --max flux_estimator<=1e-6)
  membranes_scene_test(flux_linear_adaptive_${cell_type} no-contact.prm QUICK
    SETTINGS Geometry/Cell\ type=${cell_type} Refinement/Cycles=5
             Refinement/Strategy=adaptive Refinement/Estimator=flux
             ${FLUX_LINEAR_SETTINGS}
    CHECKS --max flux_estimator<=1e-6 --max flux_estimator_flux<=1e-12
           ${FLUX_IDENTITIES})
endforeach()
