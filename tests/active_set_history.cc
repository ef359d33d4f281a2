/**
 * @file
 * What ActiveSetHistory takes for a cycle of the active set method: a
 * return to a set visited before on this mesh, the whole set over all
 * processes, not its size.
 *
 * Each of the P processes owns the two vertices 2p and 2p + 1 of 2P. From
 * the initial set {2p : every p} (one vertex a process):
 * 1. every process swaps its two vertices: {2p + 1}, a different set of
 *    the same size, is no cycle, and every wanted change is made;
 * 2. only the first process swaps back: {0} ∪ {2p + 1 : p > 0}, again a
 *    new set of the same size when P > 1 (on one process it is the
 *    initial set, a cycle);
 * 3. every process toggles what brings the set back to the initial one: a
 *    cycle to set 0, which the remedy breaks by changing fewer vertices.
 * A fingerprint of the size alone fails 1 and 2, one of the local parts
 * alone fails 2 on several processes (the first process's part returns to
 * the initial one). Prints one PASS/FAIL line per check; exit status 1 on
 * failure. Run on one and on two processes.
 */

#include <deal.II/base/mpi.h>
#include <iostream>
#include <membranes/active_set/active_set.h>

using namespace dealii;
using namespace membranes;

namespace
{
  bool
  check(const bool passed, const std::string &what)
  {
    if (Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
      std::cout << (passed ? "PASS " : "FAIL ") << what << std::endl;
    return passed;
  }



  /** The changes that turn @p from into @p to (locally owned parts). */
  std::vector<StatusChange>
  changes(const IndexSet &from, const IndexSet &to)
  {
    std::vector<StatusChange> result;
    for (const auto dof : from)
      if (!to.is_element(dof))
        result.push_back({dof, 1.});
    for (const auto dof : to)
      if (!from.is_element(dof))
        result.push_back({dof, 1.});
    return result;
  }
} // namespace



int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi_initialization(argc, argv, 1);
  const unsigned int p = Utilities::MPI::this_mpi_process(MPI_COMM_WORLD);
  const unsigned int n_processes =
    Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD);
  const types::global_dof_index n   = 2 * n_processes;
  const auto                    set = [&](const types::global_dof_index dof) {
    IndexSet result(n);
    result.add_index(dof);
    return result;
  };

  ActiveSetHistory history(MPI_COMM_WORLD);
  const IndexSet   initial = set(2 * p);
  history.restart(initial);
  bool passed = true;

  // 1. The other vertex of every process: a new set of the same size.
  const IndexSet               swapped = set(2 * p + 1);
  const ActiveSetHistory::Step first =
    history.next(initial, changes(initial, swapped));
  passed &= check(!first.cycle_to && first.changed == first.wanted &&
                    first.active_set == swapped,
                  "a new set of the same size is no cycle");

  // 2. The first process alone swaps back.
  const IndexSet               mixed = (p == 0 ? initial : swapped);
  const ActiveSetHistory::Step second =
    history.next(swapped, changes(swapped, mixed));
  passed &=
    check(n_processes > 1 ? !second.cycle_to && second.active_set == mixed :
                            second.cycle_to == 0u,
          n_processes > 1 ?
            "a set whose first part is the initial one is no cycle" :
            "the initial set again is a cycle");

  // 3. Back to the initial set on every process.
  if (n_processes > 1)
    {
      const ActiveSetHistory::Step third =
        history.next(mixed, changes(mixed, initial));
      const bool detected = third.cycle_to == 0u && history.cycles() >= 1;
      const bool broken   = third.changed < third.wanted;
      passed &= check(detected && broken,
                      "the initial set again is a cycle to set 0, and the "
                      "remedy does not return there");
    }
  return Utilities::MPI::min(static_cast<unsigned int>(passed),
                             MPI_COMM_WORLD) == 1 ?
           0 :
           1;
}
