#include <Epetra_Import.h>
#include <Epetra_Vector.h>
#include <membranes/active_set/active_set_system.h>

namespace membranes
{
  template <int dim>
  ActiveSetSystem<dim>::ActiveSetSystem(const std::string        &method,
                                        const Parameters::Solver &parameters,
                                        const ProblemData<dim>   &data,
                                        const MPI_Comm mpi_communicator)
    : data(data)
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



  template <int dim>
  std::vector<char>
  ActiveSetSystem<dim>::active_columns(
    const TrilinosWrappers::SparseMatrix &matrix,
    const IndexSet                       &active_set)
  {
    // The status of the vertex of every column: the owners' flags imported
    // by the matrix's own importer, for the columns of a row can reach
    // beyond the locally relevant DoFs (through the hanging node
    // constraints of a ghost cell).
    const Epetra_CrsMatrix &epetra_matrix = matrix.trilinos_matrix();
    const auto             &columns       = epetra_matrix.ColMap();
    const auto             &owned         = epetra_matrix.DomainMap();
    Epetra_Vector           owned_flags(owned), column_flags(columns);
    for (const auto dof : active_set)
      {
        const int p =
          owned.LID(static_cast<TrilinosWrappers::types::int_type>(dof));
        if (p >= 0)
          owned_flags[p] = 1;
      }
    if (epetra_matrix.Importer() != nullptr)
      column_flags.Import(owned_flags, *epetra_matrix.Importer(), Insert);
    else
      column_flags = owned_flags;
    std::vector<char> status(columns.NumMyElements());
    for (int c = 0; c < columns.NumMyElements(); ++c)
      status[c] = (column_flags[c] > 0);
    return status;
  }



  template class ActiveSetSystem<2>;
} // namespace membranes
