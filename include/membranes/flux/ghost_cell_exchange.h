#ifndef membranes_ghost_cell_exchange_h
#define membranes_ghost_cell_exchange_h

#include <deal.II/base/mpi.h>
#include <deal.II/grid/tria.h>
#include <map>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * Copies data that lives on the cells, n entries per active cell in the
   * order of the active cell indices, from the owned cells of each process
   * to the processes that hold them as ghost cells.
   *
   * Each process asks the owner of each of its ghost cells for it, by its
   * CellId, once per mesh (reinit()); update_ghosts() then sends the data
   * of the requested cells in the requested order. The receivers are thus
   * found from the ghost cells themselves. GridTools::
   * exchange_cell_data_to_ghosts() finds them instead through the vertices
   * that an owned cell shares with the ghost cells of other processes,
   * which misses a ghost cell that meets an owned cell only at a hanging
   * vertex in the middle of its edge: such a cell is a ghost cell on
   * p4est meshes, and on triangles after complete_ghost_layer().
   */
  template <int dim>
  class GhostCellExchange
  {
  public:
    /** The ghost cells of @p triangulation and the owned cells asked for. */
    void
    reinit(const Triangulation<dim> &triangulation,
           const MPI_Comm            mpi_communicator);

    /**
     * Overwrite the entries of the ghost cells in @p data (@p n_per_cell
     * entries of type T per active cell) with those of their owners.
     */
    template <typename T>
    void
    update_ghosts(std::vector<T> &data, const unsigned int n_per_cell) const;

  private:
    MPI_Comm mpi_communicator;
    /** Active cell indices of the owned cells each process asked for. */
    std::map<unsigned int, std::vector<unsigned int>> owned_cells_for;
    /** Active cell indices of the ghost cells, by their owner. */
    std::map<unsigned int, std::vector<unsigned int>> ghost_cells_of;
  };



  template <int dim>
  template <typename T>
  void
  GhostCellExchange<dim>::update_ghosts(std::vector<T>    &data,
                                        const unsigned int n_per_cell) const
  {
    std::map<unsigned int, std::vector<T>> outgoing;
    for (const auto &[process, cells] : owned_cells_for)
      {
        std::vector<T> &buffer = outgoing[process];
        buffer.reserve(cells.size() * n_per_cell);
        for (const unsigned int cell : cells)
          buffer.insert(buffer.end(),
                        data.begin() + cell * n_per_cell,
                        data.begin() + (cell + 1) * n_per_cell);
      }
    for (const auto &[process, buffer] :
         Utilities::MPI::some_to_some(mpi_communicator, outgoing))
      {
        const std::vector<unsigned int> &cells = ghost_cells_of.at(process);
        AssertDimension(buffer.size(), cells.size() * n_per_cell);
        for (unsigned int c = 0; c < cells.size(); ++c)
          std::copy_n(buffer.begin() + c * n_per_cell,
                      n_per_cell,
                      data.begin() + cells[c] * n_per_cell);
      }
  }
} // namespace membranes

#endif
