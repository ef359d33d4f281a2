#include <algorithm>
#include <deal.II/distributed/tria_base.h>
#include <functional>
#include <limits>
#include <membranes/mesh/cell_marking.h>
#include <numeric>
#include <utility>
#include <vector>

namespace membranes
{
  namespace
  {
    /**
     * The number of indicators, from @p first on, that a share @p fraction
     * takes of the sorted range [@p first, @p last): of the sum (bulk, the
     * fewest whose sum reaches the share) or of the count. With reverse
     * iterators, the same from the small end.
     */
    template <typename Iterator>
    std::size_t
    share(const Iterator            first,
          const Iterator            last,
          const Parameters::Marking marking,
          const double              fraction)
    {
      const std::size_t size = last - first;
      if (fraction <= 0)
        return 0;
      if (marking == Parameters::Marking::fixed_number)
        return static_cast<std::size_t>(fraction * size);
      const double total = std::accumulate(first, last, 0.);
      if (total == 0)
        return 0;
      std::size_t n   = 0;
      double      sum = 0;
      for (Iterator value = first; sum < fraction * total && value != last;
           ++value, ++n)
        sum += *value;
      return n;
    }
  } // namespace



  template <int dim>
  void
  mark_cells(Triangulation<dim>       &triangulation,
             const Vector<double>     &indicators,
             const Parameters::Marking marking,
             const double              top,
             const double              bottom,
             const MPI_Comm            mpi_communicator)
  {
    // The indicators of the locally owned cells, each cell on one process.
    std::vector<double> owned;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        owned.push_back(indicators[cell->active_cell_index()]);

    // The thresholds, from all indicators in decreasing order on the first
    // process: refine at least `refine_at`, coarsen at most `coarsen_at`.
    const std::vector<std::vector<double>> gathered =
      Utilities::MPI::gather(mpi_communicator, owned);
    std::pair<double, double> thresholds{
      std::numeric_limits<double>::infinity(),
      -std::numeric_limits<double>::infinity()};
    if (Utilities::MPI::this_mpi_process(mpi_communicator) == 0)
      {
        std::vector<double> sorted;
        for (const auto &values : gathered)
          sorted.insert(sorted.end(), values.begin(), values.end());
        std::sort(sorted.begin(), sorted.end(), std::greater<double>());
        const std::size_t n_refine =
          share(sorted.begin(), sorted.end(), marking, top);
        const std::size_t n_coarsen =
          share(sorted.rbegin(), sorted.rend(), marking, bottom);
        if (n_refine > 0 && sorted[n_refine - 1] > 0)
          thresholds.first = (1 - tie_tolerance) * sorted[n_refine - 1];
        else if (n_refine > 0)
          thresholds.first = std::numeric_limits<double>::min();
        if (n_coarsen > 0)
          thresholds.second =
            (1 + tie_tolerance) * sorted[sorted.size() - n_coarsen];
      }
    const auto [refine_at, coarsen_at] =
      Utilities::MPI::broadcast(mpi_communicator, thresholds);

    // A p4est mesh is flagged on its owned cells; a mesh that every process
    // holds whole on all cells, the same on every process.
    const bool distributed =
      dynamic_cast<const parallel::DistributedTriangulationBase<dim> *>(
        &triangulation) != nullptr;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (!distributed || cell->is_locally_owned())
        {
          const double eta2 = indicators[cell->active_cell_index()];
          if (eta2 >= refine_at)
            {
              cell->clear_coarsen_flag();
              cell->set_refine_flag();
            }
          else if (eta2 <= coarsen_at)
            cell->set_coarsen_flag();
        }
  }



  template void
  mark_cells(Triangulation<2> &,
             const Vector<double> &,
             const Parameters::Marking,
             const double,
             const double,
             const MPI_Comm);
} // namespace membranes
