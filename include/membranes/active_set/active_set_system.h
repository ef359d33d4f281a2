#ifndef membranes_active_set_system_h
#define membranes_active_set_system_h

#include <deal.II/base/index_set.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_index_access.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <membranes/active_set/active_set_solver.h>
#include <membranes/active_set/linear_solver.h>
#include <membranes/mesh/discrete_problem.h>
#include <membranes/mesh/discretization.h>
#include <membranes/scene/parameters.h>
#include <membranes/scene/problem_data.h>
#include <string>
#include <vector>

namespace membranes
{
  using namespace dealii;

  /**
   * The linear problem of one iteration of the primal-dual active set
   * method (ActiveSetSolver) for an active set A ⊂ V_h: find (u1h, u2h)
   * with u1h = g_h, u2h = g2_h on ∂ω, the hanging node constraints,
   *
   *   W_a = u1h(a) − u2h(a) = 0  on A,     λ_a = 0  on V_h \ A,
   *
   * and on A the sum of the equations of the two membranes at a (λ_1a =
   * λ_2a, the test function (φ_a, φ_a) of Prop. 12). Two ways to solve it
   * give the same iterate: CoupledSystem on the pair (u1h, u2h), as step-41
   * does it, and, for constant tensions, DecoupledSystem on
   * s = μ1 u1h + μ2 u2h and w = u1h − u2h.
   *
   * What does not depend on the active set (the constraints of the mesh,
   * the loads, and for the decoupled system the operator) is built once per
   * mesh, in setup() or on the first iteration of a mesh; set_active_set()
   * and solve() otherwise only do what the active set changes. ActiveSetSolver
   * times the two in the sections "assembly" and "solve"; solve() adds its
   * CG iterations to the ActiveSetStatistics it is given.
   */
  template <int dim>
  class ActiveSetSystem
  {
  public:
    using VectorType      = TrilinosWrappers::MPI::Vector;
    using BlockVectorType = TrilinosWrappers::MPI::BlockVector;

    virtual ~ActiveSetSystem() = default;

    /**
     * Matrices and sparsity patterns that do not depend on the active set,
     * for the mesh of @p problem and @p dof_handler.
     */
    virtual void
    setup(const DiscreteProblem<dim> &problem,
          const DoFHandler<dim>      &dof_handler) = 0;

    /**
     * Impose @p active_set (DoFs of the active locally relevant vertices,
     * ActiveSet::locally_relevant()) on the linear problem on the mesh of
     * @p problem: here, not in solve(). The lines u1(a) = u2(a) of the
     * active ghost vertices are needed where a hanging node of an owned
     * cell hangs on one: its line resolves through the contact line.
     * CoupledSystem merges its contact lines u1(a) = u2(a) into
     * AffineConstraints and assembles the condensed system; DecoupledSystem
     * imposes W_a = 0 as the projection Π of the operator of W, and
     * condenses the lines W_a = 0 into the matrix of W only when the direct
     * solver or the AMG setup needs that matrix.
     */
    virtual void
    set_active_set(const DiscreteProblem<dim> &problem,
                   const IndexSet             &active_set) = 0;

    /**
     * Solve the linear problem of the last set_active_set(), starting from
     * @p solution with its constrained entries set to zero, to the residual
     * norms @p tolerances. On return @p solution holds (u1h, u2h),
     * constraints included.
     */
    virtual void
    solve(const DiscreteProblem<dim> &problem,
          BlockVectorType            &solution,
          const LinearTolerances     &tolerances,
          ActiveSetStatistics        &statistics) = 0;

    /**
     * Free the matrices, vectors and the AMG hierarchy of this mesh once the
     * active set method has finished on it, so that the postprocessing, the
     * estimators and the refinement run without them; setup() makes them
     * anew for the next mesh.
     */
    virtual void
    clear() = 0;

    /** The method and its linear solver, e.g. "coupled, direct". */
    std::string
    description() const;

  protected:
    /**
     * One locally owned row of a matrix with the sparsity pattern of the
     * Laplacian A of the mesh (DiscreteProblem::laplace_matrix()), seen
     * with an active set: its DoF, whether that is an active vertex and,
     * if so, ∫|∇φ_a|² of the vertex, and Epetra's view of its entries.
     */
    struct MatrixRow
    {
      types::global_dof_index dof;
      bool                    active;
      double                  stiffness_diagonal;
      int                     n_entries;
      double                 *values;
      /** Epetra's local column indices of the entries. */
      const int *columns;
      /** The column map of the matrix, and the status of each column. */
      const Epetra_BlockMap   *column_map;
      const std::vector<char> *active_columns;

      /** The DoF of entry @p e. */
      types::global_dof_index
      column(const int e) const
      {
        return TrilinosWrappers::global_index(*column_map, columns[e]);
      }

      /** Whether the DoF of entry @p e is an active vertex. */
      bool
      active_column(const int e) const
      {
        return (*active_columns)[columns[e]];
      }
    };

    /**
     * @p row_function for each locally owned row of @p matrix (a copy of
     * the Laplacian of @p problem, or the Laplacian itself) with the
     * locally relevant active vertices @p active_set: one pass over the
     * locally stored entries by Epetra's row views, which point into the
     * values of the matrix. A template, so that the compiler sees the
     * function of a row inside the loop over the rows.
     */
    template <typename RowFunction>
    static void
    for_each_row(const DiscreteProblem<dim>           &problem,
                 const TrilinosWrappers::SparseMatrix &matrix,
                 const IndexSet                       &active_set,
                 const RowFunction                    &row_function);

    ActiveSetSystem(const std::string        &method,
                    const Parameters::Solver &parameters,
                    const ProblemData<dim>   &data,
                    const MPI_Comm            mpi_communicator);

    const ProblemData<dim> &data;
    const MPI_Comm          mpi_communicator;
    LinearSolver            linear_solver;

  private:
    /**
     * Whether each column of @p matrix (in Epetra's local numbering of its
     * column map) is an active vertex of @p active_set.
     */
    static std::vector<char>
    active_columns(const TrilinosWrappers::SparseMatrix &matrix,
                   const IndexSet                       &active_set);

    const std::string method;
  };



  template <int dim>
  template <typename RowFunction>
  void
  ActiveSetSystem<dim>::for_each_row(
    const DiscreteProblem<dim>           &problem,
    const TrilinosWrappers::SparseMatrix &matrix,
    const IndexSet                       &active_set,
    const RowFunction                    &row_function)
  {
    const Epetra_CrsMatrix &epetra_matrix = matrix.trilinos_matrix();
    const std::vector<char> column_status = active_columns(matrix, active_set);

    // The rows and the vertices of V_h are both sorted by the DoF.
    const auto &vertices = problem.vertices();
    auto        vertex   = vertices.begin();
    MatrixRow   row;
    row.column_map     = &epetra_matrix.ColMap();
    row.active_columns = &column_status;
    for (int r = 0; r < epetra_matrix.NumMyRows(); ++r)
      {
        row.dof = TrilinosWrappers::global_index(epetra_matrix.RowMap(), r);
        while (vertex != vertices.end() && vertex->dof < row.dof)
          ++vertex;
        row.active             = column_status[epetra_matrix.ColMap().LID(
          static_cast<TrilinosWrappers::types::int_type>(row.dof))];
        row.stiffness_diagonal = row.active ? vertex->stiffness_diagonal : 0;
        int *indices;
        epetra_matrix.ExtractMyRowView(r, row.n_entries, row.values, indices);
        row.columns = indices;
        row_function(row);
      }
  }
} // namespace membranes

#endif
