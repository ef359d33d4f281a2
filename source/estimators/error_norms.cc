#include <algorithm>
#include <cmath>
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/fe/fe_values.h>
#include <limits>
#include <membranes/estimators/error_norms.h>
#include <membranes/mesh/cell_loop.h>

namespace membranes
{
  namespace
  {
    /** The depth of the refinement of the sub-triangles where λ jumps. */
    constexpr unsigned int jump_max_depth = 5;



    /**
     * ∫_κ (λ − λ_h)² over the sub-triangles κ of one cell where the exact λ
     * jumps, by recursive refinement of each κ.
     *
     * A triangle T (in reference coordinates) carries λ at its six nodes:
     * its corners z_j and the midpoints m_j of the edges opposite them.
     * Where these differ by more than a threshold, T is cut into its four
     * children, whose corners are the nodes of T (only their edge midpoints
     * are new), down to a maximum depth; otherwise
     * ∫_T f = |T|/3 Σ_j f(m_j) |det J(m_j)|, the edge-midpoint rule, exact
     * for polynomials of degree 2. Near a jump along a curve, about 2^d of
     * the 4^d triangles of depth d are cut, so that the cost grows as 2^d,
     * not 4^d, while the part of κ left to one rule shrinks as 2^{−d}. The
     * map is the d-linear one of the cell's vertices, the mapping of
     * Discretization (affine on triangles, bilinear on quadrilaterals). The
     * nodes of one level of a cell are evaluated in one call of
     * ProblemData::exact_action_list(), λ alone: some lie on the edges of
     * the cell, where the exact u may be singular (on the slit).
     */
    template <int dim>
    class JumpRefinement
    {
    public:
      using CellIterator = typename DualMesh<dim>::CellIterator;
      using SubTriangle  = typename DualCellQuadrature<dim>::SubTriangle;

      JumpRefinement(const ProblemData<dim> &data, const double threshold)
        : data(data)
        , threshold(threshold)
      {}

      /**
       * Add ∫_κ (λ − λ_h)² over the sub-triangles @p sub_triangles of
       * @p cell to @p squares[4] where κ lies in ω_h, to @p squares[5] on
       * the strip ω ∖ ω_h (where λ_h = 0).
       */
      void
      add(const CellIterator                  &cell,
          const std::vector<SubTriangle>      &sub_triangles,
          const DualMesh<dim>                 &dual_mesh,
          const TrilinosWrappers::MPI::Vector &lambda_h,
          std::array<double, 6>               &squares)
      {
        vertices.clear();
        for (const unsigned int v : cell->vertex_indices())
          vertices.push_back(cell->vertex(v));
        level.clear();
        for (unsigned int s = 0; s < sub_triangles.size(); ++s)
          {
            Triangle triangle;
            triangle.sub_triangle = s;
            std::copy(sub_triangles[s].corners.begin(),
                      sub_triangles[s].corners.end(),
                      triangle.nodes.begin());
            level.push_back(triangle);
          }
        evaluate(cell->reference_cell(), 0);
        for (unsigned int depth = 0; !level.empty(); ++depth)
          {
            next.clear();
            for (const Triangle &triangle : level)
              {
                const auto [min, max] =
                  std::minmax_element(triangle.values.begin(),
                                      triangle.values.end());
                const bool varies = *max - *min > threshold;
                if (varies && depth < jump_max_depth)
                  {
                    split(triangle);
                    continue;
                  }
                const unsigned int v =
                  sub_triangles[triangle.sub_triangle].vertex;
                const double lambda_h_value =
                  dual_mesh.lambda_h_value(cell, v, lambda_h);
                const Tensor<1, dim> e1 = triangle.nodes[1] - triangle.nodes[0];
                const Tensor<1, dim> e2 = triangle.nodes[2] - triangle.nodes[0];
                const double area = std::abs(e1[0] * e2[1] - e1[1] * e2[0]) / 2;
                for (unsigned int j = 0; j < 3; ++j)
                  squares[dual_mesh.is_interior_vertex(cell, v) ? 4 : 5] +=
                    area / 3 * triangle.jacobians[j] *
                    std::pow(triangle.values[3 + j] - lambda_h_value, 2);
              }
            std::swap(level, next);
            evaluate(cell->reference_cell(), 3);
          }
      }

    private:
      struct Triangle
      {
        unsigned int sub_triangle; ///< The κ it lies in.
        /** The corners z_j, then the midpoints m_j opposite them. */
        std::array<Point<dim>, 6> nodes;
        std::array<double, 6>     values;    ///< λ at the nodes.
        std::array<double, 3>     jacobians; ///< |det J| at the m_j.
      };

      /** The four children of @p parent into `next`, with their corners. */
      void
      split(const Triangle &parent)
      {
        static constexpr unsigned int children[4][3] = {{0, 5, 4},
                                                        {5, 1, 3},
                                                        {4, 3, 2},
                                                        {3, 4, 5}};
        for (const auto &corners : children)
          {
            Triangle child;
            child.sub_triangle = parent.sub_triangle;
            for (unsigned int j = 0; j < 3; ++j)
              {
                child.nodes[j]  = parent.nodes[corners[j]];
                child.values[j] = parent.values[corners[j]];
              }
            next.push_back(child);
          }
      }

      /**
       * The edge midpoints of the triangles of `level`, their |det J|, and
       * λ at the nodes from @p first on (0: all six; 3: the midpoints).
       */
      void
      evaluate(const ReferenceCell &reference_cell, const unsigned int first)
      {
        points.clear();
        for (Triangle &triangle : level)
          for (unsigned int j = 0; j < 3; ++j)
            {
              const Point<dim> xi =
                (triangle.nodes[(j + 1) % 3] + triangle.nodes[(j + 2) % 3]) / 2;
              triangle.nodes[3 + j] = xi;
              Tensor<2, dim> jacobian;
              for (unsigned int v = 0; v < vertices.size(); ++v)
                jacobian += outer_product(
                  vertices[v],
                  reference_cell.d_linear_shape_function_gradient(xi, v));
              triangle.jacobians[j] = std::abs(determinant(jacobian));
            }
        for (const Triangle &triangle : level)
          for (unsigned int j = first; j < 6; ++j)
            {
              Point<dim> x;
              for (unsigned int v = 0; v < vertices.size(); ++v)
                x +=
                  reference_cell.d_linear_shape_function(triangle.nodes[j], v) *
                  vertices[v];
              points.push_back(x);
            }
        if (points.empty())
          return;
        data.exact_action_list(points, lambda);
        unsigned int k = 0;
        for (Triangle &triangle : level)
          for (unsigned int j = first; j < 6; ++j)
            triangle.values[j] = lambda[k++];
      }

      const ProblemData<dim> &data;
      const double            threshold;
      std::vector<Point<dim>> vertices;
      std::vector<Triangle>   level, next;
      std::vector<Point<dim>> points;
      std::vector<double>     lambda;
    };



    /**
     * What one thread of ErrorNorms::compute() needs on a cell: u_h and its
     * gradient at the points of the cell rule, λ_h at those of the
     * dual-cell rule, the exact solution at both from one call of
     * ProblemData::exact_solution_list(), and the exact λ at the vertices.
     */
    template <int dim>
    struct Scratch
    {
      Scratch(const Discretization<dim>           &discretization,
              const Quadrature<dim>               &u_rule,
              const DualCellQuadrature<dim>       &lambda_rule,
              const DualMesh<dim>                 &dual_mesh,
              const TrilinosWrappers::MPI::Vector &lambda_h,
              const ProblemData<dim>              &data,
              const double                         threshold)
        : values(discretization,
                 lambda_rule,
                 dual_mesh,
                 lambda_h,
                 update_quadrature_points | update_JxW_values)
        , u_values(*discretization.mapping,
                   *discretization.fe,
                   u_rule,
                   update_values | update_gradients | update_quadrature_points |
                     update_JxW_values)
        , jumps(data, threshold)
      {
        for (unsigned int i = 0; i < 2; ++i)
          {
            uh[i].resize(u_rule.size());
            grad_uh[i].resize(u_rule.size());
          }
      }

      /**
       * All of it on @p cell: `exact` holds the exact solution at the
       * points of the cell rule, then at those of the dual-cell rule.
       */
      void
      reinit(const typename DualMesh<dim>::CellIterator &cell,
             const TrilinosWrappers::MPI::BlockVector   &ghosted_solution,
             const ProblemData<dim>                     &data)
      {
        values.reinit(cell, ghosted_solution);
        u_values.reinit(cell);
        const FEValuesExtractors::Scalar scalar(0);
        for (unsigned int i = 0; i < 2; ++i)
          {
            u_values[scalar].get_function_values_from_local_dof_values(
              values.local_dofs[i], uh[i]);
            u_values[scalar].get_function_gradients_from_local_dof_values(
              values.local_dofs[i], grad_uh[i]);
          }
        const auto &lambda_points = values.fe_values.get_quadrature_points();
        points                    = u_values.get_quadrature_points();
        points.insert(points.end(), lambda_points.begin(), lambda_points.end());
        data.set_gradient_step(1e-4 * cell->diameter());
        data.exact_solution_list(points, exact);
        vertices.clear();
        for (const unsigned int v : cell->vertex_indices())
          vertices.push_back(cell->vertex(v));
        data.exact_action_list(vertices, vertex_lambda);
      }

      DualCellValues<dim>                        values;
      FEValues<dim>                              u_values;
      std::array<std::vector<double>, 2>         uh;
      std::array<std::vector<Tensor<1, dim>>, 2> grad_uh;
      std::vector<Point<dim>>                    points, vertices;
      typename ProblemData<dim>::ExactValues     exact;
      std::vector<double>                        vertex_lambda;
      JumpRefinement<dim>                        jumps;
    };



    /** Whether @p exact names any of the error columns @p names. */
    bool
    computes_one_of(const Parameters::ExactSolution          &exact,
                    const std::initializer_list<const char *> names)
    {
      return std::any_of(names.begin(), names.end(), [&](const char *name) {
        return exact.computes(name);
      });
    }



    /**
     * The errors that @p exact names from the squares of the seminorms
     * |u_i − u_ih|²_{H1} (entries 0, 1), of ‖u_i − u_ih‖²_{L2} (2, 3) and
     * of ‖λ − λ_h‖²_{L2} on ω_h (4) and on the strip ω ∖ ω_h (5): the full
     * H1 norm of (3.5) and the energy norm from the seminorms.
     */
    ErrorRecord
    error_record(const std::array<double, 6>     &squares,
                 const std::array<double, 2>     &mu,
                 const Parameters::ExactSolution &exact)
    {
      ErrorRecord errors;
      const auto  set = [&](const char            *name,
                           std::optional<double> &norm,
                           const double           square) {
        if (exact.computes(name))
          norm = std::sqrt(square);
      };
      set("err_u1_H1", errors.u1_H1, squares[0] + squares[2]);
      set("err_u2_H1", errors.u2_H1, squares[1] + squares[3]);
      set("err_u1_L2", errors.u1_L2, squares[2]);
      set("err_u2_L2", errors.u2_L2, squares[3]);
      set("err_lambda_L2", errors.lambda_L2, squares[4] + squares[5]);
      set("err_lambda_L2_omega_h", errors.lambda_L2_omega_h, squares[4]);
      set("err_energy", errors.energy, mu[0] * squares[0] + mu[1] * squares[1]);
      return errors;
    }
  } // namespace



  template <int dim>
  ErrorNorms<dim>::ErrorNorms(const Discretization<dim> &discretization,
                              const ProblemData<dim>    &data,
                              const unsigned int         reference_levels)
    : discretization(discretization)
    , data(data)
    , reference_levels(reference_levels)
    , lambda_rule(discretization.fe->reference_cell(),
                  reference_levels == 0 ?
                    Quadrature<dim>(QWitherdenVincentSimplex<dim>(1, false)) :
                    QIteratedSimplex<dim>(QGaussSimplex<dim>(2),
                                          1u << reference_levels))
    , u_rule(reference_levels == 0 ? discretization.cell_quadrature :
                                     lambda_rule.quadrature())
  {}



  template <int dim>
  ErrorRecord
  ErrorNorms<dim>::compute(const DoFHandler<dim>           &dof_handler,
                           const BlockVectorType           &ghosted_solution,
                           const DualMesh<dim>             &dual_mesh,
                           const VectorType                &lambda_h,
                           const Parameters::ExactSolution &exact_parameters,
                           const MPI_Comm mpi_communicator) const
  {
    const bool displacements = computes_one_of(
      exact_parameters,
      {"err_u1_H1", "err_u2_H1", "err_u1_L2", "err_u2_L2", "err_energy"});
    const bool action =
      computes_one_of(exact_parameters,
                      {"err_lambda_L2", "err_lambda_L2_omega_h"});
    if (!displacements && !action)
      return {};

    // The norms asked for in one pass over the cells (see the class comment
    // for why not VectorTools::integrate_difference()).
    // Squared norms on one cell, and summed over the locally owned cells.
    using Squares = std::array<double, 6>;
    Squares squares{};
    // No refinement for the reference rule.
    const double threshold = reference_levels == 0 ?
                               lambda_jump_fraction * lambda_h.linfty_norm() :
                               std::numeric_limits<double>::infinity();

    run_on_cells<Squares>(
      dof_handler,
      [&]() {
        return std::make_unique<Scratch<dim>>(discretization,
                                              u_rule,
                                              lambda_rule,
                                              dual_mesh,
                                              lambda_h,
                                              data,
                                              threshold);
      },
      [&](const auto &cell, Scratch<dim> &scratch, Squares &cell_squares) {
        cell_squares = Squares{};
        if (!cell->is_locally_owned())
          return;
        scratch.reinit(cell, ghosted_solution, data);
        const FEValues<dim> &u_values = scratch.u_values;
        const FEValues<dim> &values   = scratch.values.fe_values;
        const auto          &exact    = scratch.exact;

        if (displacements)
          for (const unsigned int q : u_values.quadrature_point_indices())
            for (unsigned int i = 0; i < 2; ++i)
              {
                cell_squares[i] +=
                  (exact.grad_u[i][q] - scratch.grad_uh[i][q]).norm_square() *
                  u_values.JxW(q);
                cell_squares[2 + i] +=
                  std::pow(exact.u[i][q] - scratch.uh[i][q], 2) *
                  u_values.JxW(q);
              }
        if (!action)
          return;
        // Where λ jumps across the cell (see the class comment).
        const auto [min, max] =
          std::minmax_element(exact.lambda.begin(), exact.lambda.end());
        const auto [vertex_min, vertex_max] =
          std::minmax_element(scratch.vertex_lambda.begin(),
                              scratch.vertex_lambda.end());
        if (std::max(*max, *vertex_max) - std::min(*min, *vertex_min) >
            threshold)
          {
            scratch.jumps.add(cell,
                              lambda_rule.sub_triangles(),
                              dual_mesh,
                              lambda_h,
                              cell_squares);
            return;
          }
        const unsigned int n_u = u_values.n_quadrature_points;
        for (const unsigned int q : values.quadrature_point_indices())
          {
            // λ_h = 0 on the strip ω ∖ ω_h.
            const bool   in_omega_h = scratch.values.in_omega_h[q];
            const double error      = exact.lambda[n_u + q] -
                                 (in_omega_h ? scratch.values.lambda_h[q] : 0.);
            cell_squares[in_omega_h ? 4 : 5] += error * error * values.JxW(q);
          }
      },
      [&](const Squares &cell_squares) {
        for (unsigned int k = 0; k < squares.size(); ++k)
          squares[k] += cell_squares[k];
      });

    Utilities::MPI::sum<double>(squares, mpi_communicator, squares);
    return error_record(squares, data.mu, exact_parameters);
  }



  template class ErrorNorms<2>;
} // namespace membranes
