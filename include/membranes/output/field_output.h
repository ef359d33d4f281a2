#ifndef membranes_field_output_h
#define membranes_field_output_h

#include <deal.II/base/data_out_base.h>
#include <deal.II/base/index_set.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/trilinos_vector.h>
#include <deal.II/lac/vector.h>
#include <functional>
#include <membranes/mesh/discretization.h>
#include <membranes/scene/parameters.h>
#include <string>
#include <utility>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * Field output, each file by write_atomically(), so that no half-written
   * file is left, and a file that cannot be written is an error naming it
   * and the system's reason:
   * - for ParaView (`Write vtu`), one VTU file per cycle with u1, u2,
   *   w = u1 − u2, λ_h (the nodal values λ_a of (4.5) at the vertices of
   *   V_h, zero at the others), the active set indicator (1 at the active
   *   vertices, 0 elsewhere), the subdomain (the process that owns the
   *   cell) and, when computed, the error indicator η_K, and a .pvd file
   *   that lists the cycles. On N > 1 processes each writes its own cells to
   *   solution-NN.PPPP.vtu and the first one the record solution-NN.pvtu
   *   that joins them (the .pvd lists the records);
   * - for comparisons to round-off (`Write nodal values`), one CSV file
   *   per cycle, nodal-values-NN.csv, with one row per vertex in the order
   *   of its position (x, then y), so that runs on different numbers of
   *   processes give the same rows: `x,y,u1,u2,lambda_h,active_set`,
   *   numbers with 17 significant digits. (VTU holds single precision
   *   values.) The first process gathers and writes it.
   */
  template <int dim>
  class FieldOutput
  {
  public:
    using VectorType      = TrilinosWrappers::MPI::Vector;
    using BlockVectorType = TrilinosWrappers::MPI::BlockVector;

    FieldOutput(const Parameters::Output  &parameters,
                const Discretization<dim> &discretization,
                const MPI_Comm             mpi_communicator);

    /**
     * Write what the scene asks for of cycle @p cycle: @p ghosted_solution
     * holds u1h and u2h as its two blocks, @p lambda_h is λ_h as
     * DiscreteAction::lambda_h() returns it (both ghosted, on the DoFs of
     * @p dof_handler), and @p active_vertices are the locally owned active
     * vertices (their DoFs, ActiveSet::locally_owned()). The error
     * indicators η_K (one per active cell) are written to VTU when given.
     * Returns the names of the files written, relative to the output
     * directory: solution-NN.vtu (or .pvtu), nodal-values-NN.csv. Called by
     * all processes together.
     */
    std::vector<std::string>
    write(const unsigned int     cycle,
          const DoFHandler<dim> &dof_handler,
          const BlockVectorType &ghosted_solution,
          const VectorType      &lambda_h,
          const IndexSet        &active_vertices,
          const Vector<double>  *indicators);

    /**
     * Write the sub-mesh S_h of the dual mesh (§4.2) of cycle @p cycle as
     * dual-mesh-NN.vtu (.pvtu on N > 1 processes), one triangle per patch
     * with the data @p names (see FluxReconstruction::patches()), and a
     * dual-mesh.pvd over cycles.
     */
    void
    write_dual_mesh(const unsigned int                               cycle,
                    const std::vector<DataOutBase::Patch<dim, dim>> &patches,
                    const std::vector<std::string>                  &names);

    /**
     * The records of solution.pvd and dual-mesh.pvd so far: (cycle, file)
     * pairs, for a checkpoint (Checkpoint::State).
     */
    std::pair<std::vector<std::pair<double, std::string>>,
              std::vector<std::pair<double, std::string>>>
    written_files() const;

    /**
     * Continue solution.pvd and dual-mesh.pvd with the records
     * @p solution_files and @p dual_mesh_files of a resumed study.
     */
    void
    resume(const std::vector<std::pair<double, std::string>> &solution_files,
           const std::vector<std::pair<double, std::string>> &dual_mesh_files);

  private:
    /**
     * The fields written besides u1h, u2h and λ_h, ghosted vectors on the
     * DoFs of the mesh, made for the output only: w = u1h − u2h, and 1 at
     * the active vertices, 0 elsewhere.
     */
    struct Fields
    {
      VectorType w, active_set;
    };

    /**
     * Write this process's piece of @p name of cycle @p cycle with
     * @p write_piece; on N > 1 processes, the first one writes the .pvtu
     * record of all pieces with @p write_record (given their file names);
     * then the .pvd file over the cycles in @p written. (Not
     * DataOut::write_vtu_with_pvtu_record(), which opens the files itself:
     * benchmarks/choices.md, "Atomic output files".)
     */
    void
    write_cycle(
      const unsigned int                                           cycle,
      const std::string                                           &name,
      const std::function<void(std::ostream &)>                   &write_piece,
      const std::function<void(std::ostream &,
                               const std::vector<std::string> &)> &write_record,
      std::vector<std::pair<double, std::string>>                 &written);

    /**
     * solution-NN.vtu (or .pvtu and pieces) and solution.pvd; returns the
     * name of the first.
     */
    std::string
    write_vtu(const unsigned int     cycle,
              const DoFHandler<dim> &dof_handler,
              const BlockVectorType &ghosted_solution,
              const VectorType      &lambda_h,
              const Fields          &fields,
              const Vector<double>  *indicators);

    /**
     * nodal-values-NN.csv: position, u1, u2, λ_a, active set per vertex;
     * returns its name.
     */
    std::string
    write_nodal_values(const unsigned int     cycle,
                       const DoFHandler<dim> &dof_handler,
                       const BlockVectorType &ghosted_solution,
                       const VectorType      &lambda_h,
                       const Fields          &fields) const;

    const Parameters::Output                   &parameters;
    const Discretization<dim>                  &discretization;
    const MPI_Comm                              mpi_communicator;
    std::vector<std::pair<double, std::string>> cycles_written;
    std::vector<std::pair<double, std::string>> dual_mesh_cycles_written;
  };
} // namespace membranes

#endif
