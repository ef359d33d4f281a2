#include <algorithm>
#include <cmath>
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/distributed/tria_base.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/lapack_full_matrix.h>
#include <map>
#include <membranes/flux_reconstruction.h>
#include <tuple>
#include <unordered_map>

namespace membranes
{
  namespace
  {
    /**
     * Overwrite the lower triangle of the symmetric matrix @p L with its
     * Cholesky factor (L Lᵀ = the matrix). Returns false if a pivot is not
     * positive relative to the diagonal entry.
     */
    bool
    cholesky_factorize(FullMatrix<double> &L)
    {
      const unsigned int n = L.m();
      for (unsigned int j = 0; j < n; ++j)
        {
          double d = L(j, j);
          for (unsigned int k = 0; k < j; ++k)
            d -= L(j, k) * L(j, k);
          if (!(d > 1e-14 * std::abs(L(j, j))))
            return false;
          L(j, j) = std::sqrt(d);
          for (unsigned int i = j + 1; i < n; ++i)
            {
              for (unsigned int k = 0; k < j; ++k)
                L(i, j) -= L(i, k) * L(j, k);
              L(i, j) /= L(j, j);
            }
        }
      return true;
    }



    /** Overwrite @p v with (L Lᵀ)⁻¹ v for the Cholesky factor @p L. */
    void
    cholesky_solve(const FullMatrix<double> &L, double *v)
    {
      const unsigned int n = L.m();
      for (unsigned int i = 0; i < n; ++i)
        {
          for (unsigned int k = 0; k < i; ++k)
            v[i] -= L(i, k) * v[k];
          v[i] /= L(i, i);
        }
      for (unsigned int i = n; i-- > 0;)
        {
          for (unsigned int k = i + 1; k < n; ++k)
            v[i] -= L(k, i) * v[k];
          v[i] /= L(i, i);
        }
    }



    /** The work arrays of solve_saddle_point(). */
    struct SaddlePointScratch
    {
      FullMatrix<double>  L, S;
      std::vector<double> Z, y;
    };



    /**
     * Solve the saddle point system [A Bᵀ; B 0] (x; y) = (b; c) with
     * A (n × n) symmetric positive definite and B (n_c × n) of full rank,
     * given as the m × m matrix @p K, m = n + n_c, for two right-hand sides
     * @p rhs (overwritten with the solutions): by the Cholesky factors of
     * A and of the Schur complement S = B A⁻¹ Bᵀ. Returns false if a
     * pivot is not positive (the system is then left to an LU solver).
     */
    bool
    solve_saddle_point(const FullMatrix<double>      &K,
                       const unsigned int             n,
                       std::array<Vector<double>, 2> &rhs,
                       SaddlePointScratch            &scratch)
    {
      const unsigned int n_c = K.m() - n;
      auto &[L, S, Z, y]     = scratch;
      L.reinit(n, n);
      L.fill(K, 0, 0, 0, 0);
      if (!cholesky_factorize(L))
        return false;
      // Z = A⁻¹ Bᵀ column by column, S = B Z and its Cholesky factor.
      Z.resize(n_c * n);
      for (unsigned int c = 0; c < n_c; ++c)
        {
          for (unsigned int i = 0; i < n; ++i)
            Z[c * n + i] = K(n + c, i);
          cholesky_solve(L, &Z[c * n]);
        }
      S.reinit(n_c, n_c);
      for (unsigned int c = 0; c < n_c; ++c)
        for (unsigned int d = 0; d <= c; ++d)
          for (unsigned int i = 0; i < n; ++i)
            S(c, d) += K(n + c, i) * Z[d * n + i];
      if (!cholesky_factorize(S))
        return false;
      y.resize(n_c);
      for (auto &r : rhs)
        {
          // x₀ = A⁻¹ b, then S y = B x₀ − c and x = x₀ − Z y.
          cholesky_solve(L, r.data());
          for (unsigned int c = 0; c < n_c; ++c)
            {
              y[c] = -r[n + c];
              for (unsigned int i = 0; i < n; ++i)
                y[c] += K(n + c, i) * r[i];
            }
          cholesky_solve(S, y.data());
          for (unsigned int c = 0; c < n_c; ++c)
            {
              r[n + c] = y[c];
              for (unsigned int i = 0; i < n; ++i)
                r[i] -= Z[c * n + i] * y[c];
            }
        }
      return true;
    }



    /** The matrix of a DerivativeForm, for the Piola transform. */
    template <int dim>
    Tensor<2, dim>
    to_tensor(const DerivativeForm<1, dim, dim> &jacobian)
    {
      Tensor<2, dim> matrix;
      for (unsigned int r = 0; r < dim; ++r)
        for (unsigned int c = 0; c < dim; ++c)
          matrix[r][c] = jacobian[r][c];
      return matrix;
    }



    /**
     * The points at which one cell's reconstruction needs u_ih and the
     * mapping, in reference coordinates: first the points of the dual
     * quadrature (for the inner products of the minimization), then two
     * Gauss points on every edge of every sub-triangle (for the fluxes
     * (4.13)), then, @p with_corners, the corners of every sub-triangle
     * (for the output).
     */
    template <int dim>
    struct ReconstructionPoints
    {
      static constexpr unsigned int n_edge_points = 2;

      ReconstructionPoints(const DualCellQuadrature<dim> &dual,
                           const bool                     with_corners)
        : n_volume(dual.quadrature().size())
        , n_triangles(dual.sub_triangles().size())
      {
        std::vector<Point<dim>> points  = dual.quadrature().get_points();
        std::vector<double>     weights = dual.quadrature().get_weights();
        const QGauss<1>         gauss(n_edge_points);
        for (const auto &triangle : dual.sub_triangles())
          for (unsigned int j = 0; j < 3; ++j)
            {
              const Point<dim> &p = triangle.corners[(j + 1) % 3];
              const Point<dim> &q = triangle.corners[(j + 2) % 3];
              for (unsigned int k = 0; k < n_edge_points; ++k)
                {
                  points.push_back(p + gauss.point(k)[0] * (q - p));
                  weights.push_back(gauss.weight(k) * (q - p).norm());
                }
            }
        for (const auto &triangle : dual.sub_triangles())
          for (unsigned int j = 0; j < (with_corners ? 3 : 0); ++j)
            {
              points.push_back(triangle.corners[j]);
              weights.push_back(0);
            }
        quadrature = Quadrature<dim>(points, weights);
      }

      unsigned int
      edge_point(const unsigned int s,
                 const unsigned int j,
                 const unsigned int k) const
      {
        return n_volume + (3 * s + j) * n_edge_points + k;
      }

      unsigned int
      corner_point(const unsigned int s, const unsigned int j) const
      {
        return n_volume + 3 * n_edge_points * n_triangles + 3 * s + j;
      }

      const unsigned int n_volume;
      const unsigned int n_triangles;
      Quadrature<dim>    quadrature;
    };



    /**
     * The index of the coarse edge of which face @p f of @p cell is a half,
     * when the neighbour there is coarser. (Found among the neighbour's
     * faces: CellAccessor::neighbor_of_coarser_neighbor() fails on
     * triangle meshes in deal.II 9.4.)
     */
    template <typename CellIterator>
    unsigned int
    coarse_face_index(const CellIterator &cell, const unsigned int f)
    {
      const auto fine_face = cell->face(f);
      for (const auto &face : cell->neighbor(f)->face_iterators())
        if (face->has_children())
          for (unsigned int c = 0; c < face->n_children(); ++c)
            if (face->child(c) == fine_face)
              return face->index();
      Assert(false, ExcInternalError());
      return numbers::invalid_unsigned_int;
    }



    /**
     * One unknown normal flux density s of the minimization: a half-edge
     * a–m_e, or a whole edge with a hanging node. Its numerator and
     * denominator are summed over the sub-triangles that touch it.
     */
    template <int dim>
    struct FreeFlux
    {
      Tensor<1, dim>        normal; ///< The direction in which s counts.
      std::array<double, 2> numerator{};
      double                denominator = 0;
    };
  } // namespace



  template <int dim>
  FluxReconstruction<dim>::FluxReconstruction(
    const Discretization<dim> &discretization,
    const ProblemData<dim>    &data,
    const DiscreteAction<dim> &action)
    : discretization(discretization)
    , data(data)
    , action(action)
    , dual_cell_quadrature(action.dual_quadrature())
  {
    // The hat functions of the cell's vertices at the Gauss points of the
    // edges of the sub-triangles (reference values).
    const ReconstructionPoints<dim> points(dual_cell_quadrature, false);
    const FiniteElement<dim>       &fe = *discretization.fe;
    for (unsigned int s = 0; s < dual_cell_quadrature.sub_triangles().size();
         ++s)
      for (unsigned int e = 0; e < 3; ++e)
        for (unsigned int k = 0; k < points.n_edge_points; ++k)
          for (unsigned int v = 0; v < GeometryInfo<dim>::vertices_per_cell;
               ++v)
            edge_shape_values.push_back(
              v < fe.reference_cell().n_vertices() ?
                fe.shape_value(fe.component_to_system_index(0, v),
                               points.quadrature.point(
                                 points.edge_point(s, e, k))) :
                0.);

    // Around b_K, sub-triangle (a, m_e, b_K) meets (a', m_e, b_K), a' the
    // other end of e, across edge 0, and (a, m_e', b_K), e' the other edge
    // through a, across edge 1.
    const auto &triangles = dual_cell_quadrature.sub_triangles();
    ring.push_back(0);
    while (ring.size() < triangles.size())
      {
        const auto &last = triangles[ring.back()];
        for (unsigned int t = 0; t < triangles.size(); ++t)
          if (ring.size() % 2 == 1 ? (triangles[t].face == last.face &&
                                      triangles[t].vertex != last.vertex) :
                                     (triangles[t].vertex == last.vertex &&
                                      triangles[t].face != last.face))
            {
              ring.push_back(t);
              break;
            }
      }
  }



  template <int dim>
  Tensor<1, dim>
  FluxReconstruction<dim>::reference_flux(const unsigned int           s,
                                          const std::array<double, 3> &fluxes,
                                          const Point<dim>            &x) const
  {
    // The Raviart–Thomas basis function of unit outward flux through the
    // edge opposite corner p_j is (x − p_j) / (2 |κ|).
    const auto    &triangle = dual_cell_quadrature.sub_triangles()[s];
    Tensor<1, dim> t;
    for (unsigned int j = 0; j < 3; ++j)
      t += fluxes[j] * (x - triangle.corners[j]) / (2 * triangle.area);
    return t;
  }



  template <int dim>
  void
  FluxReconstruction<dim>::reconstruct(
    const DoFHandler<dim>           &dof_handler,
    const VectorType                &ghosted_solution,
    const AffineConstraints<double> &hanging_node_constraints,
    const IndexSet                  &locally_owned_dofs,
    const MPI_Comm                   mpi_communicator)
  {
    this->dof_handler                   = &dof_handler;
    const FiniteElement<dim> &fe        = *discretization.fe;
    const auto               &triangles = dual_cell_quadrature.sub_triangles();
    const unsigned int        n_triangles = triangles.size();
    ReconstructionPoints<dim> points(dual_cell_quadrature, false);
    FEValues<dim>             fe_values(*discretization.mapping,
                            fe,
                            points.quadrature,
                            update_values | update_gradients |
                              update_jacobians | update_quadrature_points |
                              update_JxW_values);
    std::array<std::vector<Tensor<1, dim>>, 2> gradients;
    for (auto &gradient : gradients)
      gradient.resize(points.quadrature.size());
    // The Raviart–Thomas basis of each sub-triangle at its points of the
    // dual quadrature, in reference coordinates.
    std::vector<std::array<Tensor<1, dim>, 3>> reference_basis(points.n_volume);
    for (unsigned int q = 0; q < points.n_volume; ++q)
      for (unsigned int k = 0; k < 3; ++k)
        {
          std::array<double, 3> unit{};
          unit[k] = 1;
          reference_basis[q][k] =
            reference_flux(dual_cell_quadrature.sub_triangle_of_point(q),
                           unit,
                           points.quadrature.point(q));
        }
    const unsigned int      n_vertices = fe.reference_cell().n_vertices();
    std::vector<Point<dim>> volume_points(points.n_volume);
    std::vector<double>     load(points.n_volume);

    const unsigned int n_cells =
      dof_handler.get_triangulation().n_active_cells();
    sub_triangle_data.assign(n_cells * n_triangles, SubTriangleData());
    std::unordered_map<unsigned long long, unsigned int> free_flux_index;
    std::vector<FreeFlux<dim>>                           free_fluxes;
    std::vector<std::pair<unsigned int, double>>         free_flux_of(n_cells *
                                                              n_triangles);
    free_flux_index.reserve(n_cells * n_triangles);
    free_fluxes.reserve(n_cells * n_triangles);
    load_at_points.assign(2 * n_cells * points.n_volume, 0.);
    std::vector<PatchTerms> patch_terms(n_cells * n_triangles);

    // The owned and the ghost cells: the cells along every half-edge of an
    // owned cell (along the whole coarse edge at a hanging node) lie in
    // them, so the half-edge rule below gives the owned cells the same t_ih
    // as on one process, without communication. (At the outer rim of the
    // ghost layer, groups are cut short by artificial cells; they belong
    // to no owned cell.) The patch problems need the owned cells only.
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (!cell->is_artificial())
        {
          fe_values.reinit(cell);
          for (unsigned int i = 0; i < 2; ++i)
            fe_values[FEValuesExtractors::Scalar(i)].get_function_gradients(
              ghosted_solution, gradients[i]);
          std::array<std::vector<double>, 2> loads;
          for (unsigned int q = 0; q < points.n_volume; ++q)
            volume_points[q] = fe_values.quadrature_point(q);
          for (unsigned int i = 0; i < 2; ++i)
            {
              data.load(i).value_list(volume_points, load);
              loads[i] = load;
              std::copy(load.begin(),
                        load.end(),
                        load_at_points.begin() +
                          (2 * cell->active_cell_index() + i) *
                            points.n_volume);
            }
          for (unsigned int s = 0; s < n_triangles; ++s)
            {
              const auto        &triangle = triangles[s];
              const unsigned int id =
                cell->active_cell_index() * n_triangles + s;
              SubTriangleData &kappa = sub_triangle_data[id];
              PatchTerms      &terms = patch_terms[id];

              // The fluxes (4.13) through the edges 0 and 1, by Gauss points
              // on the reference edges: n ds = cof(DF) n̂ dŝ. On the owned
              // cells, the hat function terms of the patch problems (see
              // equilibrate()): the fluxes of φ_v μ_i ∇u_ih through all
              // three edges of κ, and ∫ φ_v along a half-edge on ∂ω.
              const bool owned = cell->is_locally_owned();
              for (unsigned int e = 0; e < (owned ? 3 : 2); ++e)
                for (unsigned int k = 0; k < points.n_edge_points; ++k)
                  {
                    const unsigned int   q  = points.edge_point(s, e, k);
                    const Tensor<2, dim> DF = to_tensor(fe_values.jacobian(q));
                    const Tensor<1, dim> n_ds =
                      std::abs(determinant(DF)) * transpose(invert(DF)) *
                      triangle.normals[e] * points.quadrature.weight(q);
                    std::array<double, 2> flux_density;
                    for (unsigned int i = 0; i < 2; ++i)
                      {
                        flux_density[i] = data.mu[i] * gradients[i][q] * n_ds;
                        if (e < 2)
                          kappa.fluxes[i][e] -= flux_density[i];
                      }
                    if (owned)
                      for (unsigned int i = 0; i < 2; ++i)
                        terms.edge_flux[i][e][k] = flux_density[i];
                    if (owned && e == 2 && cell->at_boundary(triangle.face))
                      terms.boundary_length[k] = n_ds.norm();
                  }

              // The unknown of the half-edge a–m_e in the patch problems:
              // the half-edge itself, or on an edge with a hanging node the
              // small edge that holds it (with factor 1 from the coarse
              // side, 1/2 for each of the two half-edges on the fine side).
              // Its key is the midpoint of that segment, computed alike on
              // every cell and every process.
              if (owned)
                {
                  const unsigned int f          = triangle.face;
                  auto               face       = cell->face(f);
                  double             factor     = 1;
                  bool               small_edge = false;
                  if (!cell->at_boundary(f) && face->has_children())
                    {
                      const unsigned int vertex =
                        cell->vertex_index(triangle.vertex);
                      const auto first = face->child(0);
                      face = face->child(first->vertex_index(0) == vertex ||
                                             first->vertex_index(1) == vertex ?
                                           0 :
                                           1);
                      small_edge = true;
                    }
                  else if (!cell->at_boundary(f) &&
                           cell->neighbor_is_coarser(f))
                    {
                      factor     = 0.5;
                      small_edge = true;
                    }
                  Point<dim> first = face->vertex(0), second = face->vertex(1);
                  if (std::make_pair(second[0], second[1]) <
                      std::make_pair(first[0], first[1]))
                    std::swap(first, second);
                  const Point<dim> middle = (first + second) / 2;
                  const Point<dim> key =
                    small_edge ? middle :
                                 (cell->vertex(triangle.vertex) + middle) / 2;
                  terms.key         = {{key[0], key[1]}};
                  terms.factor      = (cross_product_2d(second - first) *
                                        (middle - cell->center()) >
                                      0 ?
                                         factor :
                                         -factor);
                  terms.on_boundary = cell->at_boundary(f);
                }

              // The Gram matrix of the mapped basis ψ_k, (μ_i ∇u_ih, ψ_k),
              // the area, ∫ f_i, and the hat function terms on κ.
              for (unsigned int q = 0; q < points.n_volume; ++q)
                if (dual_cell_quadrature.sub_triangle_of_point(q) == s)
                  {
                    const Tensor<2, dim> DF  = to_tensor(fe_values.jacobian(q));
                    const double         det = std::abs(determinant(DF));
                    std::array<Tensor<1, dim>, 3> psi;
                    for (unsigned int k = 0; k < 3; ++k)
                      psi[k] = DF * reference_basis[q][k] / det;
                    const double JxW = fe_values.JxW(q);
                    kappa.area += JxW;
                    for (unsigned int k = 0; k < 3; ++k)
                      {
                        for (unsigned int l = 0; l < 3; ++l)
                          kappa.gram[k][l] += psi[k] * psi[l] * JxW;
                        for (unsigned int i = 0; i < 2; ++i)
                          kappa.discrete_flux[i][k] +=
                            data.mu[i] * gradients[i][q] * psi[k] * JxW;
                      }
                    for (unsigned int i = 0; i < 2; ++i)
                      kappa.load[i] += loads[i][q] * JxW;
                    for (unsigned int v = 0; v < (owned ? n_vertices : 0); ++v)
                      {
                        const unsigned int k =
                          fe.component_to_system_index(0, v);
                        const double phi = fe_values.shape_value(k, q);
                        terms.hat_mass[v] += phi * JxW;
                        for (unsigned int i = 0; i < 2; ++i)
                          {
                            terms.hat_residual[i][v] +=
                              (loads[i][q] * phi -
                               data.mu[i] * gradients[i][q] *
                                 fe_values.shape_grad(k, q)) *
                              JxW;
                          }
                      }
                  }

              // The half-edge of κ: its unknown s, and the contribution of κ
              // to the minimization, (−μ_i ∇u_ih − P_κ, ψ_κ) with ψ_κ = ψ_2.
              const unsigned int f    = triangle.face;
              const auto         face = cell->face(f);
              unsigned long long key;
              if (!cell->at_boundary(f) && cell->neighbor_is_coarser(f))
                key = 3ull * coarse_face_index(cell, f) + 2;
              else if (face->has_children())
                key = 3ull * face->index() + 2;
              else
                key = 3ull * face->index() +
                      (face->vertex_index(0) ==
                           cell->vertex_index(triangle.vertex) ?
                         0 :
                         1);
              Tensor<1, dim> normal =
                cross_product_2d(face->vertex(1) - face->vertex(0));
              normal /= normal.norm();
              if (normal * (face->center() - cell->center()) < 0)
                normal *= -1;
              const auto [entry, is_new] =
                free_flux_index.emplace(key, free_fluxes.size());
              if (is_new)
                free_fluxes.push_back({normal, {}, 0});
              FreeFlux<dim> &free = free_fluxes[entry->second];
              const double   factor =
                (normal * free.normal > 0 ? 1. : -1.) * face->measure() / 2;
              free_flux_of[id] = {entry->second, factor};
              free.denominator += factor * factor * kappa.gram[2][2];
              for (unsigned int i = 0; i < 2; ++i)
                free.numerator[i] +=
                  factor * (-kappa.discrete_flux[i][2] -
                            kappa.fluxes[i][0] * kappa.gram[0][2] -
                            kappa.fluxes[i][1] * kappa.gram[1][2]);
            }
        }

    // The minimizers: the fluxes through the half-edges.
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        for (unsigned int s = 0; s < n_triangles; ++s)
          {
            const unsigned int id = cell->active_cell_index() * n_triangles + s;
            const auto [index, factor] = free_flux_of[id];
            for (unsigned int i = 0; i < 2; ++i)
              sub_triangle_data[id].fluxes[i][2] =
                factor * free_fluxes[index].numerator[i] /
                free_fluxes[index].denominator;
          }

    equilibrate(patch_terms,
                hanging_node_constraints,
                locally_owned_dofs,
                mpi_communicator);

    // The identities: per cell and vertex v the measure of K ∩ D_v, the
    // integral of div t_ih over it, f_ih meas(K ∩ D_v) and f_ih ∫_K φ_v,
    // condensed like d_a with the hanging node constraints.
    VectorType         measure(locally_owned_dofs, mpi_communicator);
    VectorType         divergence(locally_owned_dofs, mpi_communicator);
    VectorType         load_on_pieces(locally_owned_dofs, mpi_communicator);
    VectorType         load_on_hats(locally_owned_dofs, mpi_communicator);
    const unsigned int dofs_per_cell = fe.n_dofs_per_cell();
    Vector<double>     local_measure(dofs_per_cell),
      local_divergence(dofs_per_cell), local_load_on_pieces(dofs_per_cell),
      local_load_on_hats(dofs_per_cell);
    std::vector<types::global_dof_index> dof_indices(dofs_per_cell);
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          cell->get_dof_indices(dof_indices);
          const SubTriangleData *kappa =
            &sub_triangle_data[cell->active_cell_index() * n_triangles];
          // f_ih = ∫_K f_i / |K| (4.14).
          std::array<double, 2> load_mean{};
          double                area = 0;
          for (unsigned int s = 0; s < n_triangles; ++s)
            {
              area += kappa[s].area;
              for (unsigned int i = 0; i < 2; ++i)
                load_mean[i] += kappa[s].load[i];
            }
          local_measure    = 0;
          local_divergence = 0;
          for (unsigned int s = 0; s < n_triangles; ++s)
            for (unsigned int i = 0; i < 2; ++i)
              {
                const auto k =
                  fe.component_to_system_index(i, triangles[s].vertex);
                local_measure(k) += kappa[s].area;
                local_divergence(k) += kappa[s].fluxes[i][0] +
                                       kappa[s].fluxes[i][1] +
                                       kappa[s].fluxes[i][2];
              }
          for (const unsigned int v : cell->vertex_indices())
            for (unsigned int i = 0; i < 2; ++i)
              {
                const auto k = fe.component_to_system_index(i, v);
                local_load_on_pieces(k) =
                  load_mean[i] / area * local_measure(k);
                // f_ih ∫_K φ_v, with ∫_K φ_v from the patch terms.
                double hat_integral = 0;
                for (unsigned int s = 0; s < n_triangles; ++s)
                  hat_integral +=
                    patch_terms[cell->active_cell_index() * n_triangles + s]
                      .hat_mass[v];
                local_load_on_hats(k) = load_mean[i] / area * hat_integral;
              }
          hanging_node_constraints.distribute_local_to_global(local_measure,
                                                              dof_indices,
                                                              measure);
          hanging_node_constraints.distribute_local_to_global(local_divergence,
                                                              dof_indices,
                                                              divergence);
          hanging_node_constraints.distribute_local_to_global(
            local_load_on_pieces, dof_indices, load_on_pieces);
          hanging_node_constraints.distribute_local_to_global(
            local_load_on_hats, dof_indices, load_on_hats);
        }
    for (auto *vector : {&measure, &divergence, &load_on_pieces, &load_on_hats})
      vector->compress(VectorOperation::add);

    defects              = Identities();
    const auto &vertices = action.vertices();
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const auto &a = vertices[k];
        defects.measure_defect =
          std::max(defects.measure_defect,
                   std::abs(measure[a.dof[0]] - a.dual_cell_measure) /
                     a.dual_cell_measure);
        for (unsigned int i = 0; i < 2; ++i)
          {
            const auto   dof  = a.dof[i];
            const double sign = (i == 0 ? 1. : -1.);
            defects.conservation_defect =
              std::max(defects.conservation_defect,
                       std::abs(divergence[dof] - action.stiffness_term(i, k)));
            // ∫ (f_i − f_ih) φ_a with the assembly's ∫ f_i φ_a.
            const double oscillation =
              action.load_term(i, k) - load_on_hats[dof];
            defects.balance_defect =
              std::max(defects.balance_defect,
                       std::abs(sign * action.lambda_from_membrane(i, k) *
                                  measure[a.dof[0]] -
                                (divergence[dof] - load_on_pieces[dof] -
                                 oscillation)));
          }
      }
    const double force_scale =
      std::max(action.force_scale(), std::numeric_limits<double>::min());
    defects.measure_defect =
      Utilities::MPI::max(defects.measure_defect, mpi_communicator);
    defects.conservation_defect =
      Utilities::MPI::max(defects.conservation_defect, mpi_communicator) /
      force_scale;
    defects.balance_defect =
      Utilities::MPI::max(defects.balance_defect, mpi_communicator) /
      force_scale;
  }



  template <int dim>
  const typename FluxReconstruction<dim>::Identities &
  FluxReconstruction<dim>::identities() const
  {
    return defects;
  }



  namespace
  {
    /**
     * The record of one sub-triangle κ of a cell K in the support of a
     * condensed hat function φ_a: what the patch problem of a needs of κ,
     * with φ_a's coefficients on K applied. The process that owns K writes
     * it; the process that owns a solves the patch problem (in general
     * another process: the support of a condensed φ_a can reach beyond the
     * ghost layer of a process that owns one of its cells). Records are
     * arrays of doubles, so that they travel in MPI messages as they are.
     */
    namespace PatchRecord
    {
      enum Entry : unsigned int
      {
        /** The key of the unknown flux through edge 2 (a point, x and y). */
        key_x,
        key_y,
        /** Outward flux of κ through edge 2 = factor × the unknown. */
        factor,
        /** 1 if edge 2 lies on ∂ω, 0 otherwise. */
        on_boundary,
        /** (ψ_k, ψ_l)_κ for k ≤ l: six entries. */
        gram,
        area = gram + 6,
        /** ∫_κ (f_i φ_a − μ_i ∇u_ih·∇φ_a), i = 1, 2. */
        residual,
        /** ∫_κ φ_a. */
        mass = residual + 2,
        /** ∫_e −μ_i φ_a ∇u_ih·n through edge e of κ: 3 per i. */
        edge_flux,
        /** ∫ φ_a along edge 2 if it lies on ∂ω. */
        boundary_mass = edge_flux + 6,
        /** The number of entries. */
        size
      };
    } // namespace PatchRecord



    /** A half-edge of a patch problem, by its key, for sorting. */
    struct PatchKey
    {
      double       x, y;
      unsigned int cell, s;
    };
  } // namespace



  /**
   * The work arrays of solve_patch_problem(), kept from one patch to the
   * next.
   */
  template <int dim>
  struct FluxReconstruction<dim>::PatchScratch
  {
    std::vector<PatchKey>                             keys;
    std::vector<std::pair<unsigned int, double>>      unknown_of;
    std::vector<std::array<double, 2>>                source, known, mean;
    std::vector<double>                               weight;
    std::vector<std::array<std::array<double, 3>, 2>> target;
    FullMatrix<double>                                matrix;
    std::array<Vector<double>, 2>                     rhs;
    SaddlePointScratch                                saddle_point;
  };



  template <int dim>
  void
  FluxReconstruction<dim>::write_patch_record(
    const CellIterator            &cell,
    const std::array<double, 4>   &coefficients,
    const std::vector<PatchTerms> &patch_terms,
    double                        *record) const
  {
    using namespace PatchRecord;
    const unsigned int n_triangles =
      dual_cell_quadrature.sub_triangles().size();
    for (unsigned int j = 0; j < ring.size(); ++j, record += size)
      {
        const unsigned int id =
          cell->active_cell_index() * n_triangles + ring[j];
        const SubTriangleData &kappa = sub_triangle_data[id];
        const PatchTerms      &terms = patch_terms[id];

        record[key_x]               = terms.key[0];
        record[key_y]               = terms.key[1];
        record[PatchRecord::factor] = terms.factor;
        record[on_boundary]         = terms.on_boundary ? 1 : 0;
        for (unsigned int k = 0, n = 0; k < 3; ++k)
          for (unsigned int l = k; l < 3; ++l, ++n)
            record[gram + n] = kappa.gram[k][l];
        record[area] = kappa.area;

        record[residual]      = 0;
        record[residual + 1]  = 0;
        record[mass]          = 0;
        record[boundary_mass] = 0;
        for (unsigned int n = 0; n < 6; ++n)
          record[edge_flux + n] = 0;
        for (unsigned int v = 0; v < GeometryInfo<dim>::vertices_per_cell; ++v)
          if (coefficients[v] != 0)
            {
              record[mass] += coefficients[v] * terms.hat_mass[v];
              for (unsigned int i = 0; i < 2; ++i)
                record[residual + i] +=
                  coefficients[v] * terms.hat_residual[i][v];
            }
        // φ_a at the Gauss points of the edges of κ.
        for (unsigned int e = 0; e < 3; ++e)
          for (unsigned int k = 0; k < 2; ++k)
            {
              double phi = 0;
              for (unsigned int v = 0; v < GeometryInfo<dim>::vertices_per_cell;
                   ++v)
                phi +=
                  coefficients[v] *
                  edge_shape_values[((ring[j] * 3 + e) * 2 + k) *
                                      GeometryInfo<dim>::vertices_per_cell +
                                    v];
              for (unsigned int i = 0; i < 2; ++i)
                record[edge_flux + 3 * i + e] -= phi * terms.edge_flux[i][e][k];
              if (e == 2)
                record[boundary_mass] += phi * terms.boundary_length[k];
            }
      }
  }



  template <int dim>
  void
  FluxReconstruction<dim>::equilibrate(
    const std::vector<PatchTerms>   &patch_terms,
    const AffineConstraints<double> &hanging_node_constraints,
    const IndexSet                  &locally_owned_dofs,
    const MPI_Comm                   mpi_communicator)
  {
    const unsigned int n_ring      = ring.size();
    const unsigned int record_size = n_ring * PatchRecord::size;
    const unsigned int result_size = n_ring * 6;

    // The owned cells of the support of each condensed φ_a, with the
    // coefficients of φ_a in the hat functions of the cell's vertices (1
    // at a, the constraint weight at a hanging vertex with parent a): in
    // local_patches if this process owns a, else to be sent to a's owner.
    using Coefficients =
      std::array<double, GeometryInfo<dim>::vertices_per_cell>;
    std::map<types::global_dof_index,
             std::vector<std::pair<CellIterator, Coefficients>>>
      local_patches;
    std::vector<std::tuple<CellIterator, types::global_dof_index, Coefficients>>
                                         remote;
    std::vector<types::global_dof_index> remote_vertices;
    for (const auto &cell : dof_handler->active_cell_iterators())
      if (cell->is_locally_owned())
        {
          std::map<types::global_dof_index, Coefficients> of_cell;
          for (const unsigned int v : cell->vertex_indices())
            {
              const auto dof = cell->vertex_dof_index(v, 0);
              if (const auto *entries =
                    hanging_node_constraints.get_constraint_entries(dof))
                for (const auto &[parent, weight] : *entries)
                  of_cell[parent][v] += weight;
              else
                of_cell[dof][v] += 1;
            }
          for (const auto &[a, coefficients] : of_cell)
            if (locally_owned_dofs.is_element(a))
              local_patches[a].emplace_back(cell, coefficients);
            else
              {
                remote.emplace_back(cell, a, coefficients);
                remote_vertices.push_back(a);
              }
        }
    std::sort(remote_vertices.begin(), remote_vertices.end());
    IndexSet remote_set(locally_owned_dofs.size());
    remote_set.add_indices(remote_vertices.begin(),
                           std::unique(remote_vertices.begin(),
                                       remote_vertices.end()));
    const std::vector<unsigned int> owners =
      Utilities::MPI::compute_index_owner(locally_owned_dofs,
                                          remote_set,
                                          mpi_communicator);
    std::map<unsigned int, std::vector<double>>       records;
    std::map<unsigned int, std::vector<CellIterator>> sent;
    for (const auto &[cell, a, coefficients] : remote)
      {
        const unsigned int   owner  = owners[remote_set.index_within_set(a)];
        std::vector<double> &buffer = records[owner];
        buffer.push_back(a);
        buffer.resize(buffer.size() + record_size);
        write_patch_record(cell,
                           coefficients,
                           patch_terms,
                           buffer.data() + buffer.size() - record_size);
        sent[owner].push_back(cell);
      }

    // The records of the owned vertices from other processes, and the
    // buffers for the answers: σ_ih^a on their sub-triangles.
    const std::map<unsigned int, std::vector<double>> received =
      Utilities::MPI::some_to_some(mpi_communicator, records);
    std::map<types::global_dof_index,
             std::vector<std::pair<unsigned int, unsigned int>>>
                                                remote_members;
    std::map<unsigned int, std::vector<double>> replies;
    for (const auto &[process, buffer] : received)
      {
        const unsigned int n_records = buffer.size() / (1 + record_size);
        replies[process].assign(n_records * result_size, 0.);
        for (unsigned int r = 0; r < n_records; ++r)
          remote_members[static_cast<types::global_dof_index>(
                           buffer[r * (1 + record_size)])]
            .emplace_back(process, r);
      }

    // The patch problems, σ_ih = Σ_a σ_ih^a on the owned cells.
    for (auto &kappa : sub_triangle_data)
      kappa.equilibrated = {};
    PatchScratch                scratch;
    std::vector<double>         local_records, local_results;
    std::vector<const double *> patch;
    std::vector<double *>       result;
    for (const auto &[a, cells] : local_patches)
      {
        local_records.resize(cells.size() * record_size);
        local_results.assign(cells.size() * result_size, 0.);
        patch.clear();
        result.clear();
        for (unsigned int c = 0; c < cells.size(); ++c)
          {
            write_patch_record(cells[c].first,
                               cells[c].second,
                               patch_terms,
                               local_records.data() + c * record_size);
            patch.push_back(local_records.data() + c * record_size);
            result.push_back(local_results.data() + c * result_size);
          }
        if (const auto members = remote_members.find(a);
            members != remote_members.end())
          for (const auto &[process, r] : members->second)
            {
              patch.push_back(received.at(process).data() +
                              r * (1 + record_size) + 1);
              result.push_back(replies[process].data() + r * result_size);
            }
        solve_patch_problem(a, patch, result, scratch);
        for (unsigned int c = 0; c < cells.size(); ++c)
          add_patch_result(cells[c].first,
                           local_results.data() + c * result_size);
      }
    for (const auto &[process, buffer] :
         Utilities::MPI::some_to_some(mpi_communicator, replies))
      for (unsigned int r = 0; r < sent[process].size(); ++r)
        add_patch_result(sent[process][r], buffer.data() + r * result_size);
    relax_rotations();
  }



  /**
   * Curls of the hat functions of the vertices p of the sub-mesh S_h are
   * RT0(S_h) fields without divergence: adding one to σ_ih changes the
   * outward flux of each sub-triangle κ around p by +c through the edge
   * that enters p and by −c through the one that leaves it (counter-
   * clockwise), and changes neither div σ_ih nor its normal continuity.
   * The c that minimizes ‖μ_i^{-1/2} σ_ih + μ_i^{1/2} ∇u_ih‖ on the
   * sub-triangles around p is
   *
   *   c = −Σ_κ u_κ·(G_κ F_κ + g_κ) / Σ_κ u_κ·G_κ u_κ,
   *
   * with F_κ the fluxes of σ_ih, G_κ the Gram matrix and g_κ the
   * products (μ_i ∇u_ih, ψ_k)_κ. Two vertices of S_h of the same kind
   * (regular vertex a, edge midpoint m_e, cell centre b_K, hanging vertex)
   * never lie in the same sub-triangle, so each sweep updates all vertices
   * of one kind at once, in any order, and the flux estimator can only
   * decrease. Vertices on ∂ω are left out (the normal flux there stays
   * the patch problems'). On several processes, σ_ih on the ghost cells
   * is brought from their owners before each sweep over one kind, so that
   * a rotation across the boundary of the owned cells is the same on every
   * process that owns one of its cells, as on one process.
   */
  template <int dim>
  void
  FluxReconstruction<dim>::relax_rotations()
  {
    const auto        &triangles   = dual_cell_quadrature.sub_triangles();
    const unsigned int n_triangles = triangles.size();

    // The corners of each reference sub-triangle, counterclockwise.
    std::vector<std::array<unsigned int, 3>> counterclockwise(n_triangles);
    for (unsigned int s = 0; s < n_triangles; ++s)
      {
        const auto          &p  = triangles[s].corners;
        const Tensor<1, dim> e1 = p[1] - p[0], e2 = p[2] - p[0];
        counterclockwise[s] = (e1[0] * e2[1] - e1[1] * e2[0] > 0 ?
                                 std::array<unsigned int, 3>{{0, 1, 2}} :
                                 std::array<unsigned int, 3>{{0, 2, 1}});
      }

    // The rotations, by the vertex p of S_h: the vertices of the mesh
    // first, then the faces (their midpoints m_e), then the cells (b_K).
    // Per sub-triangle around p its index in sub_triangle_data and the
    // change u_κ of its fluxes. At an edge with a hanging vertex c the
    // stream function is continuous on S_h: the coarse side's m_e is c, and
    // on the fine side the midpoint of each small edge takes half of the
    // hat functions of its two ends.
    const auto        &triangulation = dof_handler->get_triangulation();
    const unsigned int n_vertices    = triangulation.n_vertices();
    const unsigned int first_cell    = n_vertices + triangulation.n_raw_faces();
    const unsigned int n_nodes = first_cell + triangulation.n_active_cells();
    struct Entry
    {
      unsigned int          node, kappa;
      std::array<double, 3> u;
    };
    std::vector<Entry> entries;
    entries.reserve(triangulation.n_active_cells() * n_triangles * 3);
    std::vector<char> owned(n_nodes, 0), on_boundary(n_nodes, 0);
    std::vector<char> hanging(n_vertices, 0);
    for (const auto &cell : dof_handler->active_cell_iterators())
      if (!cell->is_artificial())
        for (const unsigned int f : cell->face_indices())
          if (!cell->at_boundary(f) && cell->face(f)->has_children())
            hanging[cell->face(f)->child(0)->vertex_index(1)] = 1;
    for (const auto &cell : dof_handler->active_cell_iterators())
      if (!cell->is_artificial())
        for (unsigned int s = 0; s < n_triangles; ++s)
          {
            const unsigned int f        = triangles[s].face;
            const auto         face     = cell->face(f);
            const bool         boundary = cell->at_boundary(f);
            // The vertices of S_h at the corners a, m_e, b_K, with weights.
            std::array<std::array<std::pair<unsigned int, double>, 2>, 3> nodes;
            std::array<unsigned int, 3> n_nodes_of{{1, 1, 1}};
            nodes[0][0] = {cell->vertex_index(triangles[s].vertex), 1.};
            if (!boundary && face->has_children())
              nodes[1][0] = {face->child(0)->vertex_index(1), 1.};
            else if (!boundary && cell->neighbor_is_coarser(f))
              {
                nodes[1] = {
                  {{face->vertex_index(0), 0.5}, {face->vertex_index(1), 0.5}}};
                n_nodes_of[1] = 2;
              }
            else
              nodes[1][0] = {n_vertices + face->index(), 1.};
            nodes[2][0] = {first_cell + cell->active_cell_index(), 1.};

            const unsigned int id = cell->active_cell_index() * n_triangles + s;
            const std::size_t  first_entry = entries.size();
            const auto        &order       = counterclockwise[s];
            for (unsigned int k = 0; k < 3; ++k)
              {
                // Corner order[k] is p, order[k−1] before and order[k+1]
                // after it: the edge entering p is opposite order[k+1].
                const unsigned int before = order[(k + 2) % 3],
                                   corner = order[k],
                                   after  = order[(k + 1) % 3];
                for (unsigned int n = 0; n < n_nodes_of[corner]; ++n)
                  {
                    const auto [node, weight] = nodes[corner][n];
                    owned[node] |= cell->is_locally_owned();
                    // p on ∂ω: a vertex of a boundary edge, or its m_e.
                    on_boundary[node] |= boundary && corner != 2;
                    auto entry = std::find_if(entries.begin() + first_entry,
                                              entries.end(),
                                              [node = node](const Entry &e) {
                                                return e.node == node;
                                              });
                    if (entry == entries.end())
                      entry =
                        entries.insert(entries.end(), Entry{node, id, {}});
                    entry->u[after] += weight;
                    entry->u[before] -= weight;
                  }
              }
          }
    // The entries sorted by vertex (counting sort), and the vertices of
    // each kind (0: regular vertex, 1: m_e, 2: b_K, 3: hanging vertex):
    // two of one kind share no sub-triangle.
    std::vector<unsigned int> start(n_nodes + 1, 0);
    for (const Entry &entry : entries)
      ++start[entry.node + 1];
    for (unsigned int node = 0; node < n_nodes; ++node)
      start[node + 1] += start[node];
    std::vector<Entry> sorted(entries.size());
    {
      std::vector<unsigned int> next(start.begin(), start.end() - 1);
      for (const Entry &entry : entries)
        sorted[next[entry.node]++] = entry;
    }
    std::array<std::vector<unsigned int>, 4> of_kind;
    for (unsigned int node = 0; node < n_nodes; ++node)
      if (owned[node] && !on_boundary[node] && start[node + 1] > start[node])
        of_kind[node < n_vertices ? (hanging[node] ? 3 : 0) :
                node < first_cell ? 1 :
                                    2]
          .push_back(node);

    // σ_ih of the owned cells to the ghost cells of the other processes.
    using Fluxes        = std::array<std::array<double, 3>, 2>;
    const auto exchange = [&]() {
      if (dynamic_cast<const parallel::TriangulationBase<dim> *>(
            &dof_handler->get_triangulation()) == nullptr)
        return;
      GridTools::exchange_cell_data_to_ghosts<std::vector<Fluxes>,
                                              DoFHandler<dim>>(
        *dof_handler,
        [&](const CellIterator &cell) {
          std::vector<Fluxes> fluxes(n_triangles);
          for (unsigned int s = 0; s < n_triangles; ++s)
            fluxes[s] =
              sub_triangle_data[cell->active_cell_index() * n_triangles + s]
                .equilibrated;
          return std::optional<std::vector<Fluxes>>(fluxes);
        },
        [&](const CellIterator &cell, const std::vector<Fluxes> &fluxes) {
          for (unsigned int s = 0; s < n_triangles; ++s)
            sub_triangle_data[cell->active_cell_index() * n_triangles + s]
              .equilibrated = fluxes[s];
        });
    };

    for (unsigned int sweep = 0; sweep < rotation_sweeps; ++sweep)
      for (const unsigned int kind : {2u, 1u, 0u, 3u})
        {
          exchange();
          for (const unsigned int node : of_kind[kind])
            for (unsigned int i = 0; i < 2; ++i)
              {
                double numerator = 0, denominator = 0;
                for (unsigned int t = start[node]; t < start[node + 1]; ++t)
                  {
                    const SubTriangleData &kappa =
                      sub_triangle_data[sorted[t].kappa];
                    const auto &u = sorted[t].u;
                    for (unsigned int k = 0; k < 3; ++k)
                      {
                        double Gu = 0, GF = 0;
                        for (unsigned int l = 0; l < 3; ++l)
                          {
                            Gu += kappa.gram[k][l] * u[l];
                            GF += kappa.gram[k][l] * kappa.equilibrated[i][l];
                          }
                        numerator += u[k] * (GF + kappa.discrete_flux[i][k]);
                        denominator += u[k] * Gu;
                      }
                  }
                const double c = -numerator / denominator;
                for (unsigned int t = start[node]; t < start[node + 1]; ++t)
                  for (unsigned int k = 0; k < 3; ++k)
                    sub_triangle_data[sorted[t].kappa].equilibrated[i][k] +=
                      c * sorted[t].u[k];
              }
        }
  }



  template <int dim>
  void
  FluxReconstruction<dim>::add_patch_result(const CellIterator &cell,
                                            const double       *result)
  {
    const unsigned int n_triangles =
      dual_cell_quadrature.sub_triangles().size();
    for (unsigned int j = 0; j < ring.size(); ++j)
      for (unsigned int i = 0; i < 2; ++i)
        for (unsigned int e = 0; e < 3; ++e)
          sub_triangle_data[cell->active_cell_index() * n_triangles + ring[j]]
            .equilibrated[i][e] += result[6 * j + 3 * i + e];
  }



  template <int dim>
  void
  FluxReconstruction<dim>::solve_patch_problem(
    const types::global_dof_index      a,
    const std::vector<const double *> &patch,
    const std::vector<double *>       &result,
    PatchScratch                      &scratch) const
  {
    using namespace PatchRecord;
    const unsigned int          n_ring  = ring.size();
    const unsigned int          n_cells = patch.size();
    const unsigned int          n_sub   = n_cells * n_ring;
    const unsigned int          invalid = numbers::invalid_unsigned_int;
    const std::array<double, 2> sign{{1., -1.}};
    // Entry k of the record of sub-triangle ring[j] of cell c; s = c n_ring +
    // j.
    const auto entry = [&](const unsigned int s, const unsigned int k) {
      return patch[s / n_ring][(s % n_ring) * size + k];
    };
    const double lambda_a = action.lambda_h_at_vertex(a);

    // The unknown fluxes: through the half-edges (or small edges at a
    // hanging node) that two cells of the patch share, found by their
    // keys. unknown_of[s]: the unknown of the half-edge of sub-triangle s
    // and the factor that gives its outward flux, or none: on ∂ω the flux
    // is prescribed, on the rest of the boundary of the support of φ_a it
    // is zero.
    auto &keys = scratch.keys;
    keys.clear();
    for (unsigned int s = 0; s < n_sub; ++s)
      if (entry(s, on_boundary) == 0)
        keys.push_back({entry(s, key_x), entry(s, key_y), s / n_ring, s});
    std::sort(keys.begin(), keys.end(), [](const auto &p, const auto &q) {
      return std::tie(p.x, p.y, p.cell) < std::tie(q.x, q.y, q.cell);
    });
    auto &unknown_of = scratch.unknown_of;
    unknown_of.assign(n_sub, {invalid, 0.});
    unsigned int n_x = 0;
    for (unsigned int begin = 0, end; begin < keys.size(); begin = end)
      {
        for (end = begin + 1;
             end < keys.size() && keys[end].x == keys[begin].x &&
             keys[end].y == keys[begin].y;
             ++end)
          ;
        if (keys[end - 1].cell != keys[begin].cell)
          {
            for (unsigned int k = begin; k < end; ++k)
              unknown_of[keys[k].s] = {n_x, entry(keys[k].s, factor)};
            ++n_x;
          }
      }

    // The divergence of σ_ih^a on each sub-triangle, ∫_κ r_ia with
    // r_ia = (f_i + s_i λ_a) φ_a − μ_i ∇u_ih·∇φ_a, and the prescribed
    // fluxes β through ∂ω: those of −μ_i φ_a ∇u_ih, plus what ∫ r_ia
    // leaves over, spread in proportion to ∫ φ_a on each half-edge. Around
    // an interior vertex, ∫ r_ia = 0 is (4.5) for the condensed φ_a; what
    // quadrature and the linear solver leave of it is spread as a constant
    // instead.
    auto &source = scratch.source;
    auto &known  = scratch.known;
    source.assign(n_sub, {});
    known.assign(n_sub, {});
    std::array<double, 2> total{}, total_boundary_flux{};
    double                patch_area = 0, total_boundary_mass = 0;
    for (unsigned int s = 0; s < n_sub; ++s)
      {
        patch_area += entry(s, area);
        total_boundary_mass += entry(s, boundary_mass);
        for (unsigned int i = 0; i < 2; ++i)
          {
            source[s][i] =
              entry(s, residual + i) + sign[i] * lambda_a * entry(s, mass);
            total[i] += source[s][i];
            if (entry(s, on_boundary) != 0)
              {
                known[s][i] = entry(s, edge_flux + 3 * i + 2);
                total_boundary_flux[i] += known[s][i];
              }
          }
      }
    for (unsigned int s = 0; s < n_sub; ++s)
      for (unsigned int i = 0; i < 2; ++i)
        if (total_boundary_mass > 0)
          known[s][i] += (total[i] - total_boundary_flux[i]) *
                         entry(s, boundary_mass) / total_boundary_mass;
        else
          source[s][i] -= total[i] * entry(s, area) / patch_area;

    // The target: on each sub-triangle the RT0 field with the fluxes of
    // −μ_i φ_a ∇u_ih through its edges; through a half-edge shared by two
    // cells, the mean of both sides. The targets are then conforming, and
    // where u_ih is linear they satisfy the constraints: σ_ih^a is its
    // target, and σ_ih = −μ_i ∇u_ih.
    auto &target = scratch.target;
    target.resize(n_sub);
    {
      auto &mean   = scratch.mean;
      auto &weight = scratch.weight;
      mean.assign(n_x, {});
      weight.assign(n_x, 0.);
      for (unsigned int s = 0; s < n_sub; ++s)
        {
          for (unsigned int i = 0; i < 2; ++i)
            for (unsigned int e = 0; e < 3; ++e)
              target[s][i][e] = entry(s, edge_flux + 3 * i + e);
          if (const auto [x, f] = unknown_of[s]; x != invalid)
            {
              weight[x] += std::abs(f);
              for (unsigned int i = 0; i < 2; ++i)
                mean[x][i] += (f > 0 ? 1. : -1.) * target[s][i][2];
            }
        }
      for (unsigned int s = 0; s < n_sub; ++s)
        for (unsigned int i = 0; i < 2; ++i)
          {
            const auto [x, f] = unknown_of[s];
            target[s][i][2] =
              (x != invalid ? f * mean[x][i] / weight[x] : known[s][i]);
          }
    }

    // On cell c, with the outward fluxes b_j through the half-edges of its
    // ring and its circulation z_c, the flux from ring[j] into ring[j+1]
    // is z_c + Σ_{k≤j} (r_k − b_k), so that div = r_j on every κ; the
    // ring closes iff Σ_j b_j = Σ_j r_j, the cell's constraint (one of
    // them is redundant: together they say ∫ r_ia = flux through ∂ω).
    // Edge 2 of ring[j] is its half-edge, through edge j % 2 (out) it
    // meets ring[j+1], through the other (in) ring[j−1]. With
    // w_j = Σ_{k<j} b_k − z_c, its fluxes are
    //
    //   F_j = w_j D + b_j E + q_j,  D = e_in − e_out,  E = e_2 − e_out,
    //
    // q_j = (Σ_{k≤j} r_k) e_out − (Σ_{k<j} r_k) e_in, and the patch
    // problem minimizes Σ_κ (F_κ − target_κ)ᵀ G_κ (F_κ − target_κ) under
    // the constraints. On each cell the quadratic form in (b_0, …, z_c)
    // has entries from suffix sums of DᵀG_jD, so it costs O(n_ring²).
    // An unknown b_j is factor × a flux unknown of the patch; a prescribed
    // one goes to the right-hand side.
    const unsigned int n_constraints = n_cells - 1;
    const unsigned int m             = n_x + n_cells + n_constraints;
    const unsigned int n_local       = n_ring + 1; // b_0, …, b_{n-1}, z
    auto              &matrix        = scratch.matrix;
    auto              &rhs           = scratch.rhs;
    matrix.reinit(m, m);
    for (auto &r : rhs)
      r.reinit(m);
    // Per cell, on the stack (a ring has at most 8 sub-triangles).
    constexpr unsigned int max_local = 9;
    AssertIndexRange(n_local, max_local + 1);
    double                                       M[max_local][max_local];
    std::array<std::array<double, 2>, max_local> l, rho, sigma;
    std::array<double, max_local>                alpha, gamma, epsilon, suffix;
    std::array<std::pair<unsigned int, double>, max_local> global;
    for (unsigned int c = 0; c < n_cells; ++c)
      {
        std::array<double, 2> partial{}, known_total{};
        for (unsigned int j = 0; j < n_ring; ++j)
          {
            const unsigned int s   = c * n_ring + j;
            const unsigned int out = j % 2, in = 1 - out;
            const double      *g       = patch[c] + j * size + gram;
            const double       G[3][3] = {{g[0], g[1], g[2]},
                                          {g[1], g[3], g[4]},
                                          {g[2], g[4], g[5]}};
            alpha[j]   = G[in][in] - 2 * G[in][out] + G[out][out];
            gamma[j]   = G[in][2] - G[in][out] - G[out][2] + G[out][out];
            epsilon[j] = G[2][2] - 2 * G[2][out] + G[out][out];
            for (unsigned int i = 0; i < 2; ++i)
              {
                std::array<double, 3> r{};
                r[out] = partial[i] + source[s][i];
                r[in]  = -partial[i];
                for (unsigned int e = 0; e < 3; ++e)
                  r[e] -= target[s][i][e];
                std::array<double, 3> Gr{};
                for (unsigned int e = 0; e < 3; ++e)
                  for (unsigned int f = 0; f < 3; ++f)
                    Gr[e] += G[e][f] * r[f];
                rho[j][i]   = Gr[in] - Gr[out];
                sigma[j][i] = Gr[2] - Gr[out];
                partial[i] += source[s][i];
                known_total[i] += known[s][i];
              }
          }
        suffix[n_ring] = 0;
        for (unsigned int j = n_ring; j-- > 0;)
          suffix[j] = suffix[j + 1] + alpha[j];
        const unsigned int z = n_ring;
        for (unsigned int k = 0; k < n_ring; ++k)
          {
            for (unsigned int j = 0; j < n_ring; ++j)
              M[k][j] = suffix[std::max(k, j) + 1];
            M[k][k] += epsilon[k];
            M[k][z] = M[z][k] = -suffix[k + 1] - gamma[k];
            for (unsigned int j = 0; j < k; ++j)
              {
                M[j][k] += gamma[k];
                M[k][j] += gamma[k];
              }
          }
        M[z][z] = suffix[0];
        std::array<double, 2> rho_suffix{};
        for (unsigned int k = n_ring; k-- > 0;)
          for (unsigned int i = 0; i < 2; ++i)
            {
              l[k][i] = rho_suffix[i] + sigma[k][i];
              rho_suffix[i] += rho[k][i];
            }
        for (unsigned int i = 0; i < 2; ++i)
          l[z][i] = -rho_suffix[i];

        for (unsigned int k = 0; k < n_ring; ++k)
          global[k] = unknown_of[c * n_ring + k];
        global[z] = {n_x + c, 1.};
        for (unsigned int u = 0; u < n_local; ++u)
          if (global[u].first != invalid)
            {
              std::array<double, 2> linear = l[u];
              for (unsigned int v = 0; v < n_local; ++v)
                if (global[v].first != invalid)
                  matrix(global[u].first, global[v].first) +=
                    global[u].second * M[u][v] * global[v].second;
                else
                  for (unsigned int i = 0; i < 2; ++i)
                    linear[i] += M[u][v] * known[c * n_ring + v][i];
              for (unsigned int i = 0; i < 2; ++i)
                rhs[i](global[u].first) -= global[u].second * linear[i];
            }
        if (c < n_constraints)
          {
            const unsigned int row = n_x + n_cells + c;
            for (unsigned int j = 0; j < n_ring; ++j)
              if (const auto [x, f] = global[j]; x != invalid)
                {
                  matrix(row, x) += f;
                  matrix(x, row) += f;
                }
            for (unsigned int i = 0; i < 2; ++i)
              rhs[i](row) = partial[i] - known_total[i];
          }
      }

    // The matrix of the minimization is positive definite, so that the
    // Cholesky factors of it and of the Schur complement of the
    // constraints solve the system; should round-off spoil that on a
    // degenerate patch, LU with pivoting does.
    if (!solve_saddle_point(matrix, n_x + n_cells, rhs, scratch.saddle_point))
      {
        LAPACKFullMatrix<double> lu(m, m);
        lu = matrix;
        lu.compute_lu_factorization();
        for (unsigned int i = 0; i < 2; ++i)
          lu.solve(rhs[i]);
      }

    // σ_ih^a on the sub-triangles of the patch.
    for (unsigned int c = 0; c < n_cells; ++c)
      for (unsigned int i = 0; i < 2; ++i)
        {
          double partial = 0, w = -rhs[i](n_x + c);
          for (unsigned int j = 0; j < n_ring; ++j)
            {
              const unsigned int s   = c * n_ring + j;
              const unsigned int out = j % 2, in = 1 - out;
              const auto [x, f] = unknown_of[s];
              const double b    = (x != invalid ? f * rhs[i](x) : known[s][i]);
              double      *F    = result[c] + 6 * j + 3 * i;
              F[out]            = -w - b + partial + source[s][i];
              F[in]             = w - partial;
              F[2]              = b;
              partial += source[s][i];
              w += b;
            }
        }
  }



  template <int dim>
  void
  FluxReconstruction<dim>::flux_values(const CellIterator          &cell,
                                       const unsigned int           i,
                                       const FEValues<dim>         &fe_values,
                                       std::vector<Tensor<1, dim>> &flux,
                                       std::vector<double> &divergence) const
  {
    const auto        &quadrature  = dual_cell_quadrature.quadrature();
    const auto        &triangles   = dual_cell_quadrature.sub_triangles();
    const unsigned int n_triangles = triangles.size();
    flux.resize(quadrature.size());
    divergence.resize(quadrature.size());
    for (unsigned int q = 0; q < quadrature.size(); ++q)
      {
        const unsigned int s = dual_cell_quadrature.sub_triangle_of_point(q);
        const auto        &f =
          sub_triangle_data[cell->active_cell_index() * n_triangles + s]
            .equilibrated[i];
        const Tensor<2, dim> DF  = to_tensor(fe_values.jacobian(q));
        const double         det = std::abs(determinant(DF));
        flux[q]       = DF * reference_flux(s, f, quadrature.point(q)) / det;
        divergence[q] = (f[0] + f[1] + f[2]) / (triangles[s].area * det);
      }
  }



  template <int dim>
  ArrayView<const double>
  FluxReconstruction<dim>::load_values(const CellIterator &cell,
                                       const unsigned int  i) const
  {
    const unsigned int n_points = dual_cell_quadrature.quadrature().size();
    return make_array_view(load_at_points.data() +
                             (2 * cell->active_cell_index() + i) * n_points,
                           load_at_points.data() +
                             (2 * cell->active_cell_index() + i + 1) *
                               n_points);
  }



  template <int dim>
  std::vector<std::string>
  FluxReconstruction<dim>::data_names()
  {
    return {"dual_vertex",
            "lambda_h",
            "t1_x",
            "t1_y",
            "t2_x",
            "t2_y",
            "div_t1",
            "div_t2"};
  }



  template <int dim>
  std::vector<DataOutBase::Patch<dim, dim>>
  FluxReconstruction<dim>::patches() const
  {
    const auto               &triangles = dual_cell_quadrature.sub_triangles();
    ReconstructionPoints<dim> points(dual_cell_quadrature, true);
    FEValues<dim>             fe_values(*discretization.mapping,
                            *discretization.fe,
                            points.quadrature,
                            update_quadrature_points | update_jacobians);
    std::vector<DataOutBase::Patch<dim, dim>> patches;
    for (const auto &cell : dof_handler->active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          for (unsigned int s = 0; s < triangles.size(); ++s)
            {
              DataOutBase::Patch<dim, dim> patch;
              patch.reference_cell = ReferenceCells::Triangle;
              patch.data.reinit(data_names().size(), 3);
              const auto &f =
                sub_triangle_data[cell->active_cell_index() * triangles.size() +
                                  s]
                  .fluxes;
              for (unsigned int j = 0; j < 3; ++j)
                {
                  const unsigned int q     = points.corner_point(s, j);
                  patch.vertices[j]        = fe_values.quadrature_point(q);
                  const Tensor<2, dim> DF  = to_tensor(fe_values.jacobian(q));
                  const double         det = std::abs(determinant(DF));
                  patch.data(0, j) = cell->vertex_index(triangles[s].vertex);
                  patch.data(1, j) =
                    action.lambda_h_value(cell, triangles[s].vertex);
                  for (unsigned int i = 0; i < 2; ++i)
                    {
                      const Tensor<1, dim> t =
                        DF * reference_flux(s, f[i], triangles[s].corners[j]) /
                        det;
                      patch.data(2 + 2 * i, j) = t[0];
                      patch.data(3 + 2 * i, j) = t[1];
                      patch.data(6 + i, j)     = (f[i][0] + f[i][1] + f[i][2]) /
                                             (triangles[s].area * det);
                    }
                }
              patches.push_back(patch);
            }
        }
    return patches;
  }



  template class FluxReconstruction<2>;
} // namespace membranes
