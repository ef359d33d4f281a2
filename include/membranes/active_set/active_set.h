#ifndef membranes_active_set_h
#define membranes_active_set_h

#include <cstdint>
#include <deal.II/base/index_set.h>
#include <deal.II/base/partitioner.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/dual_mesh/discrete_action.h>
#include <membranes/mesh/discrete_problem.h>
#include <membranes/mesh/discretization.h>
#include <membranes/scene/parameters.h>
#include <membranes/scene/problem_data.h>
#include <memory>
#include <optional>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * A vertex whose status the active set method wants to change: its DoF
   * and by how much its test is violated, in units of the band of
   * indifference (see ActiveSet), so at least 1.
   */
  struct StatusChange
  {
    types::global_dof_index dof;
    double                  violation;

    /** For Utilities::MPI::all_gather(). */
    template <class Archive>
    void
    serialize(Archive &archive, const unsigned int)
    {
      archive &dof &violation;
    }
  };



  /**
   * The active sets the active set method has visited on one mesh, and the
   * remedy against cycling.
   *
   * The plain update changes the status of every vertex whose test is
   * violated. For an M-matrix (non-obtuse meshes) this converges
   * monotonically, but in general the primal-dual active set method, a
   * semismooth Newton method for the complementarity problem, may cycle:
   * return to an active set it has already visited, and go round for ever.
   * Each update is therefore checked against all active sets visited on
   * the current mesh (the initial one included). When it would return to
   * one of them, the update is restricted to the vertices with the largest
   * violations: on the r-th cycle detected on this mesh to ⌈n / 2^r⌉ of the
   * n vertices that want to change; if that set was visited too, r is
   * raised again. Once the share is down to one vertex, the method
   * continues on this mesh with Murty's least-index rule: change only the
   * wanted vertex of least DoF index. That rule terminates for every linear
   * complementarity problem with a P-matrix (K. G. Murty, Note on a
   * Bard-type scheme for solving the complementarity problem, Opsearch 11,
   * 1974), and ours has one: eliminating the displacements leaves the Schur
   * complement of the symmetric positive definite system on the contact
   * vertices, which is symmetric positive definite. The halving can only happen
   * log2(n) times, so the method terminates on every mesh; a cycle costs
   * iterations, not convergence.
   *
   * A visited set is remembered by its fingerprint, the sum over its DoFs
   * of a 64-bit hash of each (modulo 2^64, over all processes: one
   * reduction per set), not by a copy: two different sets share a
   * fingerprint with probability about 2^{-64}, and if they did, the
   * remedy would only restrict one update more than needed, which costs
   * iterations, not termination.
   *
   * Under MPI each process passes the locally owned part of the sets; the
   * fingerprints and the choice of vertices are global.
   */
  class ActiveSetHistory
  {
  public:
    explicit ActiveSetHistory(const MPI_Comm mpi_communicator);

    /** Forget all, and start a new mesh at @p initial_active_set. */
    void
    restart(const IndexSet &initial_active_set);

    /** What one update did. */
    struct Step
    {
      /** The next active set (locally owned part). */
      IndexSet active_set;
      /** How many vertices wanted to change, and how many did. */
      types::global_dof_index wanted, changed;
      /**
       * The number of the visited set (0 for the initial one, k for the
       * set of iteration k + 1) that the plain update would have
       * returned to, if a cycle was detected.
       */
      std::optional<unsigned int> cycle_to;
      /** Whether the update followed Murty's least-index rule. */
      bool least_index_rule;
    };

    /**
     * The active set after @p active_set (the last one visited), changed
     * at the locally owned vertices @p changes or, if that would close a
     * cycle, at the part of them that the remedy allows. The result is
     * recorded as visited.
     */
    Step
    next(const IndexSet &active_set, const std::vector<StatusChange> &changes);

    /** Cycles detected since restart(). */
    unsigned int
    cycles() const;

    /**
     * The plain update: @p active_set with the status of the vertices
     * @p dofs (locally owned DoFs) changed.
     */
    static IndexSet
    toggled(const IndexSet                             &active_set,
            const std::vector<types::global_dof_index> &dofs);

  private:
    /** The fingerprint of @p set (locally owned part), over all processes. */
    std::uint64_t
    fingerprint(const IndexSet &set) const;

    /** The number of the visited set with the fingerprint of @p set. */
    std::optional<unsigned int>
    find(const IndexSet &set) const;

    const MPI_Comm             mpi_communicator;
    std::vector<std::uint64_t> visited;
    unsigned int               n_cycles;
    bool                       least_index_rule;
  };



  /**
   * The active set of the primal-dual active set method (ActiveSetSolver):
   * the set A ⊂ V_h of the vertices where the membranes are in contact, its
   * initial value on a new mesh and its update from an iterate. The linear
   * systems impose it (ActiveSetSystem::set_active_set()).
   *
   * With W_a = u1h(a) − u2h(a) (DiscreteProblem::nodal_w()) and the nodal
   * multiplier Λ_a = λ_a of (4.5), the active set is
   *
   *   A = { a ∈ V_h : Λ_a − c_a W_a > 0 },   c_a = μ̄ ∫|∇φ_a|² / ∫φ_a
   *
   * (contact_stiffness()), where c_a has the units of Λ/W (μ̄ = μ1μ2/(μ1+μ2)
   * is the tension of the obstacle problem for w = u1 − u2,
   * DecoupledSystem).
   *
   * <b>Decisions relative to the data.</b> In the units of the data, the
   * test reads λ̂_a − Ŵ_a > 0 with
   *
   *   λ̂_a = λ_a / (c_a U_∞),   Ŵ_a = W_a / U_∞,   U_∞ = max|U|,
   *
   * both unchanged when the loads and g are multiplied by a factor, or μ1
   * and μ2 (with the loads) by a factor. (c_a U_∞ d_a = μ̄ ∫|∇φ_a|² U_∞ is
   * the size of the forces of the obstacle problem for w at a.) After a
   * solve, W_a = 0 on A and λ_a = 0 off A, up to round-off, so the test
   * keeps an active vertex iff λ_a > 0 and activates an inactive one iff
   * W_a < 0: the iterates of the plain method do not depend on c_a. It
   * matters where neither holds, in the initial active set of a mesh (from
   * the transferred iterate) and on the predicted iterate
   * (ActiveSetPrediction), and in the band below, which reads λ_a in units
   * of c_a U_∞. Where
   * both are zero in exact arithmetic (a degenerate vertex: the membranes
   * touch without pressing on each other), the sign of the test is the
   * sign of round-off, a vertex may flip at every iteration, and the plain
   * method cycles. Each sign is therefore read with a band of indifference
   * ε = `Tolerance`:
   * - an active vertex is released iff λ̂_a < −ε,
   * - an inactive vertex is activated iff Ŵ_a < −ε,
   * - every other vertex keeps its status (hysteresis).
   * The band is about that of the KKT residual: a vertex kept in it adds at
   * most about ε to its dual (−λ_a d_a / F^w_∞, F^w_∞ ≥ μ̄ ∫|∇φ_a|² U_∞) or
   * primal (−W_a / U_∞) feasibility part, so either status is an acceptable
   * answer for it. λ_a is DiscreteAction::lambda(), the multiplier of the
   * obstacle problem for w: its rounding and algebraic errors are those of
   * forces of tension μ̄, as the band is, whatever the tension ratio.
   *
   * When the test wants changes, ActiveSetSolver may move to the changes
   * that the test wants on a predicted iterate instead
   * (ActiveSetPrediction); update() takes whichever it is given, through
   * the remedy against cycling (ActiveSetHistory).
   *
   * Each process holds the status of the locally owned vertices of V_h,
   * one flag each in the order of DiscreteProblem::vertices(): the one
   * representation of A, which the loops over the vertices read.
   * locally_owned() and locally_relevant() derive index sets from it when
   * the history, the output or the linear systems need one;
   * locally_relevant() tells every process the status of the vertices of
   * its ghost cells, for the constraints of the cells it assembles.
   */
  template <int dim>
  class ActiveSet
  {
  public:
    using VectorType      = TrilinosWrappers::MPI::Vector;
    using BlockVectorType = TrilinosWrappers::MPI::BlockVector;
    using Vertex          = typename DiscreteProblem<dim>::Vertex;

    ActiveSet(const Parameters::Solver &parameters,
              const ProblemData<dim>   &data,
              const MPI_Comm            mpi_communicator);

    /**
     * No active vertex on the mesh of @p discrete_problem (the first mesh),
     * and the communication pattern of its ghost vertices.
     */
    void
    reinit(const DiscreteProblem<dim> &discrete_problem);

    /**
     * The active set {a : Λ_a − c_a W_a > 0} of a new mesh, for the previous
     * mesh's solution (@p solution, the locally owned DoFs) and λ_h
     * interpolated onto it (nested iteration). A
     * vertex where both |λ̂_a| ≤ ε and |Ŵ_a| ≤ ε is degenerate up to
     * round-off; it starts inactive, as every vertex of the first mesh does.
     */
    void
    reinit(const DiscreteProblem<dim> &discrete_problem,
           const BlockVectorType      &solution,
           const VectorType           &ghosted_lambda_h);

    /** Whether the locally owned vertex k of DiscreteProblem::vertices() is
     * active. */
    bool
    is_active(const unsigned int k) const
    {
      return active_flags[k];
    }

    /** The locally owned active vertices (their DoFs) of the mesh of
     * @p problem. */
    IndexSet
    locally_owned(const DiscreteProblem<dim> &problem) const;

    /** The number of active vertices (all processes). */
    types::global_dof_index
    n_active_vertices() const;

    /**
     * The active vertices among the locally relevant ones of the mesh of
     * @p problem, by a ghost
     * exchange: the owner of each vertex decides, every process that shares
     * a cell with it learns the decision. ActiveSetSystem::set_active_set()
     * imposes them on the linear problem of an iteration: as constraint
     * lines u1(a) = u2(a) in CoupledSystem, as the projection Π (and, in
     * the matrix of W, constraint lines W_a = 0) in DecoupledSystem.
     */
    IndexSet
    locally_relevant(const DiscreteProblem<dim> &problem) const;

    /** c_a = μ̄ ∫|∇φ_a|² / d_a. */
    double
    contact_stiffness(const Vertex &a) const;

    /**
     * The test at the vertex a = @p problem.vertices()[@p k], read with its
     * status: by how much the iterate with Λ_a = @p lambda and
     * W_a = @p w, both relative to the data (U_∞ = @p u_scale), asks a to
     * change its status, λ̂_a − Ŵ_a for an inactive vertex and its negative
     * for an active one (positive: a change is wanted).
     */
    double
    violation(const DiscreteProblem<dim> &problem,
              const unsigned int          k,
              const double                lambda,
              const double                w,
              const double                u_scale) const;

    /**
     * The locally owned vertices whose status the test wants to change on
     * the iterate @p solution (locally owned DoFs), with λ_a in @p action,
     * outside the band of indifference, by increasing DoF.
     */
    std::vector<StatusChange>
    wanted_changes(const DiscreteProblem<dim> &problem,
                   const DiscreteAction<dim>  &action,
                   const BlockVectorType      &solution) const;

    /**
     * Start the record of the sets visited on the mesh of @p problem
     * (ActiveSetHistory).
     */
    void
    restart(const DiscreteProblem<dim> &problem);

    /**
     * Move to the next active set after the locally owned vertices
     * @p changes of the mesh of @p problem want to change: through the
     * remedy against cycling, ActiveSetHistory::next().
     */
    ActiveSetHistory::Step
    update(const DiscreteProblem<dim>      &problem,
           const std::vector<StatusChange> &changes);

    /** Cycles detected on this mesh (ActiveSetHistory::cycles()). */
    unsigned int
    cycles() const;

  private:
    const Parameters::Solver &parameters;
    const ProblemData<dim>   &data;

    const MPI_Comm mpi_communicator;
    /**
     * Whether each locally owned vertex of V_h is active, in the order of
     * DiscreteProblem::vertices().
     */
    std::vector<char> active_flags;
    /** The owned and ghost DoFs of the mesh, for locally_relevant(). */
    std::shared_ptr<const Utilities::MPI::Partitioner> partitioner;
    /** The sets visited on this mesh. */
    ActiveSetHistory history;
  };
} // namespace membranes

#endif
