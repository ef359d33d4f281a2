#ifndef membranes_cell_marking_h
#define membranes_cell_marking_h

#include <deal.II/base/mpi.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/vector.h>
#include <membranes/scene/parameters.h>

namespace membranes
{
  using namespace dealii;

  /**
   * Flag the cells of @p triangulation for refinement and coarsening by
   * their indicators η_K² (@p indicators, by active cell index: on a p4est
   * mesh those of the locally owned cells, on a mesh that every process
   * holds whole those of all cells, the same on every process).
   *
   * With `Marking = bulk` (Dörfler marking, deal.II's
   * `refine_and_coarsen_fixed_fraction`) the refined cells are the fewest,
   * of the largest indicators, whose η_K² sum up to the share @p top of
   * η² = Σ_K η_K²; with `fixed number` (deal.II's
   * `refine_and_coarsen_fixed_number`) they are the share @p top of the
   * cells with the largest indicators. If every indicator is zero, no cell
   * is refined (nor, with bulk marking, coarsened). Coarsening takes the share
   * @p bottom at the small end likewise, never a cell flagged for
   * refinement. Both sets are the cells above (below) a threshold, so a
   * larger share contains a smaller one.
   *
   * <h3>The same marking on any number of processes</h3>
   * The indicators differ slightly between runs on different numbers of
   * processes: the linear algebra sums in another order, and CG with a
   * preconditioner built on another partition stops at another iterate
   * within the algebraic error that `Solver/Tolerance` allows. On a
   * symmetric scene many cells carry indicators that are equal in exact
   * arithmetic, and a marking that cuts through such a group by the order
   * of their computed values would pick different cells of it on
   * different partitions, and from then on build different meshes. Here the
   * thresholds are made independent of the partition, and the cut cannot fall
   * inside a group of ties:
   *
   * - one process gathers the indicators of all cells, sorts them, and
   *   finds the share @p top (@p bottom) in this order, which does not
   *   depend on how the cells are distributed; the thresholds go to every
   *   process. (deal.II's parallel functions find their thresholds by a
   *   bisection whose sums run in the order of the partition.)
   * - The threshold is widened by the relative tolerance `tie_tolerance`:
   *   a cell is refined if η_K² ≥ (1 − 10⁻⁶) t, t the smallest indicator
   *   of the share, and coarsened if η_K² ≤ (1 + 10⁻⁶) b. Indicators that
   *   agree to a relative 10⁻⁶, far above their differences between
   *   partitions (benchmarks/parallel.md, `process_count.py`), are so
   *   marked together or not at all. A cell whose indicator is not tied
   *   to t but lies within 10⁻⁶ below it is refined too, which changes
   *   the marked share by a few cells at most.
   *
   * Gathering the indicators costs one double per cell on the first process
   * and a sort, a small part of a cycle.
   */
  template <int dim>
  void
  mark_cells(Triangulation<dim>       &triangulation,
             const Vector<double>     &indicators,
             const Parameters::Marking marking,
             const double              top,
             const double              bottom,
             const MPI_Comm            mpi_communicator);

  /** The relative width of a group of tied indicators in mark_cells(). */
  constexpr double tie_tolerance = 1e-6;
} // namespace membranes

#endif
