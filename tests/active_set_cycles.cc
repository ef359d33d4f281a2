/**
 * The remedy of ActiveSetHistory on a linear complementarity problem where
 * the plain primal-dual active set method cycles:
 *
 *   find z ≥ 0 with w = M z + q ≥ 0, z·w = 0,
 *
 *       ( 35 -23  28 )        (  5 )
 *   M = (-23  22 -15 ),   q = ( -5 ),
 *       ( 28 -15  27 )        (  1 )
 *
 * M is symmetric positive definite (a P-matrix), like the Schur complement
 * of the membrane problem on the contact vertices. Index i plays a vertex:
 * active (i ∈ A) means w_i = 0, inactive z_i = 0. From A = {} the plain
 * method visits {1}, {0,1,2}, {2}, {1}, ... for ever, and no value of z_i or
 * w_i on this path is near zero: a cycle of the method, not of round-off.
 *
 * Checks: (1) the plain method (ActiveSetHistory::toggled(), the update
 * without the remedy) returns to an earlier set; (2) with
 * ActiveSetHistory the cycle is detected and the method stops at the
 * solution of the problem, found by trying all 2^3 active sets. Prints the
 * iterations and one PASS/FAIL line per check; exit status 1 on failure.
 */

#include <algorithm>
#include <deal.II/base/mpi.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/vector.h>
#include <iostream>
#include <membranes/active_set/active_set.h>

using namespace dealii;
using namespace membranes;

namespace
{
  const unsigned int n      = 3;
  const double matrix[n][n] = {{35, -23, 28}, {-23, 22, -15}, {28, -15, 27}};
  const double rhs[n]       = {5, -5, 1};

  /** (z, w) for the active set @p active: w = 0 on it, z = 0 off it. */
  std::pair<Vector<double>, Vector<double>>
  solve(const IndexSet &active)
  {
    const std::vector<types::global_dof_index> indices(active.begin(),
                                                       active.end());
    Vector<double>                             z(n), w(n);
    if (!indices.empty())
      {
        FullMatrix<double> block(indices.size());
        Vector<double>     b(indices.size()), x(indices.size());
        for (unsigned int i = 0; i < indices.size(); ++i)
          {
            b(i) = -rhs[indices[i]];
            for (unsigned int j = 0; j < indices.size(); ++j)
              block(i, j) = matrix[indices[i]][indices[j]];
          }
        block.gauss_jordan();
        block.vmult(x, b);
        for (unsigned int i = 0; i < indices.size(); ++i)
          z(indices[i]) = x(i);
      }
    for (unsigned int i = 0; i < n; ++i)
      {
        w(i) = rhs[i];
        for (unsigned int j = 0; j < n; ++j)
          w(i) += matrix[i][j] * z(j);
      }
    return {z, w};
  }

  /** The indices whose status the test wants to change, as in the solver. */
  std::vector<StatusChange>
  wanted_changes(const IndexSet &active)
  {
    const auto [z, w] = solve(active);
    std::vector<StatusChange> changes;
    for (unsigned int i = 0; i < n; ++i)
      {
        const double violation = active.is_element(i) ? -z(i) : -w(i);
        if (violation > 0)
          changes.push_back({i, violation});
      }
    return changes;
  }

  IndexSet
  index_set(const unsigned int bits)
  {
    IndexSet set(n);
    for (unsigned int i = 0; i < n; ++i)
      if (bits & (1u << i))
        set.add_index(i);
    set.compress();
    return set;
  }

  std::string
  to_string(const IndexSet &set)
  {
    std::string text = "{";
    for (const auto i : set)
      text += (text.size() > 1 ? "," : "") + std::to_string(i);
    return text + "}";
  }

  bool
  check(const bool passed, const std::string &what)
  {
    std::cout << (passed ? "PASS " : "FAIL ") << what << std::endl;
    return passed;
  }
} // namespace



int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi_initialization(argc, argv, 1);
  bool                             passed = true;

  // The solution: the only active set whose (z, w) is feasible.
  IndexSet solution(n);
  for (unsigned int bits = 0; bits < (1u << n); ++bits)
    if (wanted_changes(index_set(bits)).empty())
      solution = index_set(bits);
  std::cout << "solution: active set " << to_string(solution) << std::endl;

  // (1) The plain method, the update of the solver without its remedy:
  // change every wanted index.
  {
    std::vector<IndexSet> visited{IndexSet(n)};
    for (unsigned int iteration = 0; iteration < 10; ++iteration)
      {
        std::vector<types::global_dof_index> dofs;
        for (const auto &change : wanted_changes(visited.back()))
          dofs.push_back(change.dof);
        const IndexSet next = ActiveSetHistory::toggled(visited.back(), dofs);
        std::cout << "plain: " << to_string(visited.back()) << " -> "
                  << to_string(next) << std::endl;
        if (std::find(visited.begin(), visited.end(), next) != visited.end())
          break;
        visited.push_back(next);
      }
    passed &= check(visited.size() < 10 && visited.back() != solution,
                    "the plain method cycles without reaching the solution");
  }

  // (2) With the remedy.
  ActiveSetHistory history(MPI_COMM_WORLD);
  IndexSet         active(n);
  history.restart(active);
  unsigned int iteration = 1;
  for (; iteration <= 20; ++iteration)
    {
      const auto changes = wanted_changes(active);
      if (changes.empty())
        break;
      const auto step = history.next(active, changes);
      std::cout << "iteration " << iteration << ": " << to_string(active)
                << " -> " << to_string(step.active_set) << ", " << step.changed
                << " of " << step.wanted << " changed";
      if (step.cycle_to)
        std::cout << ", cycle back to the set of iteration "
                  << *step.cycle_to + 1;
      if (step.least_index_rule)
        std::cout << ", least-index rule";
      std::cout << std::endl;
      active = step.active_set;
    }
  passed &= check(history.cycles() >= 1, "the cycle is detected");
  passed &= check(iteration <= 20 && active == solution,
                  "the remedy stops at the solution " + to_string(solution) +
                    " after " + std::to_string(iteration) + " iterations");
  return passed ? 0 : 1;
}
