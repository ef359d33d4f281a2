#ifndef membranes_flux_patch_problem_h
#define membranes_flux_patch_problem_h

#include <array>
#include <boost/serialization/array.hpp>
#include <deal.II/base/types.h>
#include <deal.II/lac/lapack_full_matrix.h>
#include <deal.II/lac/vector.h>
#include <utility>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The record of one sub-triangle κ of a cell K in the support of a
   * condensed hat function φ_a: what the patch problem of a needs of κ,
   * with φ_a's coefficients on K applied. The process that owns K writes
   * it; the process that owns a solves the patch problem (see
   * FluxEquilibration). The type is
   * trivially copyable, so that records travel in MPI messages as they are,
   * with the DoF indices as integers.
   */
  struct PatchRecord
  {
    /** The global DoF index of the vertex a of the patch (in both blocks). */
    types::global_dof_index vertex;
    /** The FluxReconstruction::EdgeKey of the flux through edge 2 of κ. */
    std::array<types::global_dof_index, 2> key;
    /** Outward flux of κ through edge 2 = factor × the unknown. */
    double factor;
    /** Whether edge 2 lies on ∂ω. */
    bool on_boundary;
    /** (ψ_k, ψ_l)_κ for k ≤ l, row by row. */
    std::array<double, 6> gram;
    /** |κ|. */
    double area;
    /** ∫_κ (f_i φ_a − μ_i ∇u_ih·∇φ_a), i = 1, 2. */
    std::array<double, 2> residual;
    /** ∫_κ φ_a. */
    double mass;
    /** ∫_e −μ_i φ_a ∇u_ih·n through edge e of κ, per i. */
    std::array<std::array<double, 3>, 2> edge_flux;
    /** ∫ φ_a along edge 2 if it lies on ∂ω. */
    double boundary_mass;

    /**
     * For Utilities::pack, which compiles a path for types that are not
     * trivially copyable (records take the other one).
     */
    template <class Archive>
    void
    serialize(Archive &archive, const unsigned int)
    {
      archive &vertex &key &factor &on_boundary &gram &area &residual &mass
        &edge_flux &boundary_mass;
    }
  };



  /**
   * The local problem of FluxEquilibration on the support ω_a of a
   * condensed hat function φ_a (see its class comment): the field σ_ih^a in
   * Z_h of (4.12) on ω_a with ∫_κ div σ_ih^a = ∫_κ r_ia on every
   * sub-triangle κ and the given normal fluxes on ∂ω_a, closest in the L²
   * norm of the Gram matrices of the sub-triangles to T_ia.
   *
   * On each cell the sub-triangles form a ring around b_K; with the fluxes
   * through their half-edges and one circulation per cell, the divergence
   * constraints inside the cell are solved in closed form, so a patch
   * problem is a small saddle point system of the half-edge fluxes, the
   * circulations and one constraint per cell but one: 15 (Q1) to 23 (P1)
   * unknowns around a regular interior vertex.
   *
   * One object serves one thread: it keeps its work arrays from one patch
   * to the next.
   */
  class PatchProblem
  {
  public:
    /** Patch problems on cells of @p n_ring sub-triangles each. */
    explicit PatchProblem(const unsigned int n_ring);

    /**
     * Solve the patch problem with the nodal value @p lambda_a of λ_h at a
     * on the records @p patch of the cells of ω_a (each the first of the
     * ring of its cell): writes the outward fluxes of σ_ih^a through the
     * three edges of each sub-triangle ring[j] of cell c to
     * result[c][6 j + 3 i + e].
     */
    void
    solve(const double                            lambda_a,
          const std::vector<const PatchRecord *> &patch,
          const std::vector<double *>            &result);

  private:
    /** The record of sub-triangle ring[s % n_ring] of cell s / n_ring. */
    const PatchRecord &
    record(const unsigned int s) const
    {
      return (*patch)[s / n_ring][s % n_ring];
    }

    /**
     * Number the unknown fluxes: the half-edges (or small edges at a
     * hanging node) that two cells of the patch share, found by their keys.
     */
    void
    number_unknowns();

    /**
     * The divergences ∫_κ r_ia and the prescribed fluxes through ∂ω (see
     * the class comment of FluxEquilibration).
     */
    void
    compute_sources(const double lambda_a);

    /** The fluxes of the target T_ia of the minimization. */
    void
    compute_targets();

    /** Add the minimization on cell @p c and its constraint (see .cc). */
    void
    assemble_cell(const unsigned int c);

    /** σ_ih^a on the sub-triangles of the patch, to @p result. */
    void
    write_fluxes(const std::vector<double *> &result) const;

    /** A half-edge of the patch by its key, for sorting. */
    struct HalfEdge
    {
      types::global_dof_index first, second;
      unsigned int            cell, s;
    };

    const unsigned int n_ring;

    const std::vector<const PatchRecord *> *patch = nullptr;
    unsigned int                            n_cells;
    unsigned int                            n_sub;
    /** The number of unknown half-edge fluxes. */
    unsigned int n_x;

    std::vector<HalfEdge> half_edges;
    /**
     * Per sub-triangle the unknown of its half-edge and the factor that
     * gives its outward flux, or invalid: on ∂ω the flux is prescribed, on
     * the rest of the boundary of ω_a it is zero.
     */
    std::vector<std::pair<unsigned int, double>> unknown_of;
    /** ∫_κ r_ia per sub-triangle and membrane. */
    std::vector<std::array<double, 2>> source;
    /** The prescribed flux through a half-edge on ∂ω. */
    std::vector<std::array<double, 2>> known;
    /**
     * Per unknown the sum of the one-sided fluxes of T_ia through it and
     * the sum of |factor|; per sub-triangle the change of T_ia's flux
     * through its half-edge by the mean.
     */
    std::vector<std::array<double, 2>> mean, change;
    std::vector<double>                weight;
    /** The outward fluxes of T_ia through the edges of each κ. */
    std::vector<std::array<std::array<double, 3>, 2>> target;

    /** The matrix of the saddle point system and its two right-hand sides. */
    LAPACKFullMatrix<double>      matrix;
    std::array<Vector<double>, 2> rhs;
  };
} // namespace membranes

#endif
