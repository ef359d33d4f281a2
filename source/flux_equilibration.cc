#include <algorithm>
#include <deal.II/base/mpi.h>
#include <deal.II/base/parallel.h>
#include <deal.II/distributed/tria_base.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/lapack_full_matrix.h>
#include <deal.II/lac/vector.h>
#include <map>
#include <membranes/cell_loop.h>
#include <membranes/flux_reconstruction.h>
#include <tuple>

// The patch equilibration of σ_ih = Σ_a σ_ih^a and its divergence-free
// corrections (see the class comment of FluxReconstruction); the fluxes
// t_ih of (4.13), their identities and the output of the dual mesh are in
// flux_reconstruction.cc.

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
  } // namespace



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
        /**
         * The EdgeKey of the unknown flux through edge 2 (two global DoF
         * indices, exact as doubles).
         */
        key_first,
        key_second,
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
      types::global_dof_index first, second;
      unsigned int            cell, s;
    };
  } // namespace



  /**
   * The work arrays of solve_patch_problem(), kept from one patch to the
   * next.
   */
  template <int dim>
  struct FluxReconstruction<dim>::PatchScratch
  {
    std::vector<PatchKey>                        keys;
    std::vector<std::pair<unsigned int, double>> unknown_of;
    std::vector<std::array<double, 2>>           source, known, mean, change;
    std::vector<double>                          weight;
    std::vector<std::array<std::array<double, 3>, 2>> target;
    FullMatrix<double>                                matrix;
    std::array<Vector<double>, 2>                     rhs;
    SaddlePointScratch                                saddle_point;
  };



  template <int dim>
  void
  FluxReconstruction<dim>::write_patch_record(
    const CellIterator              &cell,
    const std::array<double, 4>     &coefficients,
    const AlignedVector<PatchTerms> &patch_terms,
    double                          *record) const
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

        record[key_first]           = terms.key[0];
        record[key_second]          = terms.key[1];
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
    const AlignedVector<PatchTerms> &patch_terms,
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
    // local_patches if this process owns a (sorted by a below, the cells
    // of one a in the order of the cells), else to be sent to a's owner.
    using Coefficients =
      std::array<double, GeometryInfo<dim>::vertices_per_cell>;
    struct PatchMember
    {
      types::global_dof_index a;
      CellIterator            cell;
      Coefficients            coefficients;
    };
    std::vector<PatchMember> local_patches;
    local_patches.reserve(dof_handler->get_triangulation().n_active_cells() *
                          GeometryInfo<dim>::vertices_per_cell);
    std::vector<std::tuple<CellIterator, types::global_dof_index, Coefficients>>
                                         remote;
    std::vector<types::global_dof_index> remote_vertices;
    // The condensed hat functions of one cell, by increasing a: at most two
    // parents for each vertex.
    std::vector<std::pair<types::global_dof_index, Coefficients>> of_cell;
    for (const auto &cell : dof_handler->active_cell_iterators())
      if (cell->is_locally_owned())
        {
          of_cell.clear();
          const auto add = [&](const types::global_dof_index a,
                               const unsigned int            v,
                               const double                  weight) {
            auto entry =
              std::find_if(of_cell.begin(), of_cell.end(), [a](const auto &e) {
                return e.first == a;
              });
            if (entry == of_cell.end())
              entry = of_cell.insert(of_cell.end(), {a, Coefficients{}});
            entry->second[v] += weight;
          };
          for (const unsigned int v : cell->vertex_indices())
            {
              const auto dof = cell->vertex_dof_index(v, 0);
              if (const auto *entries =
                    hanging_node_constraints.get_constraint_entries(dof))
                for (const auto &[parent, weight] : *entries)
                  add(parent, v, weight);
              else
                add(dof, v, 1);
            }
          std::sort(of_cell.begin(),
                    of_cell.end(),
                    [](const auto &p, const auto &q) {
                      return p.first < q.first;
                    });
          for (const auto &[a, coefficients] : of_cell)
            if (locally_owned_dofs.is_element(a))
              local_patches.push_back({a, cell, coefficients});
            else
              {
                remote.emplace_back(cell, a, coefficients);
                remote_vertices.push_back(a);
              }
        }
    std::stable_sort(local_patches.begin(),
                     local_patches.end(),
                     [](const PatchMember &p, const PatchMember &q) {
                       return p.a < q.a;
                     });
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

    // The patch problems on threads, σ_ih = Σ_a σ_ih^a on the owned cells
    // added by the copier in the order of the patches. A patch is the run
    // of members with the same a in local_patches, from one of
    // patch_starts to the next.
    for (auto &kappa : sub_triangle_data)
      kappa.equilibrated = {};
    std::vector<unsigned int> patch_starts;
    for (unsigned int k = 0; k < local_patches.size(); ++k)
      if (k == 0 || local_patches[k].a != local_patches[k - 1].a)
        patch_starts.push_back(k);
    patch_starts.push_back(local_patches.size());
    struct PatchWork
    {
      PatchScratch                scratch;
      std::vector<double>         records;
      std::vector<const double *> patch;
      std::vector<double *>       result;
    };
    struct PatchResult
    {
      unsigned int        first = 0, n_cells = 0;
      std::vector<double> results;
    };
    run_in_order<PatchResult>(
      patch_starts.cbegin(),
      patch_starts.cend() - 1,
      []() { return std::make_unique<PatchWork>(); },
      [&](const std::vector<unsigned int>::const_iterator &start,
          PatchWork                                       &work,
          PatchResult                                     &out) {
        out.first                       = start[0];
        out.n_cells                     = start[1] - start[0];
        const types::global_dof_index a = local_patches[out.first].a;
        work.records.resize(out.n_cells * record_size);
        out.results.assign(out.n_cells * result_size, 0.);
        work.patch.clear();
        work.result.clear();
        for (unsigned int c = 0; c < out.n_cells; ++c)
          {
            const PatchMember &member = local_patches[out.first + c];
            write_patch_record(member.cell,
                               member.coefficients,
                               patch_terms,
                               work.records.data() + c * record_size);
            work.patch.push_back(work.records.data() + c * record_size);
            work.result.push_back(out.results.data() + c * result_size);
          }
        if (const auto members = remote_members.find(a);
            members != remote_members.end())
          for (const auto &[process, r] : members->second)
            {
              work.patch.push_back(received.at(process).data() +
                                   r * (1 + record_size) + 1);
              work.result.push_back(replies.at(process).data() +
                                    r * result_size);
            }
        solve_patch_problem(a, work.patch, work.result, work.scratch);
      },
      [&](const PatchResult &out) {
        for (unsigned int c = 0; c < out.n_cells; ++c)
          add_patch_result(local_patches[out.first + c].cell,
                           out.results.data() + c * result_size);
      });
    for (const auto &[process, buffer] :
         Utilities::MPI::some_to_some(mpi_communicator, replies))
      for (unsigned int r = 0; r < sent[process].size(); ++r)
        add_patch_result(sent[process][r], buffer.data() + r * result_size);
    relax_rotations();
    relax_cell_rotations();
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
    // The vertices of each kind (0: regular vertex, 1: m_e, 2: b_K, 3:
    // hanging vertex; two of one kind share no sub-triangle) in the order
    // in which the cells meet them first, so that a sweep runs through
    // the sub-triangles nearly in order, and their entries, vertex by
    // vertex in the order of the sweeps. The Gram matrices are symmetric,
    // so u_κ·(G_κ F_κ) = (G_κ u_κ)·F_κ: with G_κ u_κ and u_κ·g_κ of each
    // entry and Σ_κ u_κ·G_κ u_κ of each vertex computed once, a sweep reads
    // only the fluxes F_κ.
    std::array<std::vector<unsigned int>, 4> of_kind;
    std::vector<unsigned int>                count(n_nodes, 0);
    for (const Entry &entry : entries)
      if (const unsigned int node = entry.node;
          owned[node] && !on_boundary[node] && count[node]++ == 0)
        of_kind[node < n_vertices ? (hanging[node] ? 3 : 0) :
                node < first_cell ? 1 :
                                    2]
          .push_back(node);
    struct Rotation
    {
      unsigned int          kappa;
      std::array<double, 3> u, Gu;
      std::array<double, 2> ug;
    };
    struct Vertex
    {
      unsigned int begin, end;
      double       denominator;
    };
    const std::array<unsigned int, 4>  sweep_order{{2, 1, 0, 3}};
    std::array<std::vector<Vertex>, 4> vertices_of_kind;
    std::vector<unsigned int>          next(n_nodes, 0);
    unsigned int                       n_rotations = 0;
    for (const unsigned int kind : sweep_order)
      for (const unsigned int node : of_kind[kind])
        {
          next[node] = n_rotations;
          vertices_of_kind[kind].push_back(
            {n_rotations, n_rotations + count[node], 0.});
          n_rotations += count[node];
        }
    std::vector<Rotation> rotations(n_rotations);
    for (const Entry &entry : entries)
      if (count[entry.node] > 0)
        {
          Rotation &rotation = rotations[next[entry.node]++];
          rotation.kappa     = entry.kappa;
          rotation.u         = entry.u;
        }
    // The vertices of one kind share no sub-triangle: each loop over them
    // below runs on threads, on disjoint entries of rotations and sigma,
    // with the same result as in order.
    const auto for_vertices_of_kind = [&](const unsigned int kind,
                                          const auto        &f) {
      std::vector<Vertex> &vertices = vertices_of_kind[kind];
      parallel::apply_to_subranges(
        vertices.begin(),
        vertices.end(),
        [&](const auto begin, const auto end) {
          for (auto p = begin; p != end; ++p)
            f(*p);
        },
        1000);
    };
    for (const unsigned int kind : sweep_order)
      for_vertices_of_kind(kind, [&](Vertex &p) {
        for (unsigned int t = p.begin; t < p.end; ++t)
          {
            Rotation              &rotation = rotations[t];
            const SubTriangleData &kappa    = sub_triangle_data[rotation.kappa];
            for (unsigned int k = 0; k < 3; ++k)
              {
                rotation.Gu[k] = 0;
                for (unsigned int l = 0; l < 3; ++l)
                  rotation.Gu[k] += kappa.gram[k][l] * rotation.u[l];
              }
            for (unsigned int i = 0; i < 2; ++i)
              {
                rotation.ug[i] = 0;
                for (unsigned int k = 0; k < 3; ++k)
                  rotation.ug[i] += rotation.u[k] * kappa.discrete_flux[i][k];
              }
            for (unsigned int k = 0; k < 3; ++k)
              p.denominator += rotation.u[k] * rotation.Gu[k];
          }
      });

    // The sweeps work on a copy of the fluxes of σ_ih alone (48 bytes per
    // sub-triangle, in the order of sub_triangle_data), which the caches
    // hold far better than sub_triangle_data itself.
    using Fluxes = std::array<std::array<double, 3>, 2>;
    std::vector<Fluxes> sigma(sub_triangle_data.size());
    for (unsigned int id = 0; id < sigma.size(); ++id)
      sigma[id] = sub_triangle_data[id].equilibrated;

    // σ_ih of the owned cells to the ghost cells of the other processes.
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
            fluxes[s] = sigma[cell->active_cell_index() * n_triangles + s];
          return std::optional<std::vector<Fluxes>>(fluxes);
        },
        [&](const CellIterator &cell, const std::vector<Fluxes> &fluxes) {
          for (unsigned int s = 0; s < n_triangles; ++s)
            sigma[cell->active_cell_index() * n_triangles + s] = fluxes[s];
        });
    };

    for (unsigned int sweep = 0; sweep < rotation_sweeps; ++sweep)
      for (const unsigned int kind : sweep_order)
        {
          exchange();
          for_vertices_of_kind(kind, [&](const Vertex &p) {
            std::array<double, 2> numerator{};
            for (unsigned int t = p.begin; t < p.end; ++t)
              {
                const Rotation &rotation = rotations[t];
                const Fluxes   &F        = sigma[rotation.kappa];
                for (unsigned int i = 0; i < 2; ++i)
                  {
                    numerator[i] += rotation.ug[i];
                    for (unsigned int k = 0; k < 3; ++k)
                      numerator[i] += rotation.Gu[k] * F[i][k];
                  }
              }
            for (unsigned int i = 0; i < 2; ++i)
              {
                const double c = -numerator[i] / p.denominator;
                for (unsigned int t = p.begin; t < p.end; ++t)
                  for (unsigned int k = 0; k < 3; ++k)
                    sigma[rotations[t].kappa][i][k] += c * rotations[t].u[k];
              }
          });
        }
    for (unsigned int id = 0; id < sigma.size(); ++id)
      sub_triangle_data[id].equilibrated = sigma[id];
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
   * the Gram matrices of the sub-triangles, a system B b = −(Mᵀ F + g) of
   * 8 (Q1) or 6 (P1) unknowns per cell and membrane. The cells are
   * independent, so no data of other processes is needed.
   */
  template <int dim>
  void
  FluxReconstruction<dim>::relax_cell_rotations()
  {
    const auto        &triangles   = dual_cell_quadrature.sub_triangles();
    const unsigned int n_triangles = triangles.size();
    const unsigned int n_vertices =
      dof_handler->get_fe().reference_cell().n_vertices();
    // The bubble of edge 0 of κ (from m_e to b_K) is unknown n_vertices + e,
    // that of edge 1 (from a to b_K) unknown a.
    const auto unknown = [&](const unsigned int s, const unsigned int l) {
      return l == 0 ? n_vertices + triangles[s].face : triangles[s].vertex;
    };
    FullMatrix<double>            matrix(2 * n_vertices);
    std::array<Vector<double>, 2> right_hand_side, coefficients;
    for (unsigned int i = 0; i < 2; ++i)
      {
        right_hand_side[i].reinit(2 * n_vertices);
        coefficients[i].reinit(2 * n_vertices);
      }
    for (const auto &cell : dof_handler->active_cell_iterators())
      if (cell->is_locally_owned())
        {
          SubTriangleData *kappa =
            sub_triangle_data.data() + cell->active_cell_index() * n_triangles;
          matrix = 0;
          for (unsigned int i = 0; i < 2; ++i)
            right_hand_side[i] = 0;
          for (unsigned int s = 0; s < n_triangles; ++s)
            for (unsigned int l = 0; l < 2; ++l)
              {
                for (unsigned int m = 0; m < 2; ++m)
                  matrix(unknown(s, l), unknown(s, m)) +=
                    kappa[s].rotation_gram[l][m];
                for (unsigned int i = 0; i < 2; ++i)
                  {
                    double residual = kappa[s].discrete_rotation[i][l];
                    for (unsigned int k = 0; k < 3; ++k)
                      residual +=
                        kappa[s].mixed_gram[k][l] * kappa[s].equilibrated[i][k];
                    right_hand_side[i](unknown(s, l)) -= residual;
                  }
              }
          matrix.gauss_jordan();
          for (unsigned int i = 0; i < 2; ++i)
            {
              matrix.vmult(coefficients[i], right_hand_side[i]);
              for (unsigned int s = 0; s < n_triangles; ++s)
                for (unsigned int l = 0; l < 2; ++l)
                  kappa[s].rotations[i][l] = coefficients[i](unknown(s, l));
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
        keys.push_back(
          {static_cast<types::global_dof_index>(entry(s, key_first)),
           static_cast<types::global_dof_index>(entry(s, key_second)),
           s / n_ring,
           s});
    std::sort(keys.begin(), keys.end(), [](const auto &p, const auto &q) {
      return std::tie(p.first, p.second, p.cell) <
             std::tie(q.first, q.second, q.cell);
    });
    auto &unknown_of = scratch.unknown_of;
    unknown_of.assign(n_sub, {invalid, 0.});
    unsigned int n_x = 0;
    for (unsigned int begin = 0, end; begin < keys.size(); begin = end)
      {
        for (end = begin + 1;
             end < keys.size() && keys[end].first == keys[begin].first &&
             keys[end].second == keys[begin].second;
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
    // cells, the mean of both sides. On the fine side of an edge with a
    // hanging node, the two halves of a small edge share one unknown, so
    // their targets take one density: the flux this moves between the two
    // sub-triangles of the face goes back through their common edge 0
    // (m_e–b_K), half of the difference of the changes from each side,
    // which keeps the target conforming inside the cell. The targets are
    // then conforming, and where u_ih is linear they satisfy the
    // constraints (through a small edge the one-sided fluxes of the fine
    // side add up to the coarse side's, so the two changes are opposite):
    // σ_ih^a is its target, and σ_ih = −μ_i ∇u_ih, also with hanging nodes.
    auto &target = scratch.target;
    target.resize(n_sub);
    {
      auto &mean   = scratch.mean;
      auto &weight = scratch.weight;
      auto &change = scratch.change;
      mean.assign(n_x, {});
      weight.assign(n_x, 0.);
      change.resize(n_sub);
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
            const double flux =
              (x != invalid ? f * mean[x][i] / weight[x] : known[s][i]);
            change[s][i]    = flux - target[s][i][2];
            target[s][i][2] = flux;
          }
      // ring[j] and ring[j + 1], j even, share edge 0 and lie on one face.
      for (unsigned int s = 0; s < n_sub; s += 2)
        if (std::abs(entry(s, factor)) == 0.5)
          for (unsigned int i = 0; i < 2; ++i)
            {
              const double back = (change[s][i] - change[s + 1][i]) / 2;
              target[s][i][0] -= back;
              target[s + 1][i][0] += back;
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
    // degenerate patch, LU with pivoting does. (LU of LAPACKFullMatrix on
    // every patch takes 1.6 times the instructions: measured with
    // callgrind on case M, 5 cycles on Q1 and 4 on P1.)
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



  template void
  FluxReconstruction<2>::equilibrate(const AlignedVector<PatchTerms> &,
                                     const AffineConstraints<double> &,
                                     const IndexSet &,
                                     const MPI_Comm);
} // namespace membranes
