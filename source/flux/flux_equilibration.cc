#include <algorithm>
#include <deal.II/base/mpi.h>
#include <membranes/flux/flux_equilibration.h>
#include <membranes/mesh/cell_loop.h>

// The patch equilibration σ_ih = Σ_a σ_ih^a (see the class comment of
// FluxEquilibration): which cells belong to which patch, the records of
// their sub-triangles, their exchange between processes, and the patch
// problems on threads. The patch problem itself is PatchProblem.

namespace membranes
{
  template <int dim>
  struct FluxEquilibration<dim>::PatchScratch
  {
    explicit PatchScratch(const unsigned int n_ring)
      : problem(n_ring)
    {}

    PatchProblem                     problem;
    std::vector<PatchRecord>         records;
    std::vector<const PatchRecord *> patch;
    std::vector<double *>            result;
  };



  /**
   * σ_ih^a of one patch on its owned cells: the members
   * local_members[first, first + n_cells) and their fluxes, 6 per
   * sub-triangle of the ring.
   */
  template <int dim>
  struct FluxEquilibration<dim>::PatchCopy
  {
    unsigned int        first = 0, n_cells = 0;
    std::vector<double> results;
  };



  template <int dim>
  void
  FluxEquilibration<dim>::flux_values(const CellIterator          &cell,
                                      const unsigned int           i,
                                      const FEValues<dim>         &fe_values,
                                      std::vector<Tensor<1, dim>> &flux,
                                      std::vector<double> &divergence) const
  {
    const DualCellQuadrature<dim> &dual_cell_quadrature =
      basis.dual_quadrature();
    const auto        &quadrature  = dual_cell_quadrature.quadrature();
    const auto        &triangles   = dual_cell_quadrature.sub_triangles();
    const unsigned int n_triangles = triangles.size();
    flux.resize(quadrature.size());
    divergence.resize(quadrature.size());
    for (unsigned int q = 0; q < quadrature.size(); ++q)
      {
        const unsigned int   s  = dual_cell_quadrature.sub_triangle_of_point(q);
        const unsigned int   id = cell->active_cell_index() * n_triangles + s;
        const auto          &f  = sigma[id][i];
        const Tensor<2, dim> DF = fe_values.jacobian(q);
        const double         det = std::abs(determinant(DF));
        Tensor<1, dim>       reference =
          basis.reference_flux(s, f, quadrature.point(q));
        for (unsigned int l = 0; l < 2; ++l)
          reference += cell_rotations[id][i][l] * basis.rotation_basis(q)[l];
        flux[q]       = DF * reference / det;
        divergence[q] = (f[0] + f[1] + f[2]) / (triangles[s].area * det);
      }
  }



  template <int dim>
  void
  FluxEquilibration<dim>::write_patch_record(
    const CellIterator              &cell,
    const types::global_dof_index    a,
    const HatCoefficients           &coefficients,
    const AlignedVector<PatchTerms> &patch_terms,
    PatchRecord                     *record) const
  {
    constexpr unsigned int n_vertices  = GeometryInfo<dim>::vertices_per_cell;
    const auto            &ring        = basis.ring();
    const unsigned int     n_triangles = basis.n_sub_triangles();
    for (unsigned int j = 0; j < ring.size(); ++j, ++record)
      {
        const unsigned int id =
          cell->active_cell_index() * n_triangles + ring[j];
        const auto       &kappa = reconstruction.sub_triangles()[id];
        const PatchTerms &terms = patch_terms[id];

        *record             = PatchRecord{};
        record->vertex      = a;
        record->key         = terms.key;
        record->factor      = terms.factor;
        record->on_boundary = terms.on_boundary;
        for (unsigned int k = 0, n = 0; k < 3; ++k)
          for (unsigned int l = k; l < 3; ++l, ++n)
            record->gram[n] = kappa.gram[k][l];
        record->area = kappa.area;
        for (unsigned int v = 0; v < n_vertices; ++v)
          if (coefficients[v] != 0)
            {
              record->mass += coefficients[v] * terms.hat_mass[v];
              for (unsigned int i = 0; i < 2; ++i)
                record->residual[i] +=
                  coefficients[v] * terms.hat_residual[i][v];
            }
        // φ_a at the Gauss points of the edges of κ.
        for (unsigned int e = 0; e < 3; ++e)
          for (unsigned int k = 0; k < 2; ++k)
            {
              double phi = 0;
              for (unsigned int v = 0; v < n_vertices; ++v)
                phi +=
                  coefficients[v] * basis.edge_shape_value(ring[j], e, k, v);
              for (unsigned int i = 0; i < 2; ++i)
                record->edge_flux[i][e] -= phi * terms.edge_flux[i][e][k];
              if (e == 2)
                record->boundary_mass += phi * terms.boundary_length[k];
            }
      }
  }



  template <int dim>
  void
  FluxEquilibration<dim>::equilibrate(
    const DoFHandler<dim>           &dof_handler,
    const AlignedVector<PatchTerms> &patch_terms,
    const VectorType                &lambda_h,
    const AffineConstraints<double> &hanging_node_constraints,
    const IndexSet                  &locally_owned_dofs,
    const MPI_Comm                   mpi_communicator)
  {
    // The members of the patches of the owned vertices, sorted by a (the
    // cells of one a in the order of the cells), and the others, to be
    // sent to a's owner.
    std::vector<PatchMember> local_members, remote_members;
    for (const PatchMember &member :
         patch_members(dof_handler, hanging_node_constraints))
      (locally_owned_dofs.is_element(member.a) ? local_members : remote_members)
        .push_back(member);
    std::stable_sort(local_members.begin(),
                     local_members.end(),
                     [](const PatchMember &p, const PatchMember &q) {
                       return p.a < q.a;
                     });
    RemotePatches remote = send_patch_records(remote_members,
                                              patch_terms,
                                              locally_owned_dofs,
                                              mpi_communicator);

    const unsigned int n_sub_triangles = reconstruction.sub_triangles().size();
    sigma.assign(n_sub_triangles, Fluxes{});
    cell_rotations.assign(n_sub_triangles, {});
    solve_patches(local_members, patch_terms, lambda_h, remote);
    for (const auto &[process, buffer] :
         Utilities::MPI::some_to_some(mpi_communicator, remote.replies))
      for (unsigned int r = 0; r < remote.sent[process].size(); ++r)
        add_patch_result(remote.sent[process][r],
                         buffer.data() + r * 6 * basis.ring().size());
    relax_rotations(dof_handler);
    relax_cell_rotations(dof_handler);
  }



  template <int dim>
  std::vector<typename FluxEquilibration<dim>::PatchMember>
  FluxEquilibration<dim>::patch_members(
    const DoFHandler<dim>           &dof_handler,
    const AffineConstraints<double> &hanging_node_constraints) const
  {
    std::vector<PatchMember> members;
    members.reserve(dof_handler.get_triangulation().n_active_cells() *
                    GeometryInfo<dim>::vertices_per_cell);
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          // The condensed hat functions of the cell, by increasing a.
          std::map<types::global_dof_index, HatCoefficients> of_cell;
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
            members.push_back({a, cell, coefficients});
        }
    return members;
  }



  template <int dim>
  typename FluxEquilibration<dim>::RemotePatches
  FluxEquilibration<dim>::send_patch_records(
    const std::vector<PatchMember>  &remote_members,
    const AlignedVector<PatchTerms> &patch_terms,
    const IndexSet                  &locally_owned_dofs,
    const MPI_Comm                   mpi_communicator) const
  {
    const unsigned int n_ring = basis.ring().size();
    IndexSet           remote_set(locally_owned_dofs.size());
    for (const PatchMember &member : remote_members)
      remote_set.add_index(member.a);
    remote_set.compress();
    const std::vector<unsigned int> owners =
      Utilities::MPI::compute_index_owner(locally_owned_dofs,
                                          remote_set,
                                          mpi_communicator);
    RemotePatches                                    remote;
    std::map<unsigned int, std::vector<PatchRecord>> records;
    for (const auto &[a, cell, coefficients] : remote_members)
      {
        const unsigned int owner = owners[remote_set.index_within_set(a)];
        std::vector<PatchRecord> &buffer = records[owner];
        buffer.resize(buffer.size() + n_ring);
        write_patch_record(
          cell, a, coefficients, patch_terms, &*(buffer.end() - n_ring));
        remote.sent[owner].push_back(cell);
      }

    // The records of the owned vertices from other processes, and the
    // buffers for the answers: σ_ih^a on their sub-triangles.
    remote.received = Utilities::MPI::some_to_some(mpi_communicator, records);
    for (const auto &[process, buffer] : remote.received)
      {
        const unsigned int n_records = buffer.size() / n_ring;
        remote.replies[process].assign(n_records * 6 * n_ring, 0.);
        for (unsigned int r = 0; r < n_records; ++r)
          remote.members[buffer[r * n_ring].vertex].emplace_back(process, r);
      }
    return remote;
  }



  template <int dim>
  void
  FluxEquilibration<dim>::solve_patches(
    const std::vector<PatchMember>  &local_members,
    const AlignedVector<PatchTerms> &patch_terms,
    const VectorType                &lambda_h,
    RemotePatches                   &remote)
  {
    // A patch is the run of members with the same a in local_members, from
    // one of patch_starts to the next. The patch problems run on threads,
    // and σ_ih = Σ_a σ_ih^a on the owned cells is added by the copier in
    // the order of the patches.
    const unsigned int        n_ring = basis.ring().size();
    std::vector<unsigned int> patch_starts;
    for (unsigned int k = 0; k < local_members.size(); ++k)
      if (k == 0 || local_members[k].a != local_members[k - 1].a)
        patch_starts.push_back(k);
    patch_starts.push_back(local_members.size());
    run_in_order<PatchCopy>(
      patch_starts.cbegin(),
      patch_starts.cend() - 1,
      [&]() { return std::make_unique<PatchScratch>(n_ring); },
      [&](const std::vector<unsigned int>::const_iterator &start,
          PatchScratch                                    &scratch,
          PatchCopy                                       &copy) {
        const unsigned int first = start[0], n_cells = start[1] - first;
        const unsigned int result_size  = 6 * n_ring;
        const types::global_dof_index a = local_members[first].a;
        copy.first                      = first;
        copy.n_cells                    = n_cells;
        scratch.records.resize(n_cells * n_ring);
        copy.results.assign(n_cells * result_size, 0.);
        scratch.patch.clear();
        scratch.result.clear();
        for (unsigned int c = 0; c < n_cells; ++c)
          {
            const PatchMember &member = local_members[first + c];
            write_patch_record(member.cell,
                               a,
                               member.coefficients,
                               patch_terms,
                               scratch.records.data() + c * n_ring);
            scratch.patch.push_back(scratch.records.data() + c * n_ring);
            scratch.result.push_back(copy.results.data() + c * result_size);
          }
        // Each patch writes its own records of the replies.
        if (const auto members = remote.members.find(a);
            members != remote.members.end())
          for (const auto &[process, r] : members->second)
            {
              scratch.patch.push_back(remote.received.at(process).data() +
                                      r * n_ring);
              scratch.result.push_back(remote.replies.at(process).data() +
                                       r * result_size);
            }
        // λ_a at a, zero on ∂ω (DiscreteAction::lambda_h()); a is not
        // hanging.
        scratch.problem.solve(lambda_h[a], scratch.patch, scratch.result);
      },
      [&](const PatchCopy &copy) {
        for (unsigned int c = 0; c < copy.n_cells; ++c)
          add_patch_result(local_members[copy.first + c].cell,
                           copy.results.data() + c * 6 * n_ring);
      });
  }



  template <int dim>
  void
  FluxEquilibration<dim>::add_patch_result(const CellIterator &cell,
                                           const double       *result)
  {
    const auto        &ring        = basis.ring();
    const unsigned int n_triangles = basis.n_sub_triangles();
    for (unsigned int j = 0; j < ring.size(); ++j)
      for (unsigned int i = 0; i < 2; ++i)
        for (unsigned int e = 0; e < 3; ++e)
          sigma[cell->active_cell_index() * n_triangles + ring[j]][i][e] +=
            result[6 * j + 3 * i + e];
  }



  template class FluxEquilibration<2>;
} // namespace membranes
