#ifndef membranes_flux_equilibration_h
#define membranes_flux_equilibration_h

#include <deal.II/fe/fe_values.h>
#include <map>
#include <membranes/flux/flux_patch_problem.h>
#include <membranes/flux/flux_reconstruction.h>
#include <utility>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The equilibrated fluxes σ_ih ∈ Z_h = RT0(S_h), i = 1, 2, of the flux
   * estimator, on the sub-triangles of a FluxReconstruction and from the
   * terms its reconstruct() computed there.
   *
   * For the flux estimator (see ErrorEstimator) the fluxes are
   * equilibrated patch by patch on the primal mesh (Braess and Schöberl;
   * Ern and Vohralík), with RT0 on the sub-mesh S_h:
   *
   *   σ_ih = Σ_a σ_ih^a,
   *
   * the sum over all vertices a that carry a degree of freedom (interior,
   * on ∂ω, not hanging), each σ_ih^a ∈ RT0(S_h) living on the support ω_a
   * of the condensed hat function φ_a (φ_a plus the constraint weights of
   * the hanging vertices with parent a, so that Σ_a φ_a = 1) with
   *
   *   ∫_κ div σ_ih^a = ∫_κ r_ia,  r_ia = (f_i + s_i λ_a) φ_a
   *                                      − μ_i ∇u_ih·∇φ_a,
   *
   * on every sub-triangle κ (s_1 = 1, s_2 = −1), zero normal flux on
   * ∂ω_a inside ω, and on ∂ω the normal flux of −μ_i φ_a ∇u_ih plus what
   * ∫ r_ia leaves over, spread over the half-edges of ∂ω ∩ ∂ω_a in
   * proportion to ∫ φ_a on them. Around an interior vertex the patch
   * problem is solvable because ∫ r_ia = 0 is (4.5) for the condensed φ_a
   * (quadrature and solver leave O(round-off), spread as a constant). Then
   *
   *   div σ_ih = Π_0 (f_i + s_i λ̃_h)  on every κ,  λ̃_h = Σ_a λ_a φ_a,
   *
   * the P1/Q1 function with the nodal values λ_a (λ̃_h ≥ 0; the estimator
   * uses it in its residual and contact terms). Among these fields σ_ih^a
   * minimizes, in L², the distance to the RT0 field T_ia with the fluxes
   * of −μ_i φ_a ∇u_ih through the edges of S_h (through a half-edge
   * between two cells the mean of both sides). The T_ia add up to a
   * conforming field, and where u_ih is linear they satisfy the
   * constraints themselves: then σ_ih^a = T_ia and σ_ih = −μ_i ∇u_ih
   * exactly, which the tests check. (Minimizing the distance to
   * −μ_i φ_a ∇u_ih itself instead loses this: the sum of the patch
   * minimizers is then off by O(|∇u_ih|) in a strip of cells along ∂ω
   * and wherever the mesh changes direction, an effectivity that grows
   * like h^{−1/2}.) At an edge with a hanging node T_ia is made to take
   * one flux density on the two halves of a small edge, which keeps this
   * exactness (see PatchProblem::compute_targets()).
   *
   * The sum of the patch minimizers is not the field of RT0(S_h) with
   * this divergence that is closest to −μ_i ∇u_ih. Divergence-free
   * corrections bring it closer, and the flux estimator only decreases:
   * rotations around the vertices of S_h not on ∂ω (relax_rotations()),
   * then, inside each cell, the curls of the edge bubbles of the edges of
   * S_h through b_K (relax_cell_rotations()).
   *
   * Each patch problem is a PatchProblem; the sub-triangles and their
   * Raviart–Thomas basis are a SubTriangleBasis.
   *
   * On several processes the support of a condensed φ_a can reach beyond
   * the ghost layer of a process that owns one of its cells. Each process
   * therefore writes, for its owned cells, what the patch problems need
   * into PatchRecords (with the half-edges named by the global DoF indices
   * of their end vertices, the same on every process), sends them
   * to the owner of a, which solves the patch problem and sends σ_ih^a back
   * (Utilities::MPI::some_to_some).
   */
  template <int dim>
  class FluxEquilibration
  {
  public:
    using VectorType   = TrilinosWrappers::MPI::Vector;
    using CellIterator = typename DoFHandler<dim>::active_cell_iterator;
    using PatchTerms   = typename FluxReconstruction<dim>::PatchTerms;

    /**
     * The equilibration of the fluxes of @p reconstruction, which must
     * live as long as this object.
     */
    explicit FluxEquilibration(const FluxReconstruction<dim> &reconstruction)
      : reconstruction(reconstruction)
      , basis(reconstruction.sub_triangle_basis())
    {}

    /**
     * σ_ih = Σ_a σ_ih^a on the locally owned cells, by the patch problems
     * on the supports of the condensed hat functions φ_a (see the class
     * comment), each solved by the owner of a on the records of its cells,
     * with @p patch_terms from FluxReconstruction::reconstruct() and the
     * λ_a of @p lambda_h (DiscreteAction::lambda_h()); then the rotations.
     * @p dof_handler is the one of the last reconstruct() (one DoF per
     * vertex), @p hanging_node_constraints and @p locally_owned_dofs are
     * its own, by which the vertices a and their owners are found.
     */
    void
    equilibrate(const DoFHandler<dim>           &dof_handler,
                const AlignedVector<PatchTerms> &patch_terms,
                const VectorType                &lambda_h,
                const AffineConstraints<double> &hanging_node_constraints,
                const IndexSet                  &locally_owned_dofs,
                const MPI_Comm                   mpi_communicator);

    /**
     * σ_ih and div σ_ih of membrane @p i at the points of
     * Discretization::dual_cell_quadrature on the cell @p fe_values was last
     * reinit'ed on (with update_jacobians).
     */
    void
    flux_values(const CellIterator          &cell,
                const unsigned int           i,
                const FEValues<dim>         &fe_values,
                std::vector<Tensor<1, dim>> &fluxes,
                std::vector<double>         &divergences) const;

    /** The reconstruction whose fluxes are equilibrated. */
    const FluxReconstruction<dim> &
    get_reconstruction() const
    {
      return reconstruction;
    }

  private:
    /** The coefficients of a condensed φ_a in the hat functions of a cell. */
    using HatCoefficients =
      std::array<double, GeometryInfo<dim>::vertices_per_cell>;

    /** The outward normal fluxes through the edges of a sub-triangle, per i. */
    using Fluxes = std::array<std::array<double, 3>, 2>;

    /**
     * A cell K in the support of the condensed hat function φ_a, with the
     * coefficients of φ_a in the hat functions of K's vertices (1 at a, the
     * constraint weight at a hanging vertex with parent a).
     */
    struct PatchMember
    {
      types::global_dof_index a;
      CellIterator            cell;
      HatCoefficients         coefficients;
    };

    /**
     * The records exchanged with other processes: the cells whose records
     * went to each process, the records received from each process, by the
     * vertex a the records of its patch (process, record of a cell), and
     * the buffers of the answers, σ_ih^a on the received sub-triangles.
     */
    struct RemotePatches
    {
      std::map<unsigned int, std::vector<CellIterator>> sent;
      std::map<unsigned int, std::vector<PatchRecord>>  received;
      std::map<types::global_dof_index,
               std::vector<std::pair<unsigned int, unsigned int>>>
                                                  members;
      std::map<unsigned int, std::vector<double>> replies;
    };

    /** The work arrays of one thread of solve_patches(). */
    struct PatchScratch;
    struct PatchCopy;

    /**
     * The members of the patches of the owned cells, in the order of the
     * cells and, on each cell, by increasing a.
     */
    std::vector<PatchMember>
    patch_members(
      const DoFHandler<dim>           &dof_handler,
      const AffineConstraints<double> &hanging_node_constraints) const;

    /**
     * Send the records of @p remote_members to the owners of their a and
     * receive the records of the patches of the owned vertices.
     */
    RemotePatches
    send_patch_records(const std::vector<PatchMember>  &remote_members,
                       const AlignedVector<PatchTerms> &patch_terms,
                       const IndexSet                  &locally_owned_dofs,
                       const MPI_Comm                   mpi_communicator) const;

    /**
     * The patch problems of the owned vertices, on threads, with the
     * members @p local_members (sorted by a) and the records of @p remote;
     * adds σ_ih^a on the owned cells, writes it to the replies of @p remote
     * on the others.
     */
    void
    solve_patches(const std::vector<PatchMember>  &local_members,
                  const AlignedVector<PatchTerms> &patch_terms,
                  const VectorType                &lambda_h,
                  RemotePatches                   &remote);

    /**
     * Write the records of the sub-triangles of @p cell (in the order of
     * the ring) for the patch problem of the condensed hat function φ_a
     * with @p coefficients on @p cell to @p record.
     */
    void
    write_patch_record(const CellIterator              &cell,
                       const types::global_dof_index    a,
                       const HatCoefficients           &coefficients,
                       const AlignedVector<PatchTerms> &patch_terms,
                       PatchRecord                     *record) const;

    /** Add the fluxes @p result of one patch problem to σ_ih on @p cell. */
    void
    add_patch_result(const CellIterator &cell, const double *result);

    struct Rotations;

    /** The rotations around the vertices of S_h (see the .cc file). */
    void
    relax_rotations(const DoFHandler<dim> &dof_handler);

    /** The rotations of relax_rotations() (see the .cc file). */
    Rotations
    rotations_around_vertices(const DoFHandler<dim> &dof_handler) const;

    /** Sweeps of relax_rotations(). */
    static constexpr unsigned int rotation_sweeps = 3;

    /** The rotations inside each cell (see the .cc file). */
    void
    relax_cell_rotations(const DoFHandler<dim> &dof_handler);

    const FluxReconstruction<dim> &reconstruction;
    const SubTriangleBasis<dim>   &basis;

    /**
     * By active cell index × sub-triangles per cell + sub-triangle: the
     * fluxes of σ_ih, and the coefficients of the rotations inside the cell
     * (the curls β_l of the edge bubbles of the edges l = 0, 1 of κ, those
     * through b_K; see relax_cell_rotations()), per i.
     */
    std::vector<Fluxes>                               sigma;
    std::vector<std::array<std::array<double, 2>, 2>> cell_rotations;
  };
} // namespace membranes

#endif
