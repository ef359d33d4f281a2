#include <algorithm>
#include <cmath>
#include <deal.II/base/mpi.h>
#include <deal.II/fe/fe_values.h>
#include <membranes/flux/flux_reconstruction.h>
#include <membranes/mesh/cell_loop.h>
#include <type_traits>

// The fluxes t_ih of (4.13) and the identities (4.17), (4.18) and Lemma 17,
// and the dual mesh as output.

namespace membranes
{
  namespace
  {
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
  struct FluxReconstruction<dim>::LocalFluxScratch
  {
    LocalFluxScratch(const Discretization<dim>    &discretization,
                     const SubTrianglePoints<dim> &points)
      : points(points)
      , fe_values(*discretization.mapping,
                  *discretization.fe,
                  points.quadrature,
                  update_values | update_gradients | update_jacobians |
                    update_quadrature_points | update_JxW_values)
      , volume_points(points.n_volume)
    {
      for (auto &gradient : gradients)
        gradient.resize(points.quadrature.size());
    }

    const SubTrianglePoints<dim> &points;
    FEValues<dim>                 fe_values;
    /** ∇u_ih at the points. */
    std::array<std::vector<Tensor<1, dim>>, 2> gradients;
    std::vector<Point<dim>>                    volume_points;
    typename ProblemData<dim>::LoadValues      load;
    /** f_i at the points of the dual quadrature, in load_at_points. */
    std::array<const double *, 2> loads;
  };



  /**
   * What a cell gives the minimization of t_ih (added by the copier, in the
   * order of the cells): for each sub-triangle κ the slot of its unknown,
   * the normal of its half-edge and half the length of its edge.
   */
  template <int dim>
  struct FluxReconstruction<dim>::LocalFluxCopy
  {
    struct HalfEdge
    {
      unsigned int   slot;
      Tensor<1, dim> normal;
      double         half_measure;
    };
    unsigned int          cell = numbers::invalid_unsigned_int;
    std::vector<HalfEdge> half_edges;
  };



  /**
   * The unknowns of the minimization of t_ih: the index of the unknown of
   * a half-edge a–m_e at 2 × the index of its face + the end a of the face,
   * that of a whole edge at 2 × its index; the unknowns; per sub-triangle
   * its unknown and the factor that gives its outward flux.
   */
  template <int dim>
  struct FluxReconstruction<dim>::HalfEdgeMinimization
  {
    std::vector<unsigned int>                    free_flux_index;
    std::vector<FreeFlux<dim>>                   free_fluxes;
    std::vector<std::pair<unsigned int, double>> free_flux_of;
  };



  /**
   * The cell loop runs on the owned and the ghost cells: the cells along
   * every half-edge of an owned cell (along the whole coarse edge at a
   * hanging node) lie in them, so the half-edge rule gives the owned cells
   * the same t_ih as on one process, without communication. (At the outer
   * rim of the ghost layer, groups are cut short by artificial cells; they
   * belong to no owned cell.) The patch problems need the owned cells only.
   * Each cell writes its own entries of sub_triangle_data, patch_terms and
   * load_at_points; the minimizers then give the fluxes of t_ih through the
   * half-edges.
   */
  template <int dim>
  AlignedVector<typename FluxReconstruction<dim>::PatchTerms>
  FluxReconstruction<dim>::reconstruct(const DoFHandler<dim> &dof_handler,
                                       const BlockVectorType &ghosted_solution)
  {
    const unsigned int n_cells =
      dof_handler.get_triangulation().n_active_cells();
    const unsigned int n_triangles = basis.n_sub_triangles();
    // Allocated without initial values: each cell's entries are set to
    // zero in the cell loop (see SubTriangleData).
    static_assert(std::is_trivial_v<SubTriangleData> &&
                  std::is_trivial_v<PatchTerms>);
    sub_triangle_data.clear();
    sub_triangle_data.resize_fast(n_cells * n_triangles);
    load_at_points.clear();
    load_at_points.resize_fast(2 * n_cells * basis.points().n_volume);
    AlignedVector<PatchTerms> patch_terms;
    patch_terms.resize_fast(n_cells * n_triangles);
    hat_integrals.assign(n_cells, {});

    HalfEdgeMinimization minimization;
    minimization.free_flux_index.assign(
      2 * dof_handler.get_triangulation().n_raw_faces(),
      numbers::invalid_unsigned_int);
    minimization.free_flux_of.resize(sub_triangle_data.size());
    minimization.free_fluxes.reserve(sub_triangle_data.size());
    run_on_cells<LocalFluxCopy>(
      dof_handler,
      [&]() {
        return std::make_unique<LocalFluxScratch>(discretization,
                                                  basis.points());
      },
      [&](const CellIterator &cell,
          LocalFluxScratch   &scratch,
          LocalFluxCopy      &copy) {
        local_fluxes_on_cell(
          cell, ghosted_solution, patch_terms, scratch, copy);
      },
      [&](const LocalFluxCopy &copy) {
        add_to_minimization(copy, minimization);
      });

    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        for (unsigned int s = 0; s < n_triangles; ++s)
          {
            const unsigned int id = cell->active_cell_index() * n_triangles + s;
            const auto [index, factor] = minimization.free_flux_of[id];
            const FreeFlux<dim> &free  = minimization.free_fluxes[index];
            for (unsigned int i = 0; i < 2; ++i)
              sub_triangle_data[id].fluxes[i][2] =
                factor * free.numerator[i] / free.denominator;
          }
    return patch_terms;
  }



  template <int dim>
  void
  FluxReconstruction<dim>::local_fluxes_on_cell(
    const CellIterator        &cell,
    const BlockVectorType     &ghosted_solution,
    AlignedVector<PatchTerms> &patch_terms,
    LocalFluxScratch          &scratch,
    LocalFluxCopy             &copy)
  {
    const unsigned int n_triangles = basis.n_sub_triangles();
    const unsigned int n_volume    = scratch.points.n_volume;
    const unsigned int first       = cell->active_cell_index() * n_triangles;
    copy.cell                      = numbers::invalid_unsigned_int;
    std::fill_n(&sub_triangle_data[first], n_triangles, SubTriangleData{});
    std::fill_n(&patch_terms[first], n_triangles, PatchTerms{});
    std::fill_n(&load_at_points[2 * cell->active_cell_index() * n_volume],
                2 * n_volume,
                0.);
    if (cell->is_artificial())
      return;
    copy.cell = cell->active_cell_index();
    copy.half_edges.resize(n_triangles);
    scratch.fe_values.reinit(cell);
    for (unsigned int i = 0; i < 2; ++i)
      scratch.fe_values.get_function_gradients(ghosted_solution.block(i),
                                               scratch.gradients[i]);
    for (unsigned int q = 0; q < n_volume; ++q)
      scratch.volume_points[q] = scratch.fe_values.quadrature_point(q);
    data.load_list(scratch.volume_points, scratch.load);
    for (unsigned int i = 0; i < 2; ++i)
      {
        const auto begin = load_at_points.begin() +
                           (2 * cell->active_cell_index() + i) * n_volume;
        std::copy(scratch.load.f[i].begin(), scratch.load.f[i].end(), begin);
        scratch.loads[i] = &*begin;
      }
    for (unsigned int s = 0; s < n_triangles; ++s)
      {
        SubTriangleData &kappa = sub_triangle_data[first + s];
        PatchTerms      &terms = patch_terms[first + s];
        integrate_edge_fluxes(cell, s, scratch, kappa, terms);
        integrate_sub_triangle(cell, s, scratch, kappa, terms);
        name_half_edge(cell, s, terms, copy);
      }
    if (cell->is_locally_owned())
      for (unsigned int s = 0; s < n_triangles; ++s)
        for (unsigned int v = 0;
             v < discretization.fe->reference_cell().n_vertices();
             ++v)
          hat_integrals[cell->active_cell_index()][v] +=
            patch_terms[first + s].hat_mass[v];
  }



  /**
   * The fluxes (4.13) through the edges 0 and 1, by Gauss points on the
   * reference edges: n ds = cof(DF) n̂ dŝ. On the owned cells, the hat
   * function terms of the patch problems (see FluxEquilibration): the fluxes of
   * φ_v μ_i ∇u_ih through all three edges of κ, and ∫ φ_v along a half-edge
   * on ∂ω.
   */
  template <int dim>
  void
  FluxReconstruction<dim>::integrate_edge_fluxes(
    const CellIterator     &cell,
    const unsigned int      s,
    const LocalFluxScratch &scratch,
    SubTriangleData        &kappa,
    PatchTerms             &terms) const
  {
    const auto &triangle = basis.sub_triangles()[s];
    const auto &points   = scratch.points;
    const bool  owned    = cell->is_locally_owned();
    for (unsigned int e = 0; e < (owned ? 3 : 2); ++e)
      for (unsigned int k = 0; k < points.n_edge_points; ++k)
        {
          const unsigned int   q  = points.edge_point(s, e, k);
          const Tensor<2, dim> DF = scratch.fe_values.jacobian(q);
          const Tensor<1, dim> n_ds =
            std::abs(determinant(DF)) * transpose(invert(DF)) *
            triangle.normals[e] * points.quadrature.weight(q);
          for (unsigned int i = 0; i < 2; ++i)
            {
              const double flux_density =
                data.mu[i] * scratch.gradients[i][q] * n_ds;
              if (e < 2)
                kappa.fluxes[i][e] -= flux_density;
              if (owned)
                terms.edge_flux[i][e][k] = flux_density;
            }
          if (owned && e == 2 && cell->at_boundary(triangle.face))
            terms.boundary_length[k] = n_ds.norm();
        }
  }



  template <int dim>
  void
  FluxReconstruction<dim>::integrate_sub_triangle(
    const CellIterator     &cell,
    const unsigned int      s,
    const LocalFluxScratch &scratch,
    SubTriangleData        &kappa,
    PatchTerms             &terms) const
  {
    const FiniteElement<dim> &fe        = *discretization.fe;
    const FEValues<dim>      &fe_values = scratch.fe_values;
    const unsigned int        n_vertices =
      cell->is_locally_owned() ? fe.reference_cell().n_vertices() : 0;
    const auto &gradients = scratch.gradients;
    for (unsigned int q = 0; q < scratch.points.n_volume; ++q)
      if (dual_cell_quadrature.sub_triangle_of_point(q) == s)
        {
          const Tensor<2, dim>          DF  = fe_values.jacobian(q);
          const double                  det = std::abs(determinant(DF));
          std::array<Tensor<1, dim>, 3> psi;
          for (unsigned int k = 0; k < 3; ++k)
            psi[k] = DF * basis.flux_basis(q)[k] / det;
          const double JxW = fe_values.JxW(q);
          kappa.area += JxW;
          std::array<Tensor<1, dim>, 2> beta;
          for (unsigned int l = 0; l < 2; ++l)
            beta[l] = DF * basis.rotation_basis(q)[l] / det;
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
            kappa.load[i] += scratch.loads[i][q] * JxW;
          // The hat function of vertex v is shape function v of the P1/Q1
          // element.
          for (unsigned int v = 0; v < n_vertices; ++v)
            {
              const double phi = fe_values.shape_value(v, q);
              terms.hat_mass[v] += phi * JxW;
              for (unsigned int i = 0; i < 2; ++i)
                terms.hat_residual[i][v] +=
                  (scratch.loads[i][q] * phi -
                   data.mu[i] * gradients[i][q] * fe_values.shape_grad(v, q)) *
                  JxW;
            }
        }
  }



  /**
   * The unknowns of the half-edge a–m_e of κ, by their EdgeKey: in the
   * minimization of t_ih the half-edge, or at an edge with a hanging vertex
   * the whole coarse edge; in the patch problems the half-edge, or at a
   * hanging vertex the small edge that holds it (with factor 1 from the
   * coarse side, 1/2 for each of the two half-edges on the fine side).
   */
  template <int dim>
  void
  FluxReconstruction<dim>::name_half_edge(const CellIterator &cell,
                                          const unsigned int  s,
                                          PatchTerms         &terms,
                                          LocalFluxCopy      &copy) const
  {
    const auto        &triangle = basis.sub_triangles()[s];
    const unsigned int f        = triangle.face;
    const auto         face     = cell->face(f);
    const auto         a        = cell->vertex_dof_index(triangle.vertex, 0);
    const auto         b =
      face->vertex_dof_index(face->vertex_dof_index(0, 0) == a ? 1 : 0, 0);
    EdgeKey      patch_key{{a, b}};
    unsigned int slot =
      2 * face->index() + (face->vertex_dof_index(0, 0) == a ? 0 : 1);
    auto   patch_edge   = face;
    double patch_factor = 1;
    if (!cell->at_boundary(f) && face->has_children())
      {
        slot                  = 2 * face->index();
        const auto first_half = face->child(0);
        patch_edge            = first_half->vertex_dof_index(0, 0) == a ||
                         first_half->vertex_dof_index(1, 0) == a ?
                                  first_half :
                                  face->child(1);
        patch_key             = edge_key(patch_edge);
      }
    else if (!cell->at_boundary(f) && cell->neighbor_is_coarser(f))
      {
        slot         = 2 * coarse_face(cell, f)->index();
        patch_key    = edge_key(face);
        patch_factor = 0.5;
      }
    if (cell->is_locally_owned())
      {
        // The patch unknown counts in the direction of cross_product_2d()
        // of its edge run from the end with the smaller index, alike on
        // both sides.
        const bool increasing = patch_edge->vertex_dof_index(0, 0) <
                                patch_edge->vertex_dof_index(1, 0);
        const Tensor<1, dim> along = patch_edge->vertex(increasing ? 1 : 0) -
                                     patch_edge->vertex(increasing ? 0 : 1);
        terms.key = patch_key;
        terms.factor =
          (cross_product_2d(along) * (patch_edge->center() - cell->center()) >
               0 ?
             patch_factor :
             -patch_factor);
        terms.on_boundary = cell->at_boundary(f);
      }

    Tensor<1, dim> normal = cross_product_2d(face->vertex(1) - face->vertex(0));
    normal /= normal.norm();
    if (normal * (face->center() - cell->center()) < 0)
      normal *= -1;
    copy.half_edges[s] = {slot, normal, face->measure() / 2};
  }



  /**
   * The contribution of each κ to the minimization of its unknown,
   * (−μ_i ∇u_ih − P_κ, ψ_κ) with ψ_κ = ψ_2, and ‖ψ_κ‖².
   */
  template <int dim>
  void
  FluxReconstruction<dim>::add_to_minimization(
    const LocalFluxCopy  &copy,
    HalfEdgeMinimization &minimization) const
  {
    if (copy.cell == numbers::invalid_unsigned_int)
      return;
    const unsigned int n_triangles = basis.n_sub_triangles();
    auto &[free_flux_index, free_fluxes, free_flux_of] = minimization;
    for (unsigned int s = 0; s < n_triangles; ++s)
      {
        const unsigned int     id                = copy.cell * n_triangles + s;
        const SubTriangleData &kappa             = sub_triangle_data[id];
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
          free.numerator[i] += factor * (-kappa.discrete_flux[i][2] -
                                         kappa.fluxes[i][0] * kappa.gram[0][2] -
                                         kappa.fluxes[i][1] * kappa.gram[1][2]);
      }
  }



  template <int dim>
  typename FluxReconstruction<dim>::DualCellSums
  FluxReconstruction<dim>::dual_cell_sums(
    const DoFHandler<dim>           &dof_handler,
    const AffineConstraints<double> &hanging_node_constraints,
    const IndexSet                  &locally_owned_dofs,
    const MPI_Comm                   mpi_communicator) const
  {
    const auto        &triangles   = basis.sub_triangles();
    const unsigned int n_triangles = triangles.size();

    // Per cell and vertex v the measure of K ∩ D_v and, in block i, the
    // integral of div t_ih over it, f_ih meas(K ∩ D_v) and f_ih ∫_K φ_v,
    // condensed like d_a with the hanging node constraints. The hat
    // function of vertex v is shape function v of the P1/Q1 element.
    DualCellSums sums;
    sums.measure.reinit(locally_owned_dofs, mpi_communicator);
    const std::array<BlockVectorType *, 3> blocks{
      {&sums.divergence, &sums.load_on_pieces, &sums.load_on_hats}};
    for (auto *vector : blocks)
      vector->reinit(std::vector<IndexSet>(2, locally_owned_dofs),
                     mpi_communicator);
    const unsigned int dofs_per_cell = dof_handler.get_fe().n_dofs_per_cell();
    Vector<double>     local_measure(dofs_per_cell);
    // Per membrane the local parts of the vectors of blocks.
    std::array<std::array<Vector<double>, 3>, 2> local;
    for (auto &membrane : local)
      for (auto &vector : membrane)
        vector.reinit(dofs_per_cell);
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
          local_measure = 0;
          for (unsigned int i = 0; i < 2; ++i)
            local[i][0] = 0;
          for (unsigned int s = 0; s < n_triangles; ++s)
            {
              const unsigned int v = triangles[s].vertex;
              local_measure(v) += kappa[s].area;
              for (unsigned int i = 0; i < 2; ++i)
                local[i][0](v) += kappa[s].fluxes[i][0] +
                                  kappa[s].fluxes[i][1] + kappa[s].fluxes[i][2];
            }
          for (const unsigned int v : cell->vertex_indices())
            for (unsigned int i = 0; i < 2; ++i)
              {
                local[i][1](v) = load_mean[i] / area * local_measure(v);
                local[i][2](v) = load_mean[i] / area *
                                 hat_integrals[cell->active_cell_index()][v];
              }
          hanging_node_constraints.distribute_local_to_global(local_measure,
                                                              dof_indices,
                                                              sums.measure);
          for (unsigned int i = 0; i < 2; ++i)
            for (unsigned int k = 0; k < 3; ++k)
              hanging_node_constraints.distribute_local_to_global(
                local[i][k], dof_indices, blocks[k]->block(i));
        }
    sums.measure.compress(VectorOperation::add);
    for (auto *vector : blocks)
      vector->compress(VectorOperation::add);
    return sums;
  }



  template <int dim>
  typename FluxReconstruction<dim>::Identities
  FluxReconstruction<dim>::identities(
    const DoFHandler<dim>           &dof_handler,
    const AffineConstraints<double> &hanging_node_constraints,
    const DiscreteProblem<dim>      &problem,
    const DiscreteAction<dim>       &action) const
  {
    const MPI_Comm mpi_communicator = problem.get_mpi_communicator();
    const auto &[measure, divergence, load_on_pieces, load_on_hats] =
      dual_cell_sums(dof_handler,
                     hanging_node_constraints,
                     problem.locally_owned_dofs(),
                     mpi_communicator);
    Identities  defects;
    const auto &vertices = problem.vertices();
    for (unsigned int k = 0; k < vertices.size(); ++k)
      {
        const auto &a   = vertices[k];
        const auto  dof = a.dof;
        defects.measure_defect =
          std::max(defects.measure_defect,
                   std::abs(measure[dof] - a.dual_cell_measure) /
                     a.dual_cell_measure);
        for (unsigned int i = 0; i < 2; ++i)
          {
            const double sign             = (i == 0 ? 1. : -1.);
            const double divergence_i     = divergence.block(i)[dof];
            const double load_on_pieces_i = load_on_pieces.block(i)[dof];
            defects.conservation_defect =
              std::max(defects.conservation_defect,
                       std::abs(divergence_i -
                                action.stiffness_term(problem, i, k)));
            // ∫ (f_i − f_ih) φ_a with the assembly's ∫ f_i φ_a.
            const double oscillation =
              action.load_term(problem, i, k) - load_on_hats.block(i)[dof];
            defects.balance_defect = std::max(
              defects.balance_defect,
              std::abs(sign * action.lambda_from_membrane(i, k) * measure[dof] -
                       (divergence_i - load_on_pieces_i - oscillation)));
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
  ArrayView<const double>
  FluxReconstruction<dim>::load_values(const CellIterator &cell,
                                       const unsigned int  i) const
  {
    const unsigned int n_points = dual_cell_quadrature.quadrature().size();
    const double      *first =
      load_at_points.data() + (2 * cell->active_cell_index() + i) * n_points;
    return make_array_view(first, first + n_points);
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
  FluxReconstruction<dim>::patches(const DoFHandler<dim> &dof_handler,
                                   const DualMesh<dim>   &dual_mesh,
                                   const VectorType      &lambda_h) const
  {
    const auto            &triangles = basis.sub_triangles();
    SubTrianglePoints<dim> points(dual_cell_quadrature, true);
    FEValues<dim>          fe_values(*discretization.mapping,
                            *discretization.fe,
                            points.quadrature,
                            update_quadrature_points | update_jacobians);
    std::vector<DataOutBase::Patch<dim, dim>> patches;
    for (const auto &cell : dof_handler.active_cell_iterators())
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
                  const Tensor<2, dim> DF  = fe_values.jacobian(q);
                  const double         det = std::abs(determinant(DF));
                  patch.data(0, j) = cell->vertex_index(triangles[s].vertex);
                  patch.data(1, j) =
                    dual_mesh.lambda_h_value(cell,
                                             triangles[s].vertex,
                                             lambda_h);
                  for (unsigned int i = 0; i < 2; ++i)
                    {
                      const Tensor<1, dim> t =
                        DF *
                        basis.reference_flux(s, f[i], triangles[s].corners[j]) /
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
