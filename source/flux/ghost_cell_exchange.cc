#include <deal.II/grid/cell_id.h>
#include <membranes/flux/ghost_cell_exchange.h>

namespace membranes
{
  template <int dim>
  void
  GhostCellExchange<dim>::reinit(const Triangulation<dim> &triangulation,
                                 const MPI_Comm            mpi_communicator)
  {
    this->mpi_communicator = mpi_communicator;
    owned_cells_for.clear();
    ghost_cells_of.clear();
    std::map<unsigned int, std::vector<CellId::binary_type>> requests;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_ghost())
        {
          ghost_cells_of[cell->subdomain_id()].push_back(
            cell->active_cell_index());
          requests[cell->subdomain_id()].push_back(
            cell->id().template to_binary<dim>());
        }
    for (const auto &[process, ids] :
         Utilities::MPI::some_to_some(mpi_communicator, requests))
      for (const CellId::binary_type &id : ids)
        owned_cells_for[process].push_back(
          triangulation.create_cell_iterator(CellId(id))->active_cell_index());
  }



  template class GhostCellExchange<2>;
} // namespace membranes
