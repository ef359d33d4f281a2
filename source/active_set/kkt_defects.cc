#include <algorithm>
#include <cmath>
#include <deal.II/base/mpi.h>
#include <limits>
#include <membranes/active_set/kkt_defects.h>

namespace membranes
{
  double
  KKTDefects::relative_residual(const double force_scale,
                                const double contact_force_scale,
                                const double displacement_scale) const
  {
    return std::max(
      {sum_equilibrium / force_scale,
       contact_equilibrium / contact_force_scale,
       std::max(0., -min_w) / displacement_scale,
       std::max(0., -min_contact_force) / contact_force_scale,
       complementarity / (contact_force_scale * displacement_scale)});
  }



  double
  displacement_scale(const TrilinosWrappers::MPI::BlockVector &solution)
  {
    return std::max(solution.linfty_norm(), std::numeric_limits<double>::min());
  }



  template <int dim>
  KKTDefects::KKTDefects(const DiscreteProblem<dim>               &problem,
                         const DiscreteAction<dim>                &action,
                         const ActiveSet<dim>                     &active_set,
                         const TrilinosWrappers::MPI::BlockVector &solution)
  {
    const double max     = std::numeric_limits<double>::max();
    KKTDefects  &defects = *this;
    min_w = min_lambda = min_contact_force = max;
    const auto &vertices                   = problem.vertices();
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const auto  &a             = vertices[k];
        const double d             = a.dual_cell_measure;
        const double w             = problem.nodal_w(k, solution);
        const double lambda        = action.lambda(k);
        const double contact_force = lambda * d;
        defects.sum_equilibrium =
          std::max(defects.sum_equilibrium,
                   std::abs(action.lambda_from_membrane(0, k) -
                            action.lambda_from_membrane(1, k)) *
                     d);
        if (!active_set.is_active(k))
          defects.contact_equilibrium =
            std::max(defects.contact_equilibrium, std::abs(contact_force));
        defects.min_w      = std::min(defects.min_w, w);
        defects.min_lambda = std::min(defects.min_lambda, lambda);
        defects.min_contact_force =
          std::min(defects.min_contact_force, contact_force);
        defects.complementarity =
          std::max(defects.complementarity, std::abs(contact_force * w));
      }
    for (double *maximum : {&defects.sum_equilibrium,
                            &defects.contact_equilibrium,
                            &defects.complementarity})
      *maximum = Utilities::MPI::max(*maximum, problem.get_mpi_communicator());
    for (double *minimum :
         {&defects.min_w, &defects.min_lambda, &defects.min_contact_force})
      *minimum = Utilities::MPI::min(*minimum, problem.get_mpi_communicator());
  }



  template KKTDefects::KKTDefects(const DiscreteProblem<2> &,
                                  const DiscreteAction<2> &,
                                  const ActiveSet<2> &,
                                  const TrilinosWrappers::MPI::BlockVector &);
} // namespace membranes
