#ifndef membranes_checkpoint_h
#define membranes_checkpoint_h

#include <array>
#include <deal.II/base/geometry_info.h>
#include <deal.II/base/mpi.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/grid/cell_id.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/trilinos_vector.h>
#include <deal.II/lac/vector.h>
#include <functional>
#include <map>
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
   *   indicator, attached by CellDataTransfer), and by its history: the
   *   CellIds of the cells flagged in every refinement. On as many
   *   processes as wrote it, the saved mesh is loaded with its partition,
   *   each process keeps the records of its cells, and the mesh is made
   *   again from the coarse one by its refinements, so that its cells, and
   *   its DoFs, are numbered as in the uninterrupted study (the loaded mesh
   *   numbers them in p4est's order, and CG-AMG's iterates would differ by
   *   their algebraic error). On another number of processes the loaded
   *   mesh is used as it is, partitioned anew by p4est;
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
    load_mesh(
      Triangulation<dim>                              &triangulation,
      const std::function<void(Triangulation<dim> &)> &make_coarse_mesh);

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

    /**
     * load_mesh() of a p4est mesh: the saved mesh and the records of its
     * locally owned cells, then, on @p same_processes as wrote it, the mesh
     * made again from the coarse one of @p make_coarse_mesh by the
     * refinements since (see the class documentation).
     */
    void
    load_distributed(
      parallel::distributed::Triangulation<dim>       &triangulation,
      const std::string                               &directory,
      const bool                                       same_processes,
      const std::function<void(Triangulation<dim> &)> &make_coarse_mesh);

    /** The directory of the checkpoint to read: checkpoint/, or .old/. */
    std::string
    readable_directory() const;

    /**
     * Write the files of a p4est mesh into @p directory; what went wrong
     * on the first process, empty if nothing.
     */
    std::string
    write_distributed(const std::string                       &directory,
                      const DoFHandler<dim>                   &dof_handler,
                      const std::array<const VectorType *, 3> &vectors,
                      const Vector<double> &indicators) const;

    /** The same for a mesh that every process holds whole. */
    std::string
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
    /**
     * The same for a p4est mesh: the CellIds (CellId::to_binary(), four
     * numbers each) of the cells flagged for refinement and for coarsening
     * in every refinement, all processes' on the first one.
     */
    std::vector<std::pair<std::vector<unsigned int>, std::vector<unsigned int>>>
      cell_refinements;
    /** The CellRecord of each locally owned cell of the checkpoint read. */
    std::map<CellId::binary_type, CellRecord> loaded_records;
    /**
     * Of a mesh that every process holds whole: u1h, u2h and λ_h by vertex
     * index, and the indicators, from load_mesh() to load_vectors().
     */
    std::vector<double> loaded_by_vertex, loaded_indicators;
  };
} // namespace membranes

#endif
