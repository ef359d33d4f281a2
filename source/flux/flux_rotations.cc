#include <algorithm>
#include <boost/serialization/array.hpp>
#include <boost/serialization/vector.hpp>
#include <deal.II/base/parallel.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/vector.h>
#include <membranes/flux/flux_equilibration.h>

// The rotation relaxation of the equilibrated fluxes σ_ih: divergence-free
// corrections around the vertices of the sub-mesh S_h and inside each cell
// (see the class comment of FluxEquilibration).

namespace membranes
{
  namespace
  {
    /**
     * A rotation around a vertex p of S_h on one sub-triangle κ: the index
     * of κ in the sub-triangle data, the change u_κ of its fluxes, and, for
     * the Gram matrix G_κ and the products g_κ of κ, G_κ u_κ and u_κ·g_κ.
     */
    struct Rotation
    {
      unsigned int          kappa;
      std::array<double, 3> u, Gu;
      std::array<double, 2> ug;
    };

    /**
     * A vertex p of S_h: its rotations [begin, end) and Σ_κ u_κ·G_κ u_κ.
     */
    struct RotationVertex
    {
      unsigned int begin, end;
      double       denominator;
    };

    /** A rotation before the vertices are grouped: p by its node number. */
    struct RotationEntry
    {
      unsigned int          node, kappa;
      std::array<double, 3> u;
    };

    /** The vertices of S_h at the corners of a sub-triangle, weighted. */
    using CornerNodes =
      std::array<std::array<std::pair<unsigned int, double>, 2>, 3>;

    /**
     * Call @p f on every vertex of @p vertices, on threads: the vertices of
     * one kind share no sub-triangle, so their updates touch disjoint data
     * and give the same result as in order.
     */
    template <typename Function>
    void
    for_each_vertex(std::vector<RotationVertex> &vertices, const Function &f)
    {
      parallel::apply_to_subranges(
        vertices.begin(),
        vertices.end(),
        [&](const auto begin, const auto end) {
          for (auto p = begin; p != end; ++p)
            f(*p);
        },
        1000);
    }



    /**
     * The corners of each reference sub-triangle of @p triangles in
     * counterclockwise order.
     */
    template <typename SubTriangles>
    std::vector<std::array<unsigned int, 3>>
    counterclockwise_corners(const SubTriangles &triangles)
    {
      std::vector<std::array<unsigned int, 3>> counterclockwise;
      for (const auto &triangle : triangles)
        {
          const auto &p  = triangle.corners;
          const auto  e1 = p[1] - p[0], e2 = p[2] - p[0];
          counterclockwise.push_back(e1[0] * e2[1] - e1[1] * e2[0] > 0 ?
                                       std::array<unsigned int, 3>{{0, 1, 2}} :
                                       std::array<unsigned int, 3>{{0, 2, 1}});
        }
      return counterclockwise;
    }



    /**
     * The vertices of S_h at the corners a, m_e, b_K of @p triangle on
     * @p cell, with weights (two at the midpoint of a small edge), and
     * their number per corner.
     */
    template <typename CellIterator, typename SubTriangle>
    std::pair<CornerNodes, std::array<unsigned int, 3>>
    sub_mesh_vertices(const CellIterator &cell,
                      const SubTriangle  &triangle,
                      const unsigned int  n_vertices,
                      const unsigned int  first_cell)
    {
      const unsigned int          f        = triangle.face;
      const auto                  face     = cell->face(f);
      const bool                  boundary = cell->at_boundary(f);
      CornerNodes                 nodes;
      std::array<unsigned int, 3> n_nodes_of{{1, 1, 1}};
      nodes[0][0] = {cell->vertex_index(triangle.vertex), 1.};
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
      return {nodes, n_nodes_of};
    }



    /**
     * The rotation of the corner p of a sub-triangle with counterclockwise
     * corners @p order, for the corners with the vertices @p nodes of S_h
     * (and their weights): +weight through the edge that enters p, −weight
     * through the one that leaves it, added to the entry of p in
     * [@p first_entry, end) of @p entries or to a new one.
     */
    void
    add_rotation_entries(const CornerNodes                 &nodes,
                         const std::array<unsigned int, 3> &n_nodes_of,
                         const std::array<unsigned int, 3> &order,
                         const unsigned int                 kappa,
                         const std::size_t                  first_entry,
                         std::vector<RotationEntry>        &entries)
    {
      for (unsigned int k = 0; k < 3; ++k)
        {
          // Corner order[k] is p, order[k−1] before and order[k+1] after
          // it: the edge entering p is opposite order[k+1].
          const unsigned int before = order[(k + 2) % 3], corner = order[k],
                             after = order[(k + 1) % 3];
          for (unsigned int n = 0; n < n_nodes_of[corner]; ++n)
            {
              const auto [node, weight] = nodes[corner][n];
              auto entry = std::find_if(entries.begin() + first_entry,
                                        entries.end(),
                                        [node = node](const RotationEntry &e) {
                                          return e.node == node;
                                        });
              if (entry == entries.end())
                entry =
                  entries.insert(entries.end(), RotationEntry{node, kappa, {}});
              entry->u[after] += weight;
              entry->u[before] -= weight;
            }
        }
    }
  } // namespace



  /**
   * The rotations of relax_rotations(), vertex by vertex in the order of
   * the sweeps, and the vertices of each kind (0: regular vertex, 1: m_e,
   * 2: b_K, 3: hanging vertex).
   */
  template <int dim>
  struct FluxEquilibration<dim>::Rotations
  {
    std::vector<Rotation>                      rotations;
    std::array<std::vector<RotationVertex>, 4> vertices_of_kind;
    /** The kinds in the order of a sweep. */
    static constexpr std::array<unsigned int, 4> sweep_order{{2, 1, 0, 3}};
  };



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
  FluxEquilibration<dim>::relax_rotations(const DoFHandler<dim> &dof_handler)
  {
    Rotations          rotations   = rotations_around_vertices(dof_handler);
    const unsigned int n_triangles = basis.n_sub_triangles();
    // σ_ih of the sub-triangles of a cell, from its owner to its ghosts.
    using CellFluxes    = std::vector<Fluxes>;
    const auto first_of = [&](const auto &cell) {
      return sigma.begin() + cell->active_cell_index() * n_triangles;
    };
    for (unsigned int sweep = 0; sweep < rotation_sweeps; ++sweep)
      for (const unsigned int kind : Rotations::sweep_order)
        {
          GridTools::exchange_cell_data_to_ghosts<CellFluxes, DoFHandler<dim>>(
            dof_handler,
            [&](const auto &cell) {
              return CellFluxes(first_of(cell), first_of(cell) + n_triangles);
            },
            [&](const auto &cell, const CellFluxes &fluxes) {
              std::copy(fluxes.begin(), fluxes.end(), first_of(cell));
            });
          for_each_vertex(rotations.vertices_of_kind[kind],
                          [&](const RotationVertex &p) {
                            const auto           &all = rotations.rotations;
                            std::array<double, 2> numerator{};
                            for (unsigned int t = p.begin; t < p.end; ++t)
                              {
                                const Fluxes &F = sigma[all[t].kappa];
                                for (unsigned int i = 0; i < 2; ++i)
                                  {
                                    numerator[i] += all[t].ug[i];
                                    for (unsigned int k = 0; k < 3; ++k)
                                      numerator[i] += all[t].Gu[k] * F[i][k];
                                  }
                              }
                            for (unsigned int i = 0; i < 2; ++i)
                              {
                                const double c = -numerator[i] / p.denominator;
                                for (unsigned int t = p.begin; t < p.end; ++t)
                                  for (unsigned int k = 0; k < 3; ++k)
                                    sigma[all[t].kappa][i][k] +=
                                      c * all[t].u[k];
                              }
                          });
        }
  }



  /**
   * The vertices p of S_h are numbered: the vertices of the mesh first,
   * then the faces (their midpoints m_e), then the cells (b_K). At an edge
   * with a hanging vertex c the stream function is continuous on S_h: the
   * coarse side's m_e is c, and on the fine side the midpoint of each small
   * edge takes half of the hat functions of its two ends.
   *
   * The vertices of each kind are taken in the order in which the cells
   * meet them first, so that a sweep runs through the sub-triangles nearly
   * in order. The Gram matrices are symmetric, so u_κ·(G_κ F_κ) =
   * (G_κ u_κ)·F_κ: with G_κ u_κ and u_κ·g_κ of each rotation and
   * Σ_κ u_κ·G_κ u_κ of each vertex computed here, a sweep reads only the
   * fluxes F_κ.
   */
  template <int dim>
  typename FluxEquilibration<dim>::Rotations
  FluxEquilibration<dim>::rotations_around_vertices(
    const DoFHandler<dim> &dof_handler) const
  {
    const auto        &triangles     = basis.sub_triangles();
    const unsigned int n_triangles   = triangles.size();
    const auto         order         = counterclockwise_corners(triangles);
    const auto        &triangulation = dof_handler.get_triangulation();
    const unsigned int n_vertices    = triangulation.n_vertices();
    const unsigned int first_cell    = n_vertices + triangulation.n_raw_faces();
    const unsigned int n_nodes = first_cell + triangulation.n_active_cells();
    std::vector<RotationEntry> entries;
    entries.reserve(triangulation.n_active_cells() * n_triangles * 3);
    std::vector<char> owned(n_nodes, 0), on_boundary(n_nodes, 0);
    std::vector<char> hanging(n_vertices, 0);
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (!cell->is_artificial())
        for (const unsigned int f : cell->face_indices())
          if (!cell->at_boundary(f) && cell->face(f)->has_children())
            hanging[cell->face(f)->child(0)->vertex_index(1)] = 1;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (!cell->is_artificial())
        for (unsigned int s = 0; s < n_triangles; ++s)
          {
            const bool boundary = cell->at_boundary(triangles[s].face);
            const auto [nodes, n_nodes_of] =
              sub_mesh_vertices(cell, triangles[s], n_vertices, first_cell);
            for (unsigned int corner = 0; corner < 3; ++corner)
              for (unsigned int n = 0; n < n_nodes_of[corner]; ++n)
                {
                  const unsigned int node = nodes[corner][n].first;
                  owned[node] |= cell->is_locally_owned();
                  // p on ∂ω: a vertex of a boundary edge, or its m_e.
                  on_boundary[node] |= boundary && corner != 2;
                }
            add_rotation_entries(nodes,
                                 n_nodes_of,
                                 order[s],
                                 cell->active_cell_index() * n_triangles + s,
                                 entries.size(),
                                 entries);
          }

    std::array<std::vector<unsigned int>, 4> of_kind;
    std::vector<unsigned int>                count(n_nodes, 0);
    for (const RotationEntry &entry : entries)
      if (const unsigned int node = entry.node;
          owned[node] && !on_boundary[node] && count[node]++ == 0)
        of_kind[node < n_vertices ? (hanging[node] ? 3 : 0) :
                node < first_cell ? 1 :
                                    2]
          .push_back(node);
    Rotations                 result;
    std::vector<unsigned int> next(n_nodes, 0);
    unsigned int              n_rotations = 0;
    for (const unsigned int kind : Rotations::sweep_order)
      for (const unsigned int node : of_kind[kind])
        {
          next[node] = n_rotations;
          result.vertices_of_kind[kind].push_back(
            {n_rotations, n_rotations + count[node], 0.});
          n_rotations += count[node];
        }
    result.rotations.resize(n_rotations);
    for (const RotationEntry &entry : entries)
      if (count[entry.node] > 0)
        result.rotations[next[entry.node]++] = {entry.kappa, entry.u, {}, {}};
    for (const unsigned int kind : Rotations::sweep_order)
      for_each_vertex(result.vertices_of_kind[kind], [&](RotationVertex &p) {
        for (unsigned int t = p.begin; t < p.end; ++t)
          {
            Rotation   &rotation = result.rotations[t];
            const auto &kappa = reconstruction.sub_triangles()[rotation.kappa];
            // Gu and ug start at zero.
            for (unsigned int k = 0; k < 3; ++k)
              for (unsigned int l = 0; l < 3; ++l)
                rotation.Gu[k] += kappa.gram[k][l] * rotation.u[l];
            for (unsigned int i = 0; i < 2; ++i)
              for (unsigned int k = 0; k < 3; ++k)
                rotation.ug[i] += rotation.u[k] * kappa.discrete_flux[i][k];
            for (unsigned int k = 0; k < 3; ++k)
              p.denominator += rotation.u[k] * rotation.Gu[k];
          }
      });
    return result;
  }



  /**
   * The rotations of relax_rotations() are the curls of the piecewise
   * linear stream functions on S_h: constant fields on each sub-triangle.
   * On a quadrilateral −μ_i ∇u_ih also has the bilinear part
   * μ_i ∂_xy u_ih (y, x) (on a parallelogram, in its axes), which is the
   * curl of the quadratic μ_i ∂_xy u_ih (y² − x²)/2 and which no RT0 field
   * of the sub-triangles follows. The quadratic edge bubbles 4 λ_p λ_q of
   * the edges of S_h through b_K (from b_K to the vertices a and to the
   * midpoints m_e) vanish on the boundary of the cell, so their curls β
   * are fields without divergence and without normal flux through the
   * cell's boundary: adding them keeps σ_ih in H(div) with the same
   * divergence and the same fluxes through every edge of S_h, and the
   * flux estimator remains a bound. On each cell the coefficients b
   * minimize ‖μ_i^{-1/2} (σ_ih + Σ_l b_l β_l) + μ_i^{1/2} ∇u_ih‖_K: with
   * the Gram matrix (β_l, β_m) of the bubbles, the mixed products
   * (ψ_k, β_l) with the Raviart–Thomas basis and the products
   * g = (μ_i ∇u_ih, β_l), a system (β_l, β_m) b = −((ψ_k, β_l)ᵀ F + g) of
   * 8 (Q1) or 6 (P1) unknowns per cell and membrane. The cells are
   * independent, so no data of other processes is needed.
   */
  template <int dim>
  void
  FluxEquilibration<dim>::relax_cell_rotations(
    const DoFHandler<dim> &dof_handler)
  {
    const auto        &triangles   = basis.sub_triangles();
    const unsigned int n_triangles = triangles.size();
    const unsigned int n_vertices =
      dof_handler.get_fe().reference_cell().n_vertices();
    // The bubble of edge 0 of κ (from m_e to b_K) is unknown n_vertices + e,
    // that of edge 1 (from a to b_K) unknown a.
    const auto unknown = [&](const unsigned int s, const unsigned int l) {
      return l == 0 ? n_vertices + triangles[s].face : triangles[s].vertex;
    };
    FullMatrix<double>            bubble_gram(2 * n_vertices);
    const Vector<double>          zero(2 * n_vertices);
    std::array<Vector<double>, 2> right_hand_side{{zero, zero}},
      coefficients{{zero, zero}};
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          const unsigned int first = cell->active_cell_index() * n_triangles;
          const auto *const  kappa = &reconstruction.sub_triangles()[first];
          bubble_gram              = 0;
          for (unsigned int i = 0; i < 2; ++i)
            right_hand_side[i] = 0;
          for (unsigned int s = 0; s < n_triangles; ++s)
            for (unsigned int l = 0; l < 2; ++l)
              {
                for (unsigned int m = 0; m < 2; ++m)
                  bubble_gram(unknown(s, l), unknown(s, m)) +=
                    kappa[s].rotation_gram[l][m];
                for (unsigned int i = 0; i < 2; ++i)
                  {
                    double residual = kappa[s].discrete_rotation[i][l];
                    for (unsigned int k = 0; k < 3; ++k)
                      residual +=
                        kappa[s].mixed_gram[k][l] * sigma[first + s][i][k];
                    right_hand_side[i](unknown(s, l)) -= residual;
                  }
              }
          bubble_gram.gauss_jordan();
          for (unsigned int i = 0; i < 2; ++i)
            {
              bubble_gram.vmult(coefficients[i], right_hand_side[i]);
              for (unsigned int s = 0; s < n_triangles; ++s)
                for (unsigned int l = 0; l < 2; ++l)
                  cell_rotations[first + s][i][l] =
                    coefficients[i](unknown(s, l));
            }
        }
  }



  template void
  FluxEquilibration<2>::relax_rotations(const DoFHandler<2> &);
  template void
  FluxEquilibration<2>::relax_cell_rotations(const DoFHandler<2> &);
} // namespace membranes
