#include <membranes/active_set/active_set_system.h>

namespace membranes
{
  template <int dim>
  ActiveSetSystem<dim>::ActiveSetSystem(
    const std::string         &method,
    const Parameters::Solver  &parameters,
    const Discretization<dim> &discretization,
    const ProblemData<dim>    &data,
    const MPI_Comm             mpi_communicator)
    : discretization(discretization)
    , data(data)
    , mpi_communicator(mpi_communicator)
    , linear_solver(parameters.linear_solver, mpi_communicator)
    , method(method)
  {}



  template <int dim>
  std::string
  ActiveSetSystem<dim>::description() const
  {
    return method + ", " + linear_solver.method();
  }



  template class ActiveSetSystem<2>;
} // namespace membranes
