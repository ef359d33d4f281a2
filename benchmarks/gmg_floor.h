/**
 * The parts of benchmarks/gmg_floor.cc that its two multigrid
 * preconditioners share: the active sets, the timed steps, the level DoFs
 * of an active set, the cell matrix of the Laplacian, the settings of the
 * Chebyshev smoother, and the two V-cycles, matrix-free
 * (benchmarks/gmg_floor_matrix_free.cc) and on assembled level matrices
 * (benchmarks/gmg_floor_matrix.cc). The head comment of gmg_floor.cc says
 * what the program measures.
 */

#ifndef membranes_benchmarks_gmg_floor_h
#define membranes_benchmarks_gmg_floor_h

#include <algorithm>
#include <chrono>
#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/point.h>
#include <deal.II/base/utilities.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/la_parallel_vector.h>
#include <deal.II/lac/precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <deal.II/lac/vector.h>
#include <deal.II/matrix_free/operators.h>
#include <deal.II/multigrid/mg_coarse.h>
#include <deal.II/multigrid/mg_constrained_dofs.h>
#include <deal.II/multigrid/mg_matrix.h>
#include <deal.II/multigrid/mg_smoother.h>
#include <deal.II/multigrid/mg_transfer.h>
#include <deal.II/multigrid/mg_transfer_matrix_free.h>
#include <deal.II/multigrid/multigrid.h>
#include <functional>
#include <iomanip>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace gmg_floor
{
  using namespace dealii;

  constexpr int dim = 2;

  /** The active sets of the `w` problem; `none` for the `s` problem. */
  enum class Shape
  {
    none,
    disk,
    halfplane,
    ring
  };

  /** Whether the vertex at @p p belongs to the active set @p shape. */
  inline bool
  in_active_set(const Shape shape, const Point<dim> &p)
  {
    const double tolerance = 1e-12;
    const double r         = p.norm();
    switch (shape)
      {
        case Shape::disk:
          return r <= 0.5 + tolerance;
        case Shape::halfplane:
          return p[0] < 0.3;
        case Shape::ring:
          return r >= 0.45 - tolerance && r <= 0.5 + tolerance;
        default:
          return false;
      }
  }



  /**
   * The timed steps: wall time between two barriers, and the peak resident
   * set size of all processes together after the step.
   */
  class Recorder
  {
  public:
    explicit Recorder(const MPI_Comm comm)
      : comm(comm)
    {}

    void
    timed(const std::string &name, const std::function<void()> &action)
    {
      MPI_Barrier(comm);
      const auto start = std::chrono::steady_clock::now();
      action();
      MPI_Barrier(comm);
      const std::chrono::duration<double> seconds =
        std::chrono::steady_clock::now() - start;
      steps.push_back({name, seconds.count(), peak_bytes(), held_bytes()});
    }

    /** A row without a time: the memory of the process when it starts. */
    void
    start()
    {
      steps.push_back(
        {"process start (the libraries)", -1, peak_bytes(), held_bytes()});
    }

    /** The sum over the processes of VmHWM, in bytes. */
    double
    peak_bytes() const
    {
      Utilities::System::MemoryStats memory;
      Utilities::System::get_memory_stats(memory);
      return Utilities::MPI::sum(1024. * memory.VmHWM, comm);
    }

    /** The sum over the processes of VmRSS, in bytes. */
    double
    held_bytes() const
    {
      Utilities::System::MemoryStats memory;
      Utilities::System::get_memory_stats(memory);
      return Utilities::MPI::sum(1024. * memory.VmRSS, comm);
    }

    /** The sum of the times of the steps so far. */
    double
    total() const
    {
      double sum = 0;
      for (const auto &step : steps)
        sum += std::max(step.seconds, 0.);
      return sum;
    }

    void
    print(std::ostream &out, const double n_dofs) const
    {
      out << "| step | s | peak B/DoF | held B/DoF |\n|---|--:|--:|--:|\n";
      for (const auto &step : steps)
        {
          out << "| " << step.name << " | ";
          if (step.seconds >= 0)
            out << std::fixed << std::setprecision(3) << step.seconds;
          out << " | " << std::fixed << std::setprecision(0)
              << step.peak / n_dofs << " | " << step.held / n_dofs << " |\n";
        }
      out << "| **the steps above** | " << std::setprecision(3) << total()
          << " | | |\n";
    }

  private:
    struct Step
    {
      std::string name;
      double      seconds;
      double      peak;
      double      held;
    };
    const MPI_Comm    comm;
    std::vector<Step> steps;
  };



  /**
   * The level DoFs on @p level at vertices of the active set @p shape
   * that are not level boundary DoFs of @p constrained_dofs, on the cells
   * of the level that are not artificial (the vertices of a level are
   * vertices of the finest mesh).
   */
  IndexSet
  active_level_dofs(const DoFHandler<dim>   &dof_handler,
                    const unsigned int       level,
                    const Shape              shape,
                    const MGConstrainedDoFs &constrained_dofs);

  /**
   * The cell matrix of the Laplacian and the cell vector of the load 1 on
   * one cell (active or of a level), with FEValues of 2 × 2 Gauss points,
   * and the DoF indices of the cell for the caller to fill.
   */
  class CellLaplacian
  {
  public:
    CellLaplacian(const Mapping<dim> &mapping, const FiniteElement<dim> &fe);

    template <bool level_dof_access>
    void
    reinit(
      const TriaIterator<DoFCellAccessor<dim, dim, level_dof_access>> &cell)
    {
      fe_values.reinit(cell);
      compute();
    }

    FullMatrix<double>                   matrix;
    Vector<double>                       rhs;
    std::vector<types::global_dof_index> indices;

  private:
    void
    compute();

    FEValues<dim> fe_values;
  };



  /**
   * The settings of the Chebyshev smoother on @p level: degree @p degree,
   * smoothing range 15 and 10 CG iterations for the eigenvalue estimate;
   * on the coarse level, of @p n_coarse_dofs DoFs, Chebyshev iterated to
   * accuracy (the coarse solver).
   */
  template <typename AdditionalData>
  AdditionalData
  chebyshev_settings(const unsigned int level,
                     const unsigned int degree,
                     const unsigned int n_coarse_dofs)
  {
    AdditionalData data;
    if (level > 0)
      {
        data.smoothing_range     = 15.;
        data.degree              = degree;
        data.eig_cg_n_iterations = 10;
      }
    else
      {
        data.smoothing_range     = 1e-3;
        data.degree              = numbers::invalid_unsigned_int;
        data.eig_cg_n_iterations = n_coarse_dofs;
      }
    return data;
  }



  using VectorType      = LinearAlgebra::distributed::Vector<double>;
  using LevelVectorType = LinearAlgebra::distributed::Vector<float>;
  using SystemMatrixType =
    MatrixFreeOperators::LaplaceOperator<dim, 1, 2, 1, VectorType>;
  using LevelMatrixType =
    MatrixFreeOperators::LaplaceOperator<dim, 1, 2, 1, LevelVectorType>;
  using TransferType = MGTransferMatrixFree<dim, float>;
  using SmootherType = PreconditionChebyshev<LevelMatrixType, LevelVectorType>;
  using PreconditionType = PreconditionMG<dim, LevelVectorType, TransferType>;

  /**
   * The multigrid preconditioner of step-37: level operators, transfer,
   * Chebyshev smoother, coarse solver, V-cycle. The active set of
   * @p shape, if any, is constrained on the levels from @p
   * first_constrained_level on (variants (b) and (c) of the `w` problem).
   */
  class GeometricMultigrid
  {
  public:
    GeometricMultigrid(const DoFHandler<dim> &dof_handler,
                       const Mapping<dim>    &mapping,
                       const Shape            shape,
                       const unsigned int     first_constrained_level,
                       Recorder              &recorder,
                       const std::string     &label);

    const PreconditionType &
    preconditioner() const
    {
      return *mg_preconditioner;
    }

  private:
    void
    setup_level_operators(const DoFHandler<dim> &dof_handler,
                          const Mapping<dim>    &mapping,
                          const Shape            shape,
                          const unsigned int     first_constrained_level);
    void
    setup_smoother_and_cycle(const DoFHandler<dim> &dof_handler);

    MGConstrainedDoFs              constrained_dofs;
    MGLevelObject<LevelMatrixType> matrices;
    MGLevelObject<MatrixFreeOperators::MGInterfaceOperator<LevelMatrixType>>
                                                          interface_matrices;
    TransferType                                          transfer;
    mg::SmootherRelaxation<SmootherType, LevelVectorType> smoother;
    MGCoarseGridApplySmoother<LevelVectorType>            coarse;
    mg::Matrix<LevelVectorType>                           matrix_wrapper;
    mg::Matrix<LevelVectorType>                           interface_wrapper;
    std::unique_ptr<Multigrid<LevelVectorType>>           multigrid;
    std::unique_ptr<PreconditionType>                     mg_preconditioner;
  };



  /** The degree of the Chebyshev smoother on level matrices by default. */
  constexpr unsigned int default_matrix_degree = 4;

  using SparseMatrixType   = TrilinosWrappers::SparseMatrix;
  using SparseVectorType   = TrilinosWrappers::MPI::Vector;
  using SparseTransferType = MGTransferPrebuilt<SparseVectorType>;

  /**
   * The inverse of the diagonal of a level matrix as the preconditioner of
   * the Chebyshev smoother. (With DiagonalMatrix, PreconditionChebyshev of
   * deal.II 9.4 does not compile for Trilinos vectors: it calls
   * reinit(size), which TrilinosWrappers::MPI::Vector does not have.)
   */
  class InverseDiagonal
  {
  public:
    /** Holds the inverse of the diagonal of the rows of @p matrix. */
    explicit InverseDiagonal(const SparseMatrixType &matrix);

    void
    vmult(SparseVectorType &dst, const SparseVectorType &src) const
    {
      dst = src;
      dst.scale(inverse);
    }

  private:
    SparseVectorType inverse;
  };

  using SparseSmootherType =
    PreconditionChebyshev<SparseMatrixType, SparseVectorType, InverseDiagonal>;
  using SparsePreconditionType =
    PreconditionMG<dim, SparseVectorType, SparseTransferType>;

  /**
   * The multigrid preconditioner of step-16 and of the matrix-based path
   * of step-50: Trilinos level matrices assembled per level (and interface
   * matrices on refinement edges), MGTransferPrebuilt, Chebyshev smoothing
   * of degree @p degree with the inverse diagonal of the level matrix,
   * Chebyshev to accuracy on the coarse level, one V-cycle. The active
   * set of @p shape, if any, is constrained on every level (variant (b) of
   * the `w` problem, made with level boundary DoFs; see gmg_floor.cc).
   */
  class MatrixBasedMultigrid
  {
  public:
    MatrixBasedMultigrid(const DoFHandler<dim> &dof_handler,
                         const Mapping<dim>    &mapping,
                         const Shape            shape,
                         const unsigned int     degree,
                         Recorder              &recorder,
                         const std::string     &label);

    const SparsePreconditionType &
    preconditioner() const
    {
      return *mg_preconditioner;
    }

  private:
    void
    setup_level_matrices(const DoFHandler<dim> &dof_handler,
                         const Shape            shape,
                         std::vector<IndexSet> &relevant_dofs);
    void
    assemble_level_matrices(const DoFHandler<dim>       &dof_handler,
                            const Mapping<dim>          &mapping,
                            const std::vector<IndexSet> &relevant_dofs);
    void
    setup_smoother_and_cycle(const DoFHandler<dim> &dof_handler,
                             const unsigned int     degree);

    MGConstrainedDoFs               constrained_dofs;
    MGLevelObject<SparseMatrixType> matrices;
    MGLevelObject<SparseMatrixType> interface_matrices;
    SparseTransferType              transfer;
    mg::SmootherRelaxation<SparseSmootherType, SparseVectorType> smoother;
    MGCoarseGridApplySmoother<SparseVectorType>                  coarse;
    mg::Matrix<SparseVectorType>                                 matrix_wrapper;
    mg::Matrix<SparseVectorType>                 interface_wrapper;
    std::unique_ptr<Multigrid<SparseVectorType>> multigrid;
    std::unique_ptr<SparsePreconditionType>      mg_preconditioner;
  };
} // namespace gmg_floor

#endif
