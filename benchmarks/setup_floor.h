/**
 * The parts of benchmarks/setup_floor.cc that its steps,
 * benchmarks/setup_floor_cycle.cc, share: the objects that membranes makes
 * for the cell type, and the cycle of case M, step by step. The head
 * comment of setup_floor.cc says what the program measures.
 */

#ifndef membranes_benchmarks_setup_floor_h
#define membranes_benchmarks_setup_floor_h

#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature.h>
#include <deal.II/distributed/solution_transfer.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/solution_transfer.h>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace setup_floor
{
  using namespace dealii;

  constexpr int dim = 2;
  using VectorType  = TrilinosWrappers::MPI::Vector;

  /**
   * The triangulation that membranes makes for the cell type: on
   * quadrilaterals p4est's, on triangles (@p triangles), which p4est cannot
   * hold, one that every process holds whole.
   */
  std::unique_ptr<Triangulation<dim>>
  make_triangulation(const bool triangles, const MPI_Comm mpi_communicator);



  /**
   * The square (-1,1)², with @p triangles split into 8 triangles as
   * membranes splits it (convert_hypercube_to_simplex_mesh of a serial
   * mesh), in @p triangulation, refined @p refinements times.
   */
  void
  make_mesh(const bool          triangles,
            const unsigned int  refinements,
            Triangulation<dim> &triangulation);



  /** The element of one component: linear on the cell type. */
  std::unique_ptr<FiniteElement<dim>>
  make_scalar_element(const bool triangles);



  /**
   * The mapping of membranes' Discretization: on triangles the linear one
   * of simplices, on the axis-parallel squares of case M the Cartesian one.
   */
  std::unique_ptr<Mapping<dim>>
  make_mapping(const bool triangles);



  /** The cell quadrature of membranes' Discretization. */
  Quadrature<dim>
  make_quadrature(const bool triangles);



  /** One timed step: its wall time and the memory of the process after it. */
  struct Step
  {
    std::string name;
    bool        setup; // one of steps 1-4, else part of the solve
    double      seconds;
    double      peak_kib;    // VmHWM
    double      current_kib; // VmRSS
  };



  /**
   * One cycle of case M on a new mesh, step by step: the steps of the
   * cycle are in setup_floor_cycle.cc, their timing and the tables in
   * setup_floor.cc.
   */
  class SetupFloor
  {
  public:
    SetupFloor(const bool         triangles,
               const unsigned int refinements,
               const bool         full_coupling,
               const bool         trim_memory);

    void
    run();

  private:
    template <typename Action>
    void
    timed(const std::string &name, const bool setup, const Action &action);

    double
    time_refinement_alone() const;
    void
    prepare_transfer();
    void
    distribute_dofs();
    void
    interpolate_previous_solution();
    void
    make_constraints();
    void
    setup_matrix();
    void
    assemble();
    void
    setup_amg();
    double
    cg_tolerance() const;
    unsigned int
    solve_cg();
    void
    clear_system();
    std::vector<std::pair<std::string, double>>
    objects_held() const;
    void
    print_objects(
      const std::vector<std::pair<std::string, double>> &objects) const;
    void
    print_table(const double       refinement_alone,
                const unsigned int cg_iterations) const;

    const bool                                triangles;
    const unsigned int                        refinements;
    const bool                                full_coupling;
    const bool                                trim_memory;
    MPI_Comm                                  mpi_communicator;
    const std::unique_ptr<Triangulation<dim>> triangulation;
    const FESystem<dim>                       fe;
    const std::unique_ptr<const Mapping<dim>> mapping;
    const Quadrature<dim>                     quadrature;
    DoFHandler<dim>                           dof_handler;

    IndexSet                          locally_owned_dofs;
    IndexSet                          locally_relevant_dofs;
    AffineConstraints<double>         constraints;
    std::vector<std::vector<bool>>    constant_modes;
    TrilinosWrappers::SparseMatrix    system_matrix;
    VectorType                        system_rhs;
    TrilinosWrappers::PreconditionAMG amg;

    // The solution x and a second vector of the same layout, which stands
    // in for λ_h (membranes carries both to the next mesh); their copies on
    // the previous mesh while a transfer holds them: ghosted ones for the
    // transfer of p4est's mesh, ones with every entry for the serial
    // transfer of triangles.
    VectorType                  solution;
    VectorType                  lambda_h;
    std::vector<VectorType>     previous_vectors;
    std::vector<Vector<double>> replicated_previous_vectors;
    std::unique_ptr<parallel::distributed::SolutionTransfer<dim, VectorType>>
                                                           distributed_transfer;
    std::unique_ptr<SolutionTransfer<dim, Vector<double>>> serial_transfer;

    std::vector<Step> steps;
  };
} // namespace setup_floor

#endif
