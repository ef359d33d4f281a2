#include <algorithm>
#include <cmath>
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/distributed/tria_base.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/grid/grid_tools.h>
#include <membranes/flux_reconstruction.h>
#include <unordered_map>

namespace membranes
{
  template <int dim>
  DualCellQuadrature<dim>::DualCellQuadrature(
    const ReferenceCell &reference_cell,
    const unsigned int   degree)
  {
    static_assert(dim == 2, "The dual mesh is implemented for dim = 2.");
    const unsigned int n_vertices = reference_cell.n_vertices();

    std::vector<Point<dim>> vertices(n_vertices);
    Point<dim>              barycentre;
    for (unsigned int v = 0; v < n_vertices; ++v)
      {
        vertices[v] = reference_cell.template vertex<dim>(v);
        barycentre += vertices[v] / n_vertices;
      }

    // Every edge (face in 2d) of the reference cell contributes the
    // triangles (a, m_e, b) for both of its end points a.
    for (const unsigned int e : reference_cell.face_indices())
      for (unsigned int end = 0; end < 2; ++end)
        {
          const unsigned int a =
            reference_cell.face_to_cell_vertices(e, end, 1);
          const unsigned int other =
            reference_cell.face_to_cell_vertices(e, 1 - end, 1);
          SubTriangle triangle;
          triangle.vertex  = a;
          triangle.face    = e;
          triangle.corners = {
            {vertices[a], (vertices[a] + vertices[other]) / 2, barycentre}};
          const Tensor<1, dim> edge_1 = triangle.corners[1] - vertices[a];
          const Tensor<1, dim> edge_2 = triangle.corners[2] - vertices[a];
          triangle.area =
            std::abs(edge_1[0] * edge_2[1] - edge_1[1] * edge_2[0]) / 2;
          for (unsigned int j = 0; j < 3; ++j)
            {
              const Point<dim> &p      = triangle.corners[(j + 1) % 3];
              const Point<dim> &q      = triangle.corners[(j + 2) % 3];
              Tensor<1, dim>    normal = cross_product_2d(q - p);
              normal /= normal.norm();
              if (normal * (p - triangle.corners[j]) < 0)
                normal *= -1;
              triangle.normals[j] = normal;
            }
          triangles.push_back(triangle);
        }

    const QGaussSimplex<dim> simplex_rule((degree + 2) / 2);
    std::vector<Point<dim>>  points;
    std::vector<double>      weights;
    for (unsigned int s = 0; s < triangles.size(); ++s)
      {
        const auto &corners = triangles[s].corners;
        for (unsigned int q = 0; q < simplex_rule.size(); ++q)
          {
            const Point<dim> &xi = simplex_rule.point(q);
            points.push_back(corners[0] + xi[0] * (corners[1] - corners[0]) +
                             xi[1] * (corners[2] - corners[0]));
            weights.push_back(simplex_rule.weight(q) * 2 * triangles[s].area);
            triangle_of_points.push_back(s);
          }
      }
    rule = Quadrature<dim>(points, weights);
  }



  template <int dim>
  const Quadrature<dim> &
  DualCellQuadrature<dim>::quadrature() const
  {
    return rule;
  }



  template <int dim>
  unsigned int
  DualCellQuadrature<dim>::vertex_of_point(const unsigned int q) const
  {
    return triangles[triangle_of_points[q]].vertex;
  }



  template <int dim>
  unsigned int
  DualCellQuadrature<dim>::sub_triangle_of_point(const unsigned int q) const
  {
    return triangle_of_points[q];
  }



  template <int dim>
  const std::vector<typename DualCellQuadrature<dim>::SubTriangle> &
  DualCellQuadrature<dim>::sub_triangles() const
  {
    return triangles;
  }



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
     * (4.13)), then the corners of every sub-triangle (for the output).
     */
    template <int dim>
    struct ReconstructionPoints
    {
      static constexpr unsigned int n_edge_points = 2;

      explicit ReconstructionPoints(const DualCellQuadrature<dim> &dual)
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
          for (const Point<dim> &corner : triangle.corners)
            {
              points.push_back(corner);
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
    const ProblemData<dim>    &data)
    : discretization(discretization)
    , data(data)
    , dual_cell_quadrature(discretization.fe->reference_cell(), 2)
    , lambda_h(nullptr)
  {}



  template <int dim>
  const DualCellQuadrature<dim> &
  FluxReconstruction<dim>::dual_quadrature() const
  {
    return dual_cell_quadrature;
  }



  template <int dim>
  void
  FluxReconstruction<dim>::set_lambda_h(const DoFHandler<dim> &dof_handler,
                                        const VectorType      &lambda_h,
                                        const IndexSet &dual_mesh_vertices)
  {
    this->dof_handler        = &dof_handler;
    this->lambda_h           = &lambda_h;
    this->dual_mesh_vertices = dual_mesh_vertices;
  }



  template <int dim>
  double
  FluxReconstruction<dim>::lambda_h_value(const CellIterator &cell,
                                          const unsigned int  v) const
  {
    const types::global_dof_index a = cell->vertex_dof_index(v, 0);
    return dual_mesh_vertices.is_element(a) ? (*lambda_h)[a] : 0.;
  }



  template <int dim>
  void
  FluxReconstruction<dim>::lambda_h_values(const CellIterator  &cell,
                                           std::vector<double> &values,
                                           std::vector<bool> *in_omega_h) const
  {
    values.resize(dual_cell_quadrature.quadrature().size());
    if (in_omega_h)
      in_omega_h->resize(values.size());
    for (unsigned int q = 0; q < values.size(); ++q)
      {
        const unsigned int v = dual_cell_quadrature.vertex_of_point(q);
        values[q]            = lambda_h_value(cell, v);
        if (in_omega_h)
          (*in_omega_h)[q] =
            dual_mesh_vertices.is_element(cell->vertex_dof_index(v, 0));
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
    const VectorType                &ghosted_solution,
    const AffineConstraints<double> &hanging_node_constraints,
    const DiscreteAction<dim>       &action,
    const IndexSet                  &locally_owned_dofs,
    const MPI_Comm                   mpi_communicator)
  {
    const FiniteElement<dim> &fe        = *discretization.fe;
    const auto               &triangles = dual_cell_quadrature.sub_triangles();
    const unsigned int        n_triangles = triangles.size();
    ReconstructionPoints<dim> points(dual_cell_quadrature);
    FEValues<dim>             fe_values(*discretization.mapping,
                            fe,
                            points.quadrature,
                            update_values | update_gradients |
                              update_jacobians | update_quadrature_points |
                              update_JxW_values);
    std::array<std::vector<Tensor<1, dim>>, 2> gradients;
    for (auto &gradient : gradients)
      gradient.resize(points.quadrature.size());
    std::vector<Point<dim>>     volume_points(points.n_volume);
    std::vector<double>         load(points.n_volume);
    const std::array<double, 2> sign{{1., -1.}};

    const unsigned int n_cells =
      dof_handler->get_triangulation().n_active_cells();
    sub_triangle_data.assign(n_cells * n_triangles, SubTriangleData());
    links.assign(n_cells * n_triangles, {});
    std::unordered_map<unsigned long long, unsigned int> free_flux_index;
    std::vector<FreeFlux<dim>>                           free_fluxes;
    std::vector<std::vector<unsigned int>>               members;
    std::vector<std::pair<unsigned int, double>>         free_flux_of(n_cells *
                                                              n_triangles);
    vertex_sub_triangles.assign(dof_handler->get_triangulation().n_vertices(),
                                {});
    load_at_points.assign(2 * n_cells * points.n_volume, 0.);
    std::vector<double> hat_integrals(n_cells *
                                      GeometryInfo<dim>::vertices_per_cell);

    // The owned and the ghost cells: every half-edge and every fan around a
    // vertex of an owned cell lies in them, so the local rules below give
    // the owned cells the same fluxes as on one process, without
    // communication. (At the outer rim of the ghost layer, groups and fans
    // are cut short by artificial cells; they belong to no owned cell.)
    for (const auto &cell : dof_handler->active_cell_iterators())
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
          // ∫_K φ_v, for f_ih ∫_K φ_v in the balance of Lemma 17.
          for (const unsigned int v : cell->vertex_indices())
            for (unsigned int q = 0; q < points.n_volume; ++q)
              hat_integrals[cell->active_cell_index() *
                              GeometryInfo<dim>::vertices_per_cell +
                            v] +=
                fe_values.shape_value(fe.component_to_system_index(0, v), q) *
                fe_values.JxW(q);

          for (unsigned int s = 0; s < n_triangles; ++s)
            {
              const auto        &triangle = triangles[s];
              const unsigned int id =
                cell->active_cell_index() * n_triangles + s;
              SubTriangleData &kappa = sub_triangle_data[id];
              vertex_sub_triangles[cell->vertex_index(triangle.vertex)]
                .push_back(id);

              // The fluxes (4.13) through the edges 0 and 1, by Gauss points
              // on the reference edges: n ds = cof(DF) n̂ dŝ.
              for (unsigned int j = 0; j < 2; ++j)
                for (unsigned int i = 0; i < 2; ++i)
                  {
                    double flux = 0;
                    for (unsigned int k = 0; k < points.n_edge_points; ++k)
                      {
                        const unsigned int   q = points.edge_point(s, j, k);
                        const Tensor<2, dim> DF =
                          to_tensor(fe_values.jacobian(q));
                        const Tensor<2, dim> cofactor =
                          std::abs(determinant(DF)) * transpose(invert(DF));
                        flux -= data.mu[i] * gradients[i][q] *
                                (cofactor * triangle.normals[j]) *
                                points.quadrature.weight(q);
                      }
                    kappa.fluxes[i][j] = flux;
                  }

              // The Gram matrix of the mapped basis ψ_k, (μ_i ∇u_ih, ψ_k),
              // the area and ∫ (f_i + s_i λ_h) on κ.
              const double lambda = lambda_h_value(cell, triangle.vertex);
              for (unsigned int q = 0; q < points.n_volume; ++q)
                if (dual_cell_quadrature.sub_triangle_of_point(q) == s)
                  {
                    const Point<dim>    &x   = points.quadrature.point(q);
                    const Tensor<2, dim> DF  = to_tensor(fe_values.jacobian(q));
                    const double         det = std::abs(determinant(DF));
                    std::array<Tensor<1, dim>, 3> psi;
                    for (unsigned int k = 0; k < 3; ++k)
                      {
                        std::array<double, 3> unit{};
                        unit[k] = 1;
                        psi[k]  = DF * reference_flux(s, unit, x) / det;
                      }
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
                      {
                        kappa.load[i] += loads[i][q] * JxW;
                        kappa.source[i] +=
                          (loads[i][q] + sign[i] * lambda) * JxW;
                      }
                  }

              // The half-edge of κ: its unknown s, and the contribution of κ
              // to the minimization, (−μ_i ∇u_ih − P_κ, ψ_κ) with ψ_κ = ψ_2.
              const unsigned int f    = triangle.face;
              const auto         face = cell->face(f);
              unsigned long long key;
              bool               hanging = true;
              if (!cell->at_boundary(f) && cell->neighbor_is_coarser(f))
                key = 3ull * coarse_face_index(cell, f) + 2;
              else if (face->has_children())
                key = 3ull * face->index() + 2;
              else
                {
                  hanging = false;
                  key     = 3ull * face->index() +
                        (face->vertex_index(0) ==
                             cell->vertex_index(triangle.vertex) ?
                           0 :
                           1);
                }
              Tensor<1, dim> normal =
                cross_product_2d(face->vertex(1) - face->vertex(0));
              normal /= normal.norm();
              if (normal * (face->center() - cell->center()) < 0)
                normal *= -1;
              const auto [entry, is_new] =
                free_flux_index.emplace(key, free_fluxes.size());
              if (is_new)
                {
                  free_fluxes.push_back({normal, {}, 0});
                  members.emplace_back();
                }
              FreeFlux<dim> &free = free_fluxes[entry->second];
              members[entry->second].push_back(id);
              const double factor =
                (normal * free.normal > 0 ? 1. : -1.) * face->measure() / 2;
              free_flux_of[id] = {entry->second, factor};
              free.denominator += factor * factor * kappa.gram[2][2];
              for (unsigned int i = 0; i < 2; ++i)
                free.numerator[i] +=
                  factor * (-kappa.discrete_flux[i][2] -
                            kappa.fluxes[i][0] * kappa.gram[0][2] -
                            kappa.fluxes[i][1] * kappa.gram[1][2]);

              // Its neighbours around a for the equilibration: the other
              // half of the same piece across edge 1; across edge 2 the
              // sub-triangle of the neighbour cell (filled below), or an
              // end of the chain: ∂ω (free) or an edge with a hanging node.
              for (unsigned int t = 0; t < n_triangles; ++t)
                if (t != s && triangles[t].vertex == triangle.vertex)
                  links[id][0] = cell->active_cell_index() * n_triangles + t;
              links[id][1] = (cell->at_boundary(f) ? free_end :
                              hanging              ? zero_end :
                                                     free_end);
            }
        }

    // The minimizers, the fluxes through the half-edges, and the links
    // across regular half-edges (two sub-triangles, both in D_a).
    for (unsigned int group = 0; group < free_fluxes.size(); ++group)
      for (const unsigned int id : members[group])
        {
          const auto [index, factor] = free_flux_of[id];
          for (unsigned int i = 0; i < 2; ++i)
            sub_triangle_data[id].fluxes[i][2] =
              factor * free_fluxes[index].numerator[i] /
              free_fluxes[index].denominator;
          if (members[group].size() == 2 && links[id][1] == free_end)
            links[id][1] =
              members[group][0] == id ? members[group][1] : members[group][0];
        }

    // The flux density on an edge with a hanging node is a mean over the
    // three cells along the whole coarse edge, and a ghost cell may lack
    // one of them (outside the ghost layer), while the fan of a vertex of
    // an owned cell may pass through that ghost cell. Every owner has the
    // whole neighbourhood of its cells: it sends their half-edge fluxes to
    // the ghost copies.
    if (dynamic_cast<const parallel::TriangulationBase<dim> *>(
          &dof_handler->get_triangulation()))
      GridTools::exchange_cell_data_to_ghosts<std::vector<double>,
                                              DoFHandler<dim>>(
        *dof_handler,
        [&](const CellIterator &cell) {
          std::vector<double> half_edge_fluxes;
          for (unsigned int s = 0; s < n_triangles; ++s)
            for (unsigned int i = 0; i < 2; ++i)
              half_edge_fluxes.push_back(
                sub_triangle_data[cell->active_cell_index() * n_triangles + s]
                  .fluxes[i][2]);
          return std::optional<std::vector<double>>(half_edge_fluxes);
        },
        [&](const CellIterator &cell, const std::vector<double> &in) {
          for (unsigned int s = 0; s < n_triangles; ++s)
            for (unsigned int i = 0; i < 2; ++i)
              sub_triangle_data[cell->active_cell_index() * n_triangles + s]
                .fluxes[i][2] = in[2 * s + i];
        });

    equilibrate();

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
                local_load_on_hats(k) =
                  load_mean[i] / area *
                  hat_integrals[cell->active_cell_index() *
                                  GeometryInfo<dim>::vertices_per_cell +
                                v];
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



  template <int dim>
  void
  FluxReconstruction<dim>::equilibrate()
  {
    for (auto &kappa : sub_triangle_data)
      kappa.equilibrated = kappa.fluxes;
    // Chains from an edge with a hanging node first (δ_ih = 0 there), then
    // from ∂ω, then the closed fans of the remaining interior vertices.
    std::vector<bool> visited(sub_triangle_data.size(), false);
    for (const unsigned int start : {zero_end, free_end, 0u})
      for (const auto &around : vertex_sub_triangles)
        for (const unsigned int first : around)
          {
            if (visited[first])
              continue;
            unsigned int slot = 0;
            if (start != 0u)
              {
                if (links[first][0] == start)
                  slot = 0;
                else if (links[first][1] == start)
                  slot = 1;
                else
                  continue;
              }
            std::vector<std::pair<unsigned int, unsigned int>> chain;
            unsigned int                                       id     = first;
            bool                                               closed = false;
            while (true)
              {
                chain.emplace_back(id, slot);
                visited[id]             = true;
                const unsigned int next = links[id][1 - slot];
                if (next == free_end || next == zero_end)
                  break;
                if (next == first)
                  {
                    closed = true;
                    break;
                  }
                id   = next;
                slot = 1 - slot;
              }
            equilibrate_chain(
              chain,
              start != zero_end,
              closed ||
                links[chain.back().first][1 - chain.back().second] == zero_end);
          }
  }



  template <int dim>
  void
  FluxReconstruction<dim>::equilibrate_chain(
    const std::vector<std::pair<unsigned int, unsigned int>> &chain,
    const bool                                                free_entry,
    const bool                                                closed)
  {
    // With y_j the flux of δ_ih from κ_j into κ_{j+1} (y_0 into κ_1
    // through its entry edge), ∫_κj div δ_ih = y_j − y_{j−1} = r_j: the
    // y_j are y_0 plus partial sums of the r_j. A chain closed at both ends
    // (a fan around an interior vertex, or ends with a hanging node)
    // needs Σ r_j = 0, which the constant γ provides.
    double area = 0;
    for (const auto &[id, slot] : chain)
      area += sub_triangle_data[id].area;
    for (unsigned int i = 0; i < 2; ++i)
      {
        double gamma = 0;
        if (closed)
          {
            for (const auto &[id, slot] : chain)
              {
                const SubTriangleData &kappa = sub_triangle_data[id];
                gamma += kappa.fluxes[i][0] + kappa.fluxes[i][1] +
                         kappa.fluxes[i][2] - kappa.source[i];
              }
            gamma /= area;
          }

        // δ = δ^p + y_0 d on each κ_j, in the edge numbering of κ_j.
        std::vector<std::array<double, 3>> particular(chain.size()),
          direction(chain.size());
        double Y = 0;
        for (unsigned int j = 0; j < chain.size(); ++j)
          {
            const auto &[id, slot]       = chain[j];
            const SubTriangleData &kappa = sub_triangle_data[id];
            const double           r =
              kappa.source[i] + gamma * kappa.area -
              (kappa.fluxes[i][0] + kappa.fluxes[i][1] + kappa.fluxes[i][2]);
            particular[j]           = {};
            direction[j]            = {};
            particular[j][slot + 1] = -Y;
            Y += r;
            particular[j][2 - slot] = Y;
            direction[j][slot + 1]  = -1;
            direction[j][2 - slot]  = 1;
          }

        // y_0 minimizes Σ_j ‖μ_i^{-1/2} σ_ih + μ_i^{1/2} ∇u_ih‖²_κj, unless
        // the chain starts at an edge with a hanging node (y_0 = 0; if it
        // ends at one too, γ makes the flux there zero as well).
        double y_0 = 0;
        if (free_entry)
          {
            double numerator = 0, denominator = 0;
            for (unsigned int j = 0; j < chain.size(); ++j)
              {
                const SubTriangleData &kappa =
                  sub_triangle_data[chain[j].first];
                for (unsigned int k = 0; k < 3; ++k)
                  {
                    numerator += direction[j][k] * kappa.discrete_flux[i][k];
                    for (unsigned int l = 0; l < 3; ++l)
                      {
                        numerator += direction[j][k] * kappa.gram[k][l] *
                                     (kappa.fluxes[i][l] + particular[j][l]);
                        denominator +=
                          direction[j][k] * kappa.gram[k][l] * direction[j][l];
                      }
                  }
              }
            y_0 = -numerator / denominator;
          }
        for (unsigned int j = 0; j < chain.size(); ++j)
          {
            SubTriangleData &kappa = sub_triangle_data[chain[j].first];
            for (unsigned int k = 0; k < 3; ++k)
              kappa.equilibrated[i][k] =
                kappa.fluxes[i][k] + particular[j][k] + y_0 * direction[j][k];
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
    ReconstructionPoints<dim> points(dual_cell_quadrature);
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
                  patch.data(1, j) = lambda_h_value(cell, triangles[s].vertex);
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



  template class DualCellQuadrature<2>;
  template class FluxReconstruction<2>;
} // namespace membranes
