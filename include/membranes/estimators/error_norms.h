#ifndef membranes_error_norms_h
#define membranes_error_norms_h

#include <array>
#include <deal.II/base/index_set.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/dual_mesh/dual_mesh.h>
#include <membranes/mesh/discretization.h>
#include <membranes/scene/problem_data.h>

namespace membranes
{
  using namespace dealii;

  /**
   * Errors against a known exact solution:
   * |u_i − u_ih|_{H1(ω)} and ‖u_i − u_ih‖_{L2(ω)} for both membranes, and
   * ‖λ − λ_h‖ on ω and on ω_h. λ_h is piecewise constant on the dual cells
   * D_a of the interior vertices, and ω_h is their union: ω minus a strip
   * along ∂ω of width O(h), where λ_h = 0. The paper's error (4.36) is the
   * one on ω; where λ does not vanish on ∂ω, the strip alone contributes
   * ‖λ‖_{L2(ω∖ω_h)} = O(h^{1/2}) to it.
   *
   * All integrals use the DualCellQuadrature of the Discretization, so
   * that each quadrature point knows the dual cell D_a it lies in and λ_h
   * is evaluated exactly (DualMesh); the same rule integrates the displacement
   * errors over the whole cell, in one pass: one call of the exact solution
   * (ProblemData::exact_solution_list(), compiled) gives u1, u2, their
   * gradients and λ together. VectorTools::integrate_difference() takes
   * one pass and one evaluation of the exact solution per norm and
   * membrane, five passes in all (benchmarks/README.md, "Error norms in
   * one pass"), and with QGauss(2) its L2 errors come out 2 to 6 % low
   * (the Gauss points are where the error of a bilinear interpolant is
   * smallest).
   */
  template <int dim>
  class ErrorNorms
  {
  public:
    using VectorType      = TrilinosWrappers::MPI::Vector;
    using BlockVectorType = TrilinosWrappers::MPI::BlockVector;

    struct Errors
    {
      std::array<double, 2> u_H1_seminorm; ///< |u_i − u_ih|_{H1(ω)}.
      std::array<double, 2> u_L2;          ///< ‖u_i − u_ih‖_{L2(ω)}.
      double                lambda_L2;     ///< ‖λ − λ_h‖_{L2(ω)}.
      double lambda_L2_omega_h;            ///< ‖λ − λ_h‖_{L2(ω_h)}.
    };

    ErrorNorms(const Discretization<dim> &discretization,
               const ProblemData<dim>    &data);

    /**
     * The errors of @p ghosted_solution (the blocks u1h, u2h, ghosted), with
     * @p lambda_h (DiscreteAction::lambda_h()) read on the dual cells of
     * @p dual_mesh.
     */
    Errors
    compute(const DoFHandler<dim> &dof_handler,
            const BlockVectorType &ghosted_solution,
            const DualMesh<dim>   &dual_mesh,
            const VectorType      &lambda_h,
            const MPI_Comm         mpi_communicator) const;

  private:
    const Discretization<dim> &discretization;
    const ProblemData<dim>    &data;
  };
} // namespace membranes

#endif
