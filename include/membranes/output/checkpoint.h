#ifndef membranes_checkpoint_h
#define membranes_checkpoint_h

#include <array>
#include <deal.II/base/geometry_info.h>
#include <deal.II/base/mpi.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/trilinos_vector.h>
#include <deal.II/lac/vector.h>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /** What the next cycle reads besides the mesh and its vectors. */
  struct CheckpointState
  {
    /** The last finished cycle. */
    unsigned int cycle = 0;
    /** Its DoFs and estimator η, for balanced stopping on the next mesh. */
    types::global_dof_index dofs = 0;
    std::optional<double>   estimator;
    /** The column cumulative_wall_time of its row. */
    double cumulative_wall_time = 0;
    /** The .pvd records of the field output: (cycle, file) pairs. */
    std::vector<std::pair<double, std::string>> solution_files;
    std::vector<std::pair<double, std::string>> dual_mesh_files;
  };



  /**
   * The checkpoint of a study, `checkpoint/` in its output directory: what
   * the cycle after the last finished one needs to start as it would have
   * in an uninterrupted run (`Output/Checkpoint every`), and its reading
   * back by a run with `Output/Resume = true` (or `--resume`).
   *
   * A finished cycle k leaves its mesh, the nodal vectors u1h, u2h and λ_h
   * that nested iteration interpolates onto the next mesh, the indicators
   * η_K² that mark it, and a State: what the report, the field output and
   * balanced stopping carry from one cycle to the next. The mesh is kept
   * as deal.II keeps each kind:
   * - a p4est mesh (quadrilaterals) by
   *   parallel::distributed::Triangulation::save(), each locally owned
   *   cell with a CellRecord (the nodal values at its vertices and its
   *   indicator, attached by CellDataTransfer); load() on any number of
   *   processes (p4est partitions the cells anew if it differs) and
   *   deserialization. The loaded mesh numbers its cells, and so its DoFs,
   *   in p4est's order rather than in the order in which the refinements
   *   made them: where adaptive refinement made the mesh, the resumed run
   *   agrees with the uninterrupted one to the algebraic error of CG-AMG
   *   (to round-off with a direct solver), where global refinement made
   *   it, to round-off;
   * - a mesh that every process holds whole (triangles, a
   *   parallel::shared::Triangulation) by its history: the refine and
   *   coarsen flags of every refinement since the coarse mesh, replayed on
   *   it; the vectors by vertex index and the indicators by active cell
   *   index, which the replayed mesh numbers alike on any number of
   *   processes.
   *
   * Each checkpoint is written into `checkpoint.tmp/`, with `state.txt`
   * last (the size and a 64-bit hash of every other file in it),
   * and then takes the place of the previous one by two renames: a kill at
   * any point leaves `checkpoint/` or, between the renames,
   * `checkpoint.old/` whole. Reading checks every file against `state.txt`
   * before deal.II reads any of them, so that a damaged or truncated
   * checkpoint is an error naming the file, never a crash in p4est.
   */
  template <int dim>
  class Checkpoint
  {
  public:
    using VectorType = TrilinosWrappers::MPI::Vector;

    using State = CheckpointState;

    Checkpoint(const std::string &output_directory,
               const MPI_Comm     mpi_communicator);

    /**
     * Keep the flags of a refinement of @p triangulation, prepared and
     * about to be executed, if every process holds that mesh whole
     * (nothing is kept for a p4est mesh, which save() writes itself).
     */
    void
    record_refinement(const Triangulation<dim> &triangulation);

    /**
     * Write the checkpoint of the finished cycle of @p state: the mesh of
     * @p dof_handler, the ghosted vectors @p vectors (u1h, u2h, λ_h) and
     * the @p indicators (empty if no estimator marks cells). Collective.
     */
    void
    write(const State                             &state,
          const DoFHandler<dim>                   &dof_handler,
          const std::array<const VectorType *, 3> &vectors,
          const Vector<double>                    &indicators);

    /**
     * Check the checkpoint of the output directory and make its mesh out
     * of the coarse mesh @p triangulation; returns its State. A missing or
     * damaged checkpoint, or one of a mesh of the other kind, is a
     * Parameters::CollectiveError before anything is changed. Collective.
     */
    State
    load_mesh(Triangulation<dim> &triangulation);

    /**
     * After load_mesh() and the distribution of the DoFs of @p dof_handler
     * on that mesh: the locally owned entries of @p vectors (u1h, u2h, λ_h,
     * without ghosts) and the @p indicators. Collective.
     */
    void
    load_vectors(const DoFHandler<dim>             &dof_handler,
                 const std::array<VectorType *, 3> &vectors,
                 Vector<double>                    &indicators);

  private:
    static constexpr unsigned int n_vertices_per_cell =
      GeometryInfo<dim>::vertices_per_cell;
    /**
     * What a p4est mesh keeps with each locally owned cell: u1h, u2h and
     * λ_h at its vertices, and its indicator.
     */
    using CellRecord = std::array<double, 3 * n_vertices_per_cell + 1>;

    /** The CellRecord of each locally owned cell, by active cell index. */
    std::vector<CellRecord>
    cell_records(const DoFHandler<dim>                   &dof_handler,
                 const std::array<const VectorType *, 3> &vectors,
                 const Vector<double>                    &indicators) const;

    /** The directory of the checkpoint to read: checkpoint/, or .old/. */
    std::string
    readable_directory() const;

    /** Write the files of a mesh that every process holds whole. */
    void
    write_replicated(const std::string                       &directory,
                     const DoFHandler<dim>                   &dof_handler,
                     const std::array<const VectorType *, 3> &vectors,
                     const Vector<double>                    &indicators) const;

    const std::string output_directory;
    const MPI_Comm    mpi_communicator;
    /** Whether the checkpoint read last holds indicators. */
    bool has_indicators = false;
    /**
     * The refine and coarsen flags of every refinement of a mesh that every
     * process holds whole, from the coarse mesh on.
     */
    std::vector<std::pair<std::vector<bool>, std::vector<bool>>> refinements;
  };
} // namespace membranes

#endif
