#ifndef membranes_error_norms_h
#define membranes_error_norms_h

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/dual_mesh/dual_mesh.h>
#include <membranes/mesh/discretization.h>
#include <membranes/output/report.h>
#include <membranes/scene/problem_data.h>

namespace membranes
{
  using namespace dealii;

  /**
   * Where the exact λ jumps: the cells on which λ (or λ − λ_h) varies by
   * more than this share of max |λ_h|. A smooth λ varies across a cell by
   * O(h), a jump by its height. The error norms of λ (ErrorNorms,
   * NegativeNorm) integrate these cells by finer rules.
   */
  constexpr double lambda_jump_fraction = 0.1;



  /**
   * Errors against a known exact solution:
   * |u_i − u_ih|_{H1(ω)} and ‖u_i − u_ih‖_{L2(ω)} for both membranes, and
   * ‖λ − λ_h‖ on ω and on ω_h. λ_h is piecewise constant on the dual cells
   * D_a of the interior vertices, and ω_h is their union: ω minus a strip
   * along ∂ω of width O(h), where λ_h = 0. The paper's error (4.36) is the
   * one on ω; where λ does not vanish on ∂ω, the strip alone contributes
   * ‖λ‖_{L2(ω∖ω_h)} = O(h^{1/2}) to it.
   *
   * Those of the six that `Exact solution/Norms` names, in one pass over
   * the cells, with one call of the exact solution per cell
   * (ProblemData::exact_solution_list(), compiled: u1, u2, their gradients
   * and λ together) at the points of two rules:
   *
   * - the displacement errors: the cell rule of the Discretization
   *   (QGaussSimplex(3) on triangles, QGauss(3) on quadrilaterals), exact
   *   to degree 5. On a cell, u − u_h is to leading order a quadratic (the
   *   error of the linear or bilinear interpolant), so (u − u_h)² is of
   *   degree 4 and |∇(u − u_h)|² of degree 2 there: the rule integrates
   *   their leading terms exactly, and its relative error falls with h
   *   (a rule of degree 3 on the sub-triangles would leave a bias that
   *   does not);
   * - the λ errors: a DualCellQuadrature, the 3-point rule of degree 2 on
   *   each sub-triangle κ = (a, m_e, b_K), so that each point knows the
   *   dual cell D_a it lies in and λ_h is exact there (DualMesh). Where λ
   *   is smooth, λ − λ_h is on κ a constant plus O(h) linear terms, whose
   *   square the rule integrates exactly. Where λ jumps inside κ (case M:
   *   across the circle r = 1/2, which no mesh line follows), no fixed rule
   *   converges: on a cell where λ at the points of both rules and at the
   *   vertices varies by more than a tenth of max |λ_h|, each κ is refined
   *   recursively where λ varies across it (JumpRefinement in the source),
   *   down to triangles 2^5 times smaller. A smooth λ varies across a cell
   *   by O(h), so that only coarse meshes are refined there. An interface
   *   that crosses a cell cuts off at least one of its vertices (unless it
   *   enters and leaves through one edge), which is why λ is also taken at
   *   the vertices, alone (ProblemData::exact_action_list(): u may be
   *   singular there).
   *
   * The quadrature error of these rules: benchmarks/estimators.md,
   * "`error_quadrature.sh`". VectorTools::integrate_difference() takes the
   * quadrature as an argument too, but makes one pass and one evaluation
   * of the exact solution per norm and membrane (benchmarks/choices.md,
   * "Error norms in one pass").
   */



  template <int dim>
  class ErrorNorms
  {
  public:
    using VectorType      = TrilinosWrappers::MPI::Vector;
    using BlockVectorType = TrilinosWrappers::MPI::BlockVector;

    /**
     * With @p reference_levels > 0, every error is integrated instead by
     * the composite rule: each sub-triangle cut into 4^{reference_levels}
     * triangles with QGaussSimplex(2) on each, and no refinement at jumps
     * (the reference of benchmarks/error_quadrature.sh).
     */
    ErrorNorms(const Discretization<dim> &discretization,
               const ProblemData<dim>    &data,
               const unsigned int         reference_levels = 0);

    /**
     * The errors of @p ghosted_solution (the blocks u1h, u2h, ghosted), with
     * @p lambda_h (DiscreteAction::lambda_h()) read on the dual cells of
     * @p dual_mesh, that @p exact names in `Norms`: of ErrorRecord all but
     * lambda_Hm1 (NegativeNorm's). The pass integrates the displacement
     * errors only if one of them is asked for, and the L² errors of the
     * action likewise; none asked for, it makes no pass.
     */
    ErrorRecord
    compute(const DoFHandler<dim>           &dof_handler,
            const BlockVectorType           &ghosted_solution,
            const DualMesh<dim>             &dual_mesh,
            const VectorType                &lambda_h,
            const Parameters::ExactSolution &exact,
            const MPI_Comm                   mpi_communicator) const;

  private:
    const Discretization<dim>    &discretization;
    const ProblemData<dim>       &data;
    const unsigned int            reference_levels;
    const DualCellQuadrature<dim> lambda_rule;
    const Quadrature<dim>         u_rule;
  };
} // namespace membranes

#endif
