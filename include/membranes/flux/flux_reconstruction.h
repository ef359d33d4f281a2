#ifndef membranes_flux_reconstruction_h
#define membranes_flux_reconstruction_h

#include <array>
#include <deal.II/base/aligned_vector.h>
#include <deal.II/base/array_view.h>
#include <deal.II/base/data_out_base.h>
#include <deal.II/base/index_set.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/dual_mesh/discrete_action.h>
#include <membranes/dual_mesh/dual_cell_quadrature.h>
#include <membranes/dual_mesh/dual_mesh.h>
#include <membranes/flux/flux_sub_triangles.h>
#include <membranes/mesh/discretization.h>
#include <membranes/scene/problem_data.h>
#include <string>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The objects of §4.2–4.3 of the paper on the current mesh: the dual mesh
   * D_h, λ_h as a function on it, and the flux reconstructions t_ih,
   * i = 1, 2, of (4.13) in the Raviart–Thomas space Z_h = RT0(S_h) of
   * (4.12) with the identities (4.17), (4.18) and Lemma 17. The
   * equilibrated fluxes σ_ih ∈ Z_h of the flux estimator are
   * FluxEquilibration's, from the terms that reconstruct() computes on the
   * same sub-triangles.
   *
   * λ_h comes from DiscreteAction::lambda_h(), the dual cells from the
   * DualCellQuadrature of the Discretization on the pieces K ∩ D_a.
   *
   * <h3>The fluxes t_ih (4.13)</h3>
   * On every sub-triangle κ = (a, m_e, b_K) ⊂ K, t_ih is the lowest order
   * Raviart–Thomas field given by its three normal fluxes. On the two edges
   * of κ inside K (m_e–b_K on ∂D_a, a–b_K inside D_a) the flux is that of
   * the discrete flux of K,
   *
   *   ∫_e t_ih·n = −μ_i ∫_e ∇(u_ih|_K)·n,                            (4.13)
   *
   * so that t_ih is H(div)-conforming inside K. The remaining degree of
   * freedom of κ is the flux through its half-edge a–m_e ⊂ ∂K, which κ
   * shares with a sub-triangle κ' of the neighbour K'. It is chosen by
   * local minimization: with the prescribed part P_κ of t_ih on κ (zero
   * flux through a–m_e) and the Raviart–Thomas basis function ψ_κ of unit
   * outward flux through a–m_e, the common normal flux density s across
   * the half-edge minimizes
   *
   *   Σ_κ ‖μ_i^{-1/2} (P_κ + σ_κ ℓ_κ s ψ_κ) + μ_i^{1/2} ∇u_ih‖²_κ
   *
   * over the sub-triangles κ that touch it (ℓ_κ the length of κ's piece of
   * the half-edge, σ_κ = ±1 its orientation), which is the distance of
   * t_ih from the discrete flux −μ_i ∇u_ih that the flux estimator
   * measures. This is the local minimization on D_a of the paper's
   * reference [14], and it decouples: each half-edge is an independent
   * one-dimensional problem,
   *
   *   s = Σ_κ σ_κ ℓ_κ (−μ_i ∇u_ih − P_κ, ψ_κ)_κ / Σ_κ ℓ_κ² ‖ψ_κ‖²_κ.
   *
   * On triangles, where −μ_i ∇u_ih is a constant in RT0(κ), s is the mean
   * of the two one-sided fluxes of the neighbours weighted by ‖ψ_κ‖²_κ.
   * The flux through half-edges on ∂ω is its own cell's (one κ). Since all
   * half-edges a–m_e lie inside D_a, whatever their fluxes,
   * ∫_{D_a} div t_ih = ∫_{∂D_a} t_ih·n involves only the fluxes (4.13), and
   *
   *   μ_i ∫ ∇u_ih·∇φ_a = ∫_{D_a} div t_ih                            (4.18)
   *
   * holds on triangles (P1 gradients are constant on K).
   *
   * <h3>Hanging nodes</h3>
   * On an edge e of a coarse cell that holds a hanging vertex c, the two
   * half-edges of e are covered from the other side by the four half-edges
   * of the two small edges. The normal flux density is taken constant on
   * all of e (one unknown s for the six sub-triangles along e, by the same
   * minimization): t_ih is then H(div)-conforming across e, and (4.17) and
   * (4.18) hold on triangles for the condensed hat functions φ_a = φ_a +
   * Σ_c w_ca φ_c of the hanging node constraints, with D_a replaced by the
   * weighted union Σ_c w_ca D_c: the coarse side's flux through the part
   * of e in D_c, weighted by w_ca = 1/2 for both parents a, cancels the
   * fine side's exactly when the density is the same on both halves of e.
   *
   * <h3>Quadrilaterals</h3>
   * The construction is the same on the pieces of Q1 cells, with the
   * Raviart–Thomas fields mapped from the reference sub-triangles by the
   * contravariant Piola transform t = DF t̂ / |det DF| of the bilinear map
   * (which keeps normal fluxes through mapped edges, so t_ih is again
   * H(div)-conforming; the same transform on triangles is the affine one) and
   * the fluxes (4.13) integrated along the edges. The gradient of a Q1
   * function is not constant on K, so (4.17) and (4.18) no longer hold
   * exactly: identities() reports their defects instead.
   *
   * The sub-triangles and their Raviart–Thomas basis are a
   * SubTriangleBasis.
   */
  template <int dim>
  class FluxReconstruction
  {
  public:
    using VectorType      = TrilinosWrappers::MPI::Vector;
    using BlockVectorType = TrilinosWrappers::MPI::BlockVector;
    using CellIterator    = typename DoFHandler<dim>::active_cell_iterator;

    /** The defects of the identities of §4.3, relative to the data. */
    struct Identities
    {
      /**
       * (4.17): max over a ∈ V_h of |meas(D_a) − d_a| / d_a, with D_a the
       * weighted union of dual cells of the condensed φ_a.
       */
      double measure_defect = 0;
      /**
       * (4.18): max over a and i of |∫_{D_a} div t_ih − μ_i ∫ ∇u_ih·∇φ_a|
       * / F, F the force scale of (4.5).
       */
      double conservation_defect = 0;
      /**
       * Lemma 17, step 4: max over a and i of
       * |±λ_a meas(D_a) − ∫_{D_a}(div t_ih − f_ih) + ∫(f_i − f_ih) φ_a| / F
       * with λ_a from membrane i's formula of (4.5) and f_ih the mean of
       * f_i on each cell (4.14).
       */
      double balance_defect = 0;
    };

    FluxReconstruction(const Discretization<dim> &discretization,
                       const ProblemData<dim>    &data)
      : discretization(discretization)
      , data(data)
      , dual_cell_quadrature(discretization.dual_cell_quadrature)
      , basis(dual_cell_quadrature, *discretization.fe)
    {}

    /**
     * An edge or a half-edge of the mesh, by the global DoF indices of its
     * end vertices (one per vertex, the same in both blocks), which are
     * exact and the same on every process: an edge by its two ends in
     * increasing order, the half-edge a–m_e of the edge (a, b) by (a, b). (Two
     * vertices end at most one edge, and an edge is named either whole or by
     * its two halves, so names never meet.)
     */
    using EdgeKey = std::array<types::global_dof_index, 2>;

    /**
     * What the reconstruction keeps of one sub-triangle κ. The type is
     * trivial: the arrays of all sub-triangles are allocated without
     * initial values, and the cell loop of reconstruct() sets the entries of
     * each cell to zero (SubTriangleData{}) on the thread that fills them,
     * instead of a serial pass over hundreds of megabytes before it.
     */
    struct SubTriangleData
    {
      /** Outward normal fluxes of t_ih through the edges of κ, per i. */
      std::array<std::array<double, 3>, 2> fluxes;
      /** (ψ_k, ψ_l)_κ for the mapped Raviart–Thomas basis of κ. */
      std::array<std::array<double, 3>, 3> gram;
      /** (μ_i ∇u_ih, ψ_k)_κ. */
      std::array<std::array<double, 3>, 2> discrete_flux;
      /**
       * (β_l, β_m)_κ for the curls β_l of the edge bubbles 4 λ_p λ_q of the
       * edges l = 0, 1 of κ, those through b_K (the rotations inside a cell
       * of FluxEquilibration).
       */
      std::array<std::array<double, 2>, 2> rotation_gram;
      /** (ψ_k, β_l)_κ. */
      std::array<std::array<double, 2>, 3> mixed_gram;
      /** (μ_i ∇u_ih, β_l)_κ. */
      std::array<std::array<double, 2>, 2> discrete_rotation;
      /** ∫_κ f_i. */
      std::array<double, 2> load;
      double                area;
    };

    /**
     * The terms of the patch problems of FluxEquilibration on one
     * sub-triangle κ: for the hat function φ_v of each vertex v of the cell
     * ∫_κ (f_i φ_v − μ_i ∇u_ih·∇φ_v) and ∫_κ φ_v; at the two Gauss points of
     * each edge of κ the weighted flux density μ_i ∇u_ih·n ds; and the
     * weighted length ds at those of edge 2 if it lies on ∂ω; the key of its
     * half-edge. Trivial like SubTriangleData.
     */
    struct PatchTerms
    {
      std::array<std::array<double, 4>, 2>                hat_residual;
      std::array<double, 4>                               hat_mass;
      std::array<std::array<std::array<double, 2>, 3>, 2> edge_flux;
      std::array<double, 2>                               boundary_length;
      /**
       * The key of the unknown flux through edge 2 of κ, the factor that
       * gives κ's outward flux from it, and whether edge 2 lies on ∂ω (see
       * FluxEquilibration).
       */
      EdgeKey key;
      double  factor;
      bool    on_boundary;
    };

    /**
     * Compute t_1h, t_2h for @p ghosted_solution (the blocks u1h, u2h on
     * the DoFs of @p dof_handler, ghosted) on the locally owned cells of
     * @p dof_handler (and what they need of the ghost cells).
     * Returns the PatchTerms of the sub-triangles of the owned cells, by
     * active cell index × sub-triangles per cell + sub-triangle, for
     * FluxEquilibration::equilibrate().
     */
    AlignedVector<PatchTerms>
    reconstruct(const DoFHandler<dim> &dof_handler,
                const BlockVectorType &ghosted_solution);

    /**
     * The defects of the identities for the t_ih of the last reconstruct()
     * on @p dof_handler (with its @p hanging_node_constraints), against the
     * λ_a of @p action and the d_a and loads of @p problem. Only the output
     * asks for them: the flux estimator does not need them.
     */
    Identities
    identities(const DoFHandler<dim>           &dof_handler,
               const AffineConstraints<double> &hanging_node_constraints,
               const DiscreteProblem<dim>      &problem,
               const DiscreteAction<dim>       &action) const;

    /**
     * f_i at the points of the dual cell quadrature on @p cell, as
     * evaluated by the last reconstruct().
     */
    ArrayView<const double>
    load_values(const CellIterator &cell, const unsigned int i) const;

    /**
     * The sub-mesh S_h of the locally owned cells of @p dof_handler (that of
     * the last reconstruct()) as patches for DataOutBase::write_vtu, with
     * data_names(): on every sub-triangle the vertex a of its dual cell,
     * λ_h (@p lambda_h on the dual cells of @p dual_mesh), t_1h, t_2h
     * (exact at the corners: RT0 fields are linear) and div t_ih.
     */
    std::vector<DataOutBase::Patch<dim, dim>>
    patches(const DoFHandler<dim> &dof_handler,
            const DualMesh<dim>   &dual_mesh,
            const VectorType      &lambda_h) const;

    /** The names of the data of patches(), in order. */
    static std::vector<std::string>
    data_names();

    /** The sub-triangles and their Raviart–Thomas basis. */
    const SubTriangleBasis<dim> &
    sub_triangle_basis() const
    {
      return basis;
    }

    /**
     * The SubTriangleData of the last reconstruct(), by active cell index ×
     * sub-triangles per cell + sub-triangle.
     */
    const AlignedVector<SubTriangleData> &
    sub_triangles() const
    {
      return sub_triangle_data;
    }

  private:
    /** The work arrays of one thread of the cell loop of reconstruct(). */
    struct LocalFluxScratch;
    struct LocalFluxCopy;
    struct HalfEdgeMinimization;

    /**
     * The worker of the cell loop of reconstruct() on @p cell, on the owned
     * and ghost cells: the fluxes (4.13) through the edges of the
     * sub-triangles inside the cell, the inner products of the minimization
     * and, on an owned cell, the @p patch_terms.
     */
    void
    local_fluxes_on_cell(const CellIterator        &cell,
                         const BlockVectorType     &ghosted_solution,
                         AlignedVector<PatchTerms> &patch_terms,
                         LocalFluxScratch          &scratch,
                         LocalFluxCopy             &copy);

    /** The edge integrals of sub-triangle @p s (see the .cc file). */
    void
    integrate_edge_fluxes(const CellIterator     &cell,
                          const unsigned int      s,
                          const LocalFluxScratch &scratch,
                          SubTriangleData        &kappa,
                          PatchTerms             &terms) const;

    /** The integrals of SubTriangleData and PatchTerms on sub-triangle @p s. */
    void
    integrate_sub_triangle(const CellIterator     &cell,
                           const unsigned int      s,
                           const LocalFluxScratch &scratch,
                           SubTriangleData        &kappa,
                           PatchTerms             &terms) const;

    /** The unknowns of the half-edge a–m_e of sub-triangle @p s. */
    void
    name_half_edge(const CellIterator &cell,
                   const unsigned int  s,
                   PatchTerms         &terms,
                   LocalFluxCopy      &copy) const;

    /** The copier of the cell loop: sums of the minimization. */
    void
    add_to_minimization(const LocalFluxCopy  &copy,
                        HalfEdgeMinimization &minimization) const;

    /**
     * Per vertex a, condensed with the hanging node constraints: meas(D_a),
     * and in block i for membrane i ∫_{D_a} div t_ih, f_ih meas(D_a) and
     * f_ih ∫ φ_a.
     */
    struct DualCellSums
    {
      VectorType      measure;
      BlockVectorType divergence, load_on_pieces, load_on_hats;
    };

    /** The DualCellSums of the locally owned cells. */
    DualCellSums
    dual_cell_sums(const DoFHandler<dim>           &dof_handler,
                   const AffineConstraints<double> &hanging_node_constraints,
                   const IndexSet                  &locally_owned_dofs,
                   const MPI_Comm                   mpi_communicator) const;

    const Discretization<dim>     &discretization;
    const ProblemData<dim>        &data;
    const DualCellQuadrature<dim> &dual_cell_quadrature;
    /** The sub-triangles and their Raviart–Thomas basis. */
    const SubTriangleBasis<dim> basis;

    /** By active cell index × sub-triangles per cell + sub-triangle. */
    AlignedVector<SubTriangleData> sub_triangle_data;
    /** f_1, f_2 at the points of the dual quadrature, cell by cell. */
    AlignedVector<double> load_at_points;
    /** ∫_K φ_v for the vertices v of each locally owned cell K. */
    std::vector<std::array<double, 4>> hat_integrals;
  };
} // namespace membranes

#endif
