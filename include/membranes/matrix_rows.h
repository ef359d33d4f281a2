#ifndef membranes_matrix_rows_h
#define membranes_matrix_rows_h

#include <Epetra_CrsMatrix.h>
#include <deal.II/base/array_view.h>
#include <deal.II/base/types.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>

namespace membranes
{
  using namespace dealii;

  /**
   * The locally owned rows of an assembled Trilinos matrix, read and
   * written in place: how the systems of the active set method make the
   * matrix of an iteration from the operator of the mesh (MeshOperator) in
   * one pass over its entries, without a cell loop.
   *
   * deal.II's iterators over the rows of a TrilinosWrappers::SparseMatrix
   * copy every row they visit into a buffer of n() entries, so a pass over
   * all rows costs far more than the matrix has entries. Epetra's row views
   * point into the matrix's storage instead, writable even through a const
   * matrix: the values can be overwritten, the sparsity pattern stays.
   *
   * Rows and columns are numbered locally, as Epetra does: the locally
   * owned rows 0, …, n_rows() − 1 in the order of their global indices, the
   * columns by the matrix's column map (the columns that occur in the
   * locally owned rows); global_row() and global_column() translate, and
   * local_row() and local_column() back (−1 where the matrix has no such
   * locally owned row or column).
   */
  class MatrixRows
  {
  public:
    /** The entries of one row: values and local column indices. */
    struct Row
    {
      ArrayView<double>    values;
      ArrayView<const int> columns;
    };

    explicit MatrixRows(const TrilinosWrappers::SparseMatrix &matrix)
      : matrix(matrix.trilinos_matrix())
    {}

    unsigned int
    n_rows() const
    {
      return matrix.NumMyRows();
    }

    unsigned int
    n_columns() const
    {
      return matrix.NumMyCols();
    }

    Row
    operator[](const int local_row) const
    {
      int     n_entries;
      double *values;
      int    *columns;
      matrix.ExtractMyRowView(local_row, n_entries, values, columns);
      return {ArrayView<double>(values, n_entries),
              ArrayView<const int>(columns, n_entries)};
    }

    types::global_dof_index
    global_row(const int local_row) const
    {
      return matrix.GRID64(local_row);
    }

    types::global_dof_index
    global_column(const int local_column) const
    {
      return matrix.GCID64(local_column);
    }

    int
    local_row(const types::global_dof_index row) const
    {
      return matrix.LRID(static_cast<long long>(row));
    }

    int
    local_column(const types::global_dof_index column) const
    {
      return matrix.LCID(static_cast<long long>(column));
    }

  private:
    const Epetra_CrsMatrix &matrix;
  };
} // namespace membranes

#endif
