#ifndef membranes_linear_embedding_h
#define membranes_linear_embedding_h

#include <deal.II/base/partitioner.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/la_parallel_vector.h>
#include <memory>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The embedding P of the space V_1 of degree 1 into the space V_p of
   * degree p on the same mesh, both continuous and zero on ∂ω, and its
   * transpose, applied cell by cell without a matrix (the two-level
   * transfer of deal.II's step-75, for the single step from p to 1).
   *
   * A function v of V_1 is a function of V_p (V_1 ⊂ V_p), whose nodal values
   * are its values at the nodes x_i of V_p: (P V)_i = Σ_J φ_J(x_i) V_J. On a
   * cell K these are the entries of the interpolation matrix of the
   * reference cell (FETools::get_interpolation_matrix), the same on every
   * cell. A DoF of V_1 that a hanging node constrains is replaced by its
   * masters; the rows of the DoFs of V_p that the constraints of V_p
   * take (hanging nodes, ∂ω) are zero, as the operator on V_p leaves them
   * out.
   *
   * Each unconstrained, locally owned DoF i of V_p is assigned to one
   * locally owned cell that holds it (the first in the order of the cells):
   * prolongate() writes (P V)_i there, restrict_and_add() adds φ_J(x_i) R_i to
   * the DoFs J of V_1 there, so that each row of P is taken once. Only the
   * indices are stored: about 1.25 integers a DoF of V_p and four (P1:
   * three) per cell.
   */
  template <int dim>
  class LinearEmbedding
  {
  public:
    using VectorType = LinearAlgebra::distributed::Vector<double>;

    /**
     * The embedding of the space of @p linear_dof_handler (degree 1, with
     * @p linear_constraints) into that of @p dof_handler (with
     * @p constraints), for vectors of V_p with the layout of
     * @p partitioner.
     */
    LinearEmbedding(
      const DoFHandler<dim>                                    &dof_handler,
      const AffineConstraints<double>                          &constraints,
      const std::shared_ptr<const Utilities::MPI::Partitioner> &partitioner,
      const DoFHandler<dim>           &linear_dof_handler,
      const AffineConstraints<double> &linear_constraints);

    /** @p vector with the layout (owned and ghost DoFs) of V_1. */
    void
    initialize_linear_vector(VectorType &vector) const;

    /** @p dst = P @p src, for @p src of V_1 and @p dst of V_p. */
    void
    prolongate(VectorType &dst, const VectorType &src) const;

    /** @p dst += Pᵀ @p src, for @p src of V_p and @p dst of V_1. */
    void
    restrict_and_add(VectorType &dst, const VectorType &src) const;

  private:
    /** φ_J(x_i) on the reference cell, for the DoFs i of V_p, J of V_1. */
    FullMatrix<double> interpolation;

    /**
     * For each locally owned cell c, the DoFs of V_p assigned to it: their
     * positions i on the cell in cell_positions and their local indices
     * in the vectors of V_p in cell_dofs, from cell_offsets[c] to
     * cell_offsets[c + 1].
     */
    std::vector<unsigned int>  cell_offsets;
    std::vector<unsigned char> cell_positions;
    std::vector<unsigned int>  cell_dofs;

    /**
     * For each locally owned cell c and each of its DoFs J of V_1, the
     * local indices (in the vectors of V_1) and weights of the DoFs it
     * stands for: itself with weight one, or the masters of its
     * constraint, from linear_offsets[c·n + J] to linear_offsets[c·n + J +
     * 1] (n DoFs a cell).
     */
    std::vector<unsigned int> linear_offsets;
    std::vector<unsigned int> linear_dofs;
    std::vector<double>       linear_weights;

    /** The owned and ghost DoFs of V_1: the locally relevant ones. */
    std::shared_ptr<const Utilities::MPI::Partitioner> linear_partitioner;
  };
} // namespace membranes

#endif
