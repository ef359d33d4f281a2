#ifndef membranes_coupled_system_h
#define membranes_coupled_system_h

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/block_indices.h>
#include <deal.II/lac/diagonal_matrix.h>
#include <membranes/active_set/active_set_system.h>

namespace membranes
{
  using namespace dealii;

  /**
   * The linear problem of one active set iteration on the coupled pair
   * (u1h, u2h), as deal.II's step-41 does it for one field.
   *
   * The unknowns of the system are those of the two blocks of the solution,
   * numbered block after block as deal.II's BlockIndices number them (the
   * DoFs of u1h, then those of u2h): one matrix of twice the size of the
   * mesh's, because Trilinos' direct solver and AMG work on one matrix.
   * On active vertices the contact constraint u1(a) = u2(a) is a line of an
   * AffineConstraints object in this numbering, merged with the hanging
   * node constraints and the boundary values u1 = g_h, u2 = g2_h of each
   * block (those of DiscreteProblem, built once per mesh). Every iteration
   * assembles its system anew from the rows of A (condensed with the
   * hanging node and boundary constraints already), block diagonal with
   * μ_i A on membrane i and the lifted loads, condensed with the contact
   * lines as distribute_local_to_global would condense them in a cell
   * loop: the equations of u1 and u2 at an active vertex are added, so the
   * solution of each iteration satisfies Prop. 12 (λ from either membrane) by
   * construction; on inactive vertices both equations hold, i.e. λ_a = 0. This
   * is the reference method: clear, and an assembly of the whole system per
   * iteration (its cost is in benchmarks/choices.md, "The matrices of an active
   * set from the mesh's A").
   *
   * The rows of the two membranes are forces of tensions μ1 and μ2, and of
   * μ1 + μ2 where the contact constraint adds them: for tension ratios far
   * from 1 they differ by orders of magnitude, and a Euclidean residual
   * bound would leave the rows of the softer membrane unresolved. CG
   * therefore solves the system scaled symmetrically by the tensions
   * (a LinearOperator D K D; the scaling is described in solve()), which
   * measures its residual as the two problems of DecoupledSystem measure theirs
   * (LinearTolerances).
   */
  template <int dim>
  class CoupledSystem : public ActiveSetSystem<dim>
  {
  public:
    using VectorType      = typename ActiveSetSystem<dim>::VectorType;
    using BlockVectorType = typename ActiveSetSystem<dim>::BlockVectorType;

    CoupledSystem(const Parameters::Solver &parameters,
                  const ProblemData<dim>   &data,
                  const MPI_Comm            mpi_communicator);

    /**
     * The constraints of both membranes of @p problem in the numbering of
     * the system, sparsity pattern and matrix for @p dof_handler; the
     * pattern has room for any active set.
     */
    void
    setup(const DiscreteProblem<dim> &problem,
          const DoFHandler<dim>      &dof_handler) override;

    /**
     * The constraints of @p active_set (its contact lines merged with the
     * constraints of the mesh), and the system assembled with them.
     */
    void
    set_active_set(const DiscreteProblem<dim> &problem,
                   const IndexSet             &active_set) override;

    void
    solve(const DiscreteProblem<dim> &problem,
          BlockVectorType            &solution,
          const LinearTolerances     &tolerances,
          ActiveSetStatistics        &statistics) override;

    /** The matrix, vectors, constraints and the AMG hierarchy. */
    void
    clear() override;

  private:
    /**
     * The unknowns of the system of the DoFs @p dofs of both blocks: the
     * index set of one block, and its copy shifted into the second.
     */
    IndexSet
    system_unknowns(const IndexSet &dofs) const;

    /** The system unknowns (u1 block, then u2) of the DoFs of a cell. */
    void
    get_system_indices(const std::vector<types::global_dof_index> &dofs,
                       std::vector<types::global_dof_index> &indices) const;

    /** The two blocks of @p solution into `system_solution`. */
    void
    copy_to_system(const BlockVectorType &solution);

    /** `system_solution` back into the two blocks of @p solution. */
    void
    copy_from_system(BlockVectorType &solution) const;

    /**
     * The system matrix and right-hand side of @p active_set on the mesh of
     * @p problem, from its Laplacian and lifted loads.
     */
    void
    assemble_system(const DiscreteProblem<dim> &problem,
                    const IndexSet             &active_set);

    /**
     * The diagonal D = diag(m_j^{-1/2}) of the scaling of the system of
     * @p active_set on the mesh of @p problem, and its inverse, in place
     * (locally owned entries; see solve()).
     */
    void
    set_scaling(const DiscreteProblem<dim> &problem,
                const IndexSet             &active_set);
    /** The numbering of the unknowns: block 0 (u1), then block 1 (u2). */
    BlockIndices block_indices;

    /** Hanging node and boundary constraints of the mesh. */
    AffineConstraints<double> mesh_constraints;
    /** The same with the contact lines of the current active set. */
    AffineConstraints<double> constraints;

    TrilinosWrappers::SparseMatrix system_matrix;
    VectorType                     system_rhs;
    /**
     * The iterate in the numbering of the system: the two blocks of the
     * solution one after the other in its local storage.
     */
    VectorType system_solution;
    /**
     * The scaling D of the system (see solve()) for the current active set,
     * and D⁻¹: allocated once per mesh, set on every iteration.
     */
    DiagonalMatrix<VectorType> scaling, inverse_scaling;
  };
} // namespace membranes

#endif
