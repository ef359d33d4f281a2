#include <algorithm>
#include <cmath>
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/fe/fe_values.h>
#include <membranes/cell_loop.h>
#include <membranes/flux_reconstruction.h>
#include <type_traits>

// The fluxes t_ih of (4.13) and the identities (4.17), (4.18) and Lemma 17,
// the evaluation of σ_ih, and the dual mesh as output; the patch
// equilibration of σ_ih is in flux_equilibration.cc.

namespace membranes
{
  namespace
  {
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
     * The coarse edge of which face @p f of @p cell is a half, when the
     * neighbour there is coarser. (Found among the neighbour's faces:
     * CellAccessor::neighbor_of_coarser_neighbor() fails on triangle meshes
     * in deal.II 9.4.)
     */
    template <typename CellIterator>
    auto
    coarse_face(const CellIterator &cell, const unsigned int f)
    {
      const auto fine_face = cell->face(f);
      for (const auto &face : cell->neighbor(f)->face_iterators())
        if (face->has_children())
          for (unsigned int c = 0; c < face->n_children(); ++c)
            if (face->child(c) == fine_face)
              return face;
      Assert(false, ExcInternalError());
      return fine_face;
    }



    /** The EdgeKey of the whole edge @p edge. */
    template <typename FaceIterator>
    std::array<types::global_dof_index, 2>
    edge_key(const FaceIterator &edge)
    {
      const auto p = edge->vertex_dof_index(0, 0);
      const auto q = edge->vertex_dof_index(1, 0);
      return {{std::min(p, q), std::max(p, q)}};
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

    for (unsigned int q = 0; q < points.n_volume; ++q)
      rotation_basis.push_back(
        {{reference_rotation(dual_cell_quadrature.sub_triangle_of_point(q),
                             0,
                             points.quadrature.point(q)),
          reference_rotation(dual_cell_quadrature.sub_triangle_of_point(q),
                             1,
                             points.quadrature.point(q))}});

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
  Tensor<1, dim>
  FluxReconstruction<dim>::reference_rotation(const unsigned int s,
                                              const unsigned int l,
                                              const Point<dim>  &x) const
  {
    // λ_j is the linear function that is 1 at the corner c_j and 0 on the
    // line through the other two, r·(x − c_{j+1}) / r·(c_j − c_{j+1}) with
    // r normal to c_{j+2} − c_{j+1}; 4 λ_p λ_q has the gradient
    // 4 (λ_p ∇λ_q + λ_q ∇λ_p), and the curl is (∂_y, −∂_x).
    const auto &corners     = dual_cell_quadrature.sub_triangles()[s].corners;
    const auto  barycentric = [&](const unsigned int j) {
      const Tensor<1, dim> d = corners[(j + 2) % 3] - corners[(j + 1) % 3];
      const double         scale =
        cross_product_2d(d) * (corners[j] - corners[(j + 1) % 3]);
      return std::make_pair(cross_product_2d(d) * (x - corners[(j + 1) % 3]) /
                              scale,
                            Tensor<1, dim>(cross_product_2d(d) / scale));
    };
    const auto [lambda_p, grad_p] = barycentric((l + 1) % 3);
    const auto [lambda_q, grad_q] = barycentric((l + 2) % 3);
    const Tensor<1, dim> gradient = 4 * (lambda_p * grad_q + lambda_q * grad_p);
    Tensor<1, dim>       curl;
    curl[0] = gradient[1];
    curl[1] = -gradient[0];
    return curl;
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
    const unsigned int n_vertices = fe.reference_cell().n_vertices();

    const unsigned int n_cells =
      dof_handler.get_triangulation().n_active_cells();
    // Allocated without initial values: each cell's entries are set to
    // zero in the cell loop below (see SubTriangleData).
    static_assert(std::is_trivial_v<SubTriangleData> &&
                  std::is_trivial_v<PatchTerms>);
    sub_triangle_data.clear();
    sub_triangle_data.resize_fast(n_cells * n_triangles);
    // The unknown of a half-edge a–m_e at 2 × the index of its face + the
    // end a of the face, that of a whole edge at 2 × its index.
    std::vector<unsigned int> free_flux_index(
      2 * dof_handler.get_triangulation().n_raw_faces(),
      numbers::invalid_unsigned_int);
    std::vector<FreeFlux<dim>>                   free_fluxes;
    std::vector<std::pair<unsigned int, double>> free_flux_of(n_cells *
                                                              n_triangles);
    free_fluxes.reserve(n_cells * n_triangles);
    load_at_points.clear();
    load_at_points.resize_fast(2 * n_cells * points.n_volume);
    AlignedVector<PatchTerms> patch_terms;
    patch_terms.resize_fast(n_cells * n_triangles);
    hat_integrals.assign(n_cells, {});

    // What one thread needs on a cell, and what a cell gives the
    // minimization of t_ih (formed by the copier, in the order of the
    // cells): for each sub-triangle κ the slot of its unknown, the normal
    // of its edge e and |e|/2.
    struct Scratch
    {
      Scratch(const Discretization<dim> &discretization,
              const Quadrature<dim>     &quadrature,
              const unsigned int         n_volume)
        : fe_values(*discretization.mapping,
                    *discretization.fe,
                    quadrature,
                    update_values | update_gradients | update_jacobians |
                      update_quadrature_points | update_JxW_values)
        , volume_points(n_volume)
        , load(n_volume)
      {
        for (auto &gradient : gradients)
          gradient.resize(quadrature.size());
      }
      FEValues<dim>                              fe_values;
      std::array<std::vector<Tensor<1, dim>>, 2> gradients;
      std::vector<Point<dim>>                    volume_points;
      std::vector<double>                        load;
    };
    struct HalfEdge
    {
      unsigned int   slot;
      Tensor<1, dim> normal;
      double         half_measure;
    };
    struct CellHalfEdges
    {
      unsigned int          cell = numbers::invalid_unsigned_int;
      std::vector<HalfEdge> half_edges;
    };

    // The owned and the ghost cells: the cells along every half-edge of an
    // owned cell (along the whole coarse edge at a hanging node) lie in
    // them, so the half-edge rule below gives the owned cells the same t_ih
    // as on one process, without communication. (At the outer rim of the
    // ghost layer, groups are cut short by artificial cells; they belong
    // to no owned cell.) The patch problems need the owned cells only.
    // Each cell writes its own entries of sub_triangle_data, patch_terms
    // and load_at_points.
    run_on_cells<CellHalfEdges>(
      dof_handler,
      [&]() {
        return std::make_unique<Scratch>(discretization,
                                         points.quadrature,
                                         points.n_volume);
      },
      [&](const auto &cell, Scratch &scratch, CellHalfEdges &copy) {
        copy.cell                = numbers::invalid_unsigned_int;
        const unsigned int first = cell->active_cell_index() * n_triangles;
        std::fill_n(&sub_triangle_data[first], n_triangles, SubTriangleData{});
        std::fill_n(&patch_terms[first], n_triangles, PatchTerms{});
        std::fill_n(
          &load_at_points[2 * cell->active_cell_index() * points.n_volume],
          2 * points.n_volume,
          0.);
        if (cell->is_artificial())
          return;
        FEValues<dim> &fe_values     = scratch.fe_values;
        auto          &gradients     = scratch.gradients;
        auto          &volume_points = scratch.volume_points;
        auto          &load          = scratch.load;
        copy.cell                    = cell->active_cell_index();
        copy.half_edges.resize(n_triangles);
        fe_values.reinit(cell);
        for (unsigned int i = 0; i < 2; ++i)
          fe_values[FEValuesExtractors::Scalar(i)].get_function_gradients(
            ghosted_solution, gradients[i]);
        std::array<const double *, 2> loads;
        for (unsigned int q = 0; q < points.n_volume; ++q)
          volume_points[q] = fe_values.quadrature_point(q);
        for (unsigned int i = 0; i < 2; ++i)
          {
            data.load(i).value_list(volume_points, load);
            const auto first =
              load_at_points.begin() +
              (2 * cell->active_cell_index() + i) * points.n_volume;
            std::copy(load.begin(), load.end(), first);
            loads[i] = &*first;
          }
        for (unsigned int s = 0; s < n_triangles; ++s)
          {
            const auto        &triangle = triangles[s];
            const unsigned int id = cell->active_cell_index() * n_triangles + s;
            SubTriangleData   &kappa = sub_triangle_data[id];
            PatchTerms        &terms = patch_terms[id];

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
                  std::array<Tensor<1, dim>, 2> beta;
                  for (unsigned int l = 0; l < 2; ++l)
                    beta[l] = DF * rotation_basis[q][l] / det;
                  for (unsigned int k = 0; k < 3; ++k)
                    {
                      for (unsigned int l = 0; l < 3; ++l)
                        kappa.gram[k][l] += psi[k] * psi[l] * JxW;
                      for (unsigned int l = 0; l < 2; ++l)
                        kappa.mixed_gram[k][l] += psi[k] * beta[l] * JxW;
                      for (unsigned int i = 0; i < 2; ++i)
                        kappa.discrete_flux[i][k] +=
                          data.mu[i] * gradients[i][q] * psi[k] * JxW;
                    }
                  for (unsigned int l = 0; l < 2; ++l)
                    {
                      for (unsigned int m = 0; m < 2; ++m)
                        kappa.rotation_gram[l][m] += beta[l] * beta[m] * JxW;
                      for (unsigned int i = 0; i < 2; ++i)
                        kappa.discrete_rotation[i][l] +=
                          data.mu[i] * gradients[i][q] * beta[l] * JxW;
                    }
                  for (unsigned int i = 0; i < 2; ++i)
                    kappa.load[i] += loads[i][q] * JxW;
                  for (unsigned int v = 0; v < (owned ? n_vertices : 0); ++v)
                    {
                      const unsigned int k = fe.component_to_system_index(0, v);
                      const double       phi = fe_values.shape_value(k, q);
                      terms.hat_mass[v] += phi * JxW;
                      for (unsigned int i = 0; i < 2; ++i)
                        {
                          terms.hat_residual[i][v] +=
                            (loads[i][q] * phi - data.mu[i] * gradients[i][q] *
                                                   fe_values.shape_grad(k, q)) *
                            JxW;
                        }
                    }
                }

            // The unknowns of the half-edge a–m_e of κ, by their
            // EdgeKey: in the minimization of t_ih the half-edge, or at an
            // edge with a hanging vertex the whole coarse edge; in the
            // patch problems the half-edge, or at a hanging vertex the
            // small edge that holds it (with factor 1 from the coarse
            // side, 1/2 for each of the two half-edges on the fine side).
            const unsigned int f    = triangle.face;
            const auto         face = cell->face(f);
            const auto         a = cell->vertex_dof_index(triangle.vertex, 0);
            const auto         b =
              face->vertex_dof_index(face->vertex_dof_index(0, 0) == a ? 1 : 0,
                                     0);
            EdgeKey      patch_key{{a, b}};
            unsigned int slot =
              2 * face->index() + (face->vertex_dof_index(0, 0) == a ? 0 : 1);
            auto   patch_edge   = face;
            double patch_factor = 1;
            if (!cell->at_boundary(f) && face->has_children())
              {
                slot                  = 2 * face->index();
                const auto first_half = face->child(0);
                patch_edge = first_half->vertex_dof_index(0, 0) == a ||
                                 first_half->vertex_dof_index(1, 0) == a ?
                               first_half :
                               face->child(1);
                patch_key  = edge_key(patch_edge);
              }
            else if (!cell->at_boundary(f) && cell->neighbor_is_coarser(f))
              {
                slot         = 2 * coarse_face(cell, f)->index();
                patch_key    = edge_key(face);
                patch_factor = 0.5;
              }
            if (owned)
              {
                // The patch unknown counts in the direction of
                // cross_product_2d() of its edge run from the end with the
                // smaller index, alike on both sides.
                const bool increasing = patch_edge->vertex_dof_index(0, 0) <
                                        patch_edge->vertex_dof_index(1, 0);
                const Tensor<1, dim> along =
                  patch_edge->vertex(increasing ? 1 : 0) -
                  patch_edge->vertex(increasing ? 0 : 1);
                terms.key         = patch_key;
                terms.factor      = (cross_product_2d(along) *
                                      (patch_edge->center() - cell->center()) >
                                    0 ?
                                       patch_factor :
                                       -patch_factor);
                terms.on_boundary = cell->at_boundary(f);
              }

            Tensor<1, dim> normal =
              cross_product_2d(face->vertex(1) - face->vertex(0));
            normal /= normal.norm();
            if (normal * (face->center() - cell->center()) < 0)
              normal *= -1;
            copy.half_edges[s] = {slot, normal, face->measure() / 2};
          }
        if (cell->is_locally_owned())
          for (unsigned int s = 0; s < n_triangles; ++s)
            for (unsigned int v = 0; v < n_vertices; ++v)
              hat_integrals[cell->active_cell_index()][v] +=
                patch_terms[first + s].hat_mass[v];
      },
      [&](const CellHalfEdges &copy) {
        if (copy.cell == numbers::invalid_unsigned_int)
          return;
        // The contribution of each κ to the minimization of its unknown,
        // (−μ_i ∇u_ih − P_κ, ψ_κ) with ψ_κ = ψ_2.
        for (unsigned int s = 0; s < n_triangles; ++s)
          {
            const unsigned int     id    = copy.cell * n_triangles + s;
            const SubTriangleData &kappa = sub_triangle_data[id];
            const auto &[slot, normal, half_measure] = copy.half_edges[s];
            if (free_flux_index[slot] == numbers::invalid_unsigned_int)
              {
                free_flux_index[slot] = free_fluxes.size();
                free_fluxes.push_back({normal, {}, 0});
              }
            FreeFlux<dim> &free = free_fluxes[free_flux_index[slot]];
            const double   factor =
              (normal * free.normal > 0 ? 1. : -1.) * half_measure;
            free_flux_of[id] = {free_flux_index[slot], factor};
            free.denominator += factor * factor * kappa.gram[2][2];
            for (unsigned int i = 0; i < 2; ++i)
              free.numerator[i] +=
                factor * (-kappa.discrete_flux[i][2] -
                          kappa.fluxes[i][0] * kappa.gram[0][2] -
                          kappa.fluxes[i][1] * kappa.gram[1][2]);
          }
      });

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
  }



  template <int dim>
  typename FluxReconstruction<dim>::Identities
  FluxReconstruction<dim>::identities(
    const AffineConstraints<double> &hanging_node_constraints,
    const IndexSet                  &locally_owned_dofs,
    const MPI_Comm                   mpi_communicator) const
  {
    const FiniteElement<dim> &fe        = dof_handler->get_fe();
    const auto               &triangles = dual_cell_quadrature.sub_triangles();
    const unsigned int        n_triangles = triangles.size();

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
    for (const auto &cell : dof_handler->active_cell_iterators())
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
                // f_ih ∫_K φ_v.
                local_load_on_hats(k) =
                  load_mean[i] / area *
                  hat_integrals[cell->active_cell_index()][v];
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

    Identities  defects;
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
    return defects;
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
        const SubTriangleData &kappa =
          sub_triangle_data[cell->active_cell_index() * n_triangles + s];
        const auto          &f   = kappa.equilibrated[i];
        const Tensor<2, dim> DF  = to_tensor(fe_values.jacobian(q));
        const double         det = std::abs(determinant(DF));
        Tensor<1, dim> reference = reference_flux(s, f, quadrature.point(q));
        for (unsigned int l = 0; l < 2; ++l)
          reference += kappa.rotations[i][l] * rotation_basis[q][l];
        flux[q]       = DF * reference / det;
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
