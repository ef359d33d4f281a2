#include <algorithm>
#include <cmath>
#include <deal.II/base/exceptions.h>
#include <membranes/flux/flux_patch_problem.h>
#include <tuple>

// The patch problems of the equilibration of σ_ih (see the class comment of
// FluxEquilibration and PatchProblem).

namespace membranes
{
  namespace
  {
    constexpr unsigned int invalid = numbers::invalid_unsigned_int;

    /** At most 8 sub-triangles per cell, and the circulation. */
    constexpr unsigned int max_cell_unknowns = 9;

    /**
     * The quadratic form of the minimization on one cell in its local
     * unknowns (b_0, …, b_{n−1}, z): ½ xᵀ A x + lᵀ x, with the linear term l
     * per membrane.
     */
    struct CellForm
    {
      double quadratic[max_cell_unknowns][max_cell_unknowns];
      std::array<std::array<double, 2>, max_cell_unknowns> linear;
    };
  } // namespace



  PatchProblem::PatchProblem(const unsigned int n_ring)
    : n_ring(n_ring)
  {
    AssertIndexRange(n_ring, max_cell_unknowns);
  }



  void
  PatchProblem::solve(const double                            lambda_a,
                      const std::vector<const PatchRecord *> &patch,
                      const std::vector<double *>            &result)
  {
    this->patch = &patch;
    n_cells     = patch.size();
    n_sub       = n_cells * n_ring;
    number_unknowns();
    compute_sources(lambda_a);
    compute_targets();

    const unsigned int m = n_x + 2 * n_cells - 1;
    matrix.reinit(m, m);
    for (auto &r : rhs)
      r.reinit(m);
    for (unsigned int c = 0; c < n_cells; ++c)
      assemble_cell(c);
    // The system [A Bᵀ; B 0] (x; y) = (b; c) of the minimization A and the
    // constraints B (of full rank), by LU with pivoting.
    matrix.compute_lu_factorization();
    for (auto &r : rhs)
      matrix.solve(r);
    write_fluxes(result);
  }



  void
  PatchProblem::number_unknowns()
  {
    half_edges.clear();
    for (unsigned int s = 0; s < n_sub; ++s)
      if (!record(s).on_boundary)
        half_edges.push_back(
          {record(s).key[0], record(s).key[1], s / n_ring, s});
    std::sort(half_edges.begin(),
              half_edges.end(),
              [](const auto &p, const auto &q) {
                return std::tie(p.first, p.second, p.cell) <
                       std::tie(q.first, q.second, q.cell);
              });
    unknown_of.assign(n_sub, {numbers::invalid_unsigned_int, 0.});
    n_x = 0;
    for (unsigned int begin = 0, end; begin < half_edges.size(); begin = end)
      {
        for (end = begin + 1;
             end < half_edges.size() &&
             half_edges[end].first == half_edges[begin].first &&
             half_edges[end].second == half_edges[begin].second;
             ++end)
          ;
        if (half_edges[end - 1].cell != half_edges[begin].cell)
          {
            for (unsigned int k = begin; k < end; ++k)
              unknown_of[half_edges[k].s] = {n_x,
                                             record(half_edges[k].s).factor};
            ++n_x;
          }
      }
  }



  void
  PatchProblem::compute_sources(const double lambda_a)
  {
    const std::array<double, 2> sign{{1., -1.}};
    source.assign(n_sub, {});
    known.assign(n_sub, {});
    std::array<double, 2> total{}, total_boundary_flux{};
    double                patch_area = 0, total_boundary_mass = 0;
    for (unsigned int s = 0; s < n_sub; ++s)
      {
        const PatchRecord &kappa = record(s);
        patch_area += kappa.area;
        total_boundary_mass += kappa.boundary_mass;
        for (unsigned int i = 0; i < 2; ++i)
          {
            source[s][i] = kappa.residual[i] + sign[i] * lambda_a * kappa.mass;
            total[i] += source[s][i];
            if (kappa.on_boundary)
              {
                known[s][i] = kappa.edge_flux[i][2];
                total_boundary_flux[i] += known[s][i];
              }
          }
      }
    for (unsigned int s = 0; s < n_sub; ++s)
      for (unsigned int i = 0; i < 2; ++i)
        if (total_boundary_mass > 0)
          known[s][i] += (total[i] - total_boundary_flux[i]) *
                         record(s).boundary_mass / total_boundary_mass;
        else
          source[s][i] -= total[i] * record(s).area / patch_area;
  }



  /**
   * The target: on each sub-triangle the RT0 field with the fluxes of
   * −μ_i φ_a ∇u_ih through its edges; through a half-edge shared by two
   * cells, the mean of both sides. On the fine side of an edge with a
   * hanging node, the two halves of a small edge share one unknown, so
   * their targets take one density: the flux this moves between the two
   * sub-triangles of the face goes back through their common edge 0
   * (m_e–b_K), half of the difference of the changes from each side, which
   * keeps the target conforming inside the cell. The targets are then
   * conforming, and where u_ih is linear they satisfy the constraints
   * (through a small edge the one-sided fluxes of the fine side add up to
   * the coarse side's, so the two changes are opposite): σ_ih^a is its
   * target, and σ_ih = −μ_i ∇u_ih, also with hanging nodes.
   */
  void
  PatchProblem::compute_targets()
  {
    target.resize(n_sub);
    mean.assign(n_x, {});
    weight.assign(n_x, 0.);
    change.resize(n_sub);
    for (unsigned int s = 0; s < n_sub; ++s)
      {
        target[s] = record(s).edge_flux;
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
      if (std::abs(record(s).factor) == 0.5)
        for (unsigned int i = 0; i < 2; ++i)
          {
            const double back = (change[s][i] - change[s + 1][i]) / 2;
            target[s][i][0] -= back;
            target[s + 1][i][0] += back;
          }
  }



  /**
   * On cell c, with the outward fluxes b_j through the half-edges of its
   * ring and its circulation z_c, the flux from ring[j] into ring[j+1] is
   * z_c + Σ_{k≤j} (r_k − b_k), so that div = r_j on every κ; the ring
   * closes iff Σ_j b_j = Σ_j r_j, the cell's constraint (one of them is
   * redundant: together they say ∫ r_ia = flux through ∂ω). Edge 2 of
   * ring[j] is its half-edge, through edge j % 2 (out) it meets ring[j+1],
   * through the other (in) ring[j−1]. With η_j = Σ_{k<j} b_k − z_c, its
   * fluxes are
   *
   *   F_j = η_j D + b_j E + q_j,  D = e_in − e_out,  E = e_2 − e_out,
   *
   * q_j = (Σ_{k≤j} r_k) e_out − (Σ_{k<j} r_k) e_in, and the patch problem
   * minimizes Σ_κ (F_κ − target_κ)ᵀ G_κ (F_κ − target_κ) under the
   * constraints. On each cell the quadratic form in (b_0, …, z_c) has
   * entries from suffix sums of α_j = DᵀG_jD, with γ_j = DᵀG_jE and
   * ε_j = EᵀG_jE, so it costs O(n_ring²). An unknown b_j is factor × a flux
   * unknown of the patch; a prescribed one goes to the right-hand side.
   */
  void
  PatchProblem::assemble_cell(const unsigned int c)
  {
    const unsigned int                                   z = n_ring;
    CellForm                                             form;
    std::array<std::array<double, 2>, max_cell_unknowns> g_d, g_e;
    std::array<double, max_cell_unknowns> alpha, gamma, epsilon, suffix;
    std::array<double, 2>                 partial{}, known_total{};
    for (unsigned int j = 0; j < n_ring; ++j)
      {
        const unsigned int s   = c * n_ring + j;
        const unsigned int out = j % 2, in = 1 - out;
        const auto        &g       = record(s).gram;
        const double       G[3][3] = {{g[0], g[1], g[2]},
                                      {g[1], g[3], g[4]},
                                      {g[2], g[4], g[5]}};
        alpha[j]                   = G[in][in] - 2 * G[in][out] + G[out][out];
        gamma[j]   = G[in][2] - G[in][out] - G[out][2] + G[out][out];
        epsilon[j] = G[2][2] - 2 * G[2][out] + G[out][out];
        for (unsigned int i = 0; i < 2; ++i)
          {
            // q_j − target_j, and Dᵀ G_j and Eᵀ G_j of it.
            std::array<double, 3> r{};
            r[out] = partial[i] + source[s][i];
            r[in]  = -partial[i];
            for (unsigned int e = 0; e < 3; ++e)
              r[e] -= target[s][i][e];
            std::array<double, 3> Gr{};
            for (unsigned int e = 0; e < 3; ++e)
              for (unsigned int f = 0; f < 3; ++f)
                Gr[e] += G[e][f] * r[f];
            g_d[j][i] = Gr[in] - Gr[out];
            g_e[j][i] = Gr[2] - Gr[out];
            partial[i] += source[s][i];
            known_total[i] += known[s][i];
          }
      }
    suffix[n_ring] = 0;
    for (unsigned int j = n_ring; j-- > 0;)
      suffix[j] = suffix[j + 1] + alpha[j];
    auto &A = form.quadratic;
    for (unsigned int k = 0; k < n_ring; ++k)
      {
        for (unsigned int j = 0; j < n_ring; ++j)
          A[k][j] = suffix[std::max(k, j) + 1];
        A[k][k] += epsilon[k];
        A[k][z] = A[z][k] = -suffix[k + 1] - gamma[k];
        for (unsigned int j = 0; j < k; ++j)
          {
            A[j][k] += gamma[k];
            A[k][j] += gamma[k];
          }
      }
    A[z][z] = suffix[0];
    std::array<double, 2> g_d_suffix{};
    for (unsigned int k = n_ring; k-- > 0;)
      for (unsigned int i = 0; i < 2; ++i)
        {
          form.linear[k][i] = g_d_suffix[i] + g_e[k][i];
          g_d_suffix[i] += g_d[k][i];
        }
    for (unsigned int i = 0; i < 2; ++i)
      form.linear[z][i] = -g_d_suffix[i];

    // The local unknowns in those of the patch.
    std::array<std::pair<unsigned int, double>, max_cell_unknowns> global;
    for (unsigned int k = 0; k < n_ring; ++k)
      global[k] = unknown_of[c * n_ring + k];
    global[z] = {n_x + c, 1.};
    for (unsigned int u = 0; u <= n_ring; ++u)
      if (global[u].first != invalid)
        {
          std::array<double, 2> linear = form.linear[u];
          for (unsigned int v = 0; v <= n_ring; ++v)
            if (global[v].first != invalid)
              matrix(global[u].first, global[v].first) +=
                global[u].second * A[u][v] * global[v].second;
            else
              for (unsigned int i = 0; i < 2; ++i)
                linear[i] += A[u][v] * known[c * n_ring + v][i];
          for (unsigned int i = 0; i < 2; ++i)
            rhs[i](global[u].first) -= global[u].second * linear[i];
        }
    if (c + 1 < n_cells)
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



  void
  PatchProblem::write_fluxes(const std::vector<double *> &result) const
  {
    for (unsigned int c = 0; c < n_cells; ++c)
      for (unsigned int i = 0; i < 2; ++i)
        {
          // η_j = Σ_{k<j} b_k − z_c.
          double partial = 0, eta = -rhs[i](n_x + c);
          for (unsigned int j = 0; j < n_ring; ++j)
            {
              const unsigned int s   = c * n_ring + j;
              const unsigned int out = j % 2, in = 1 - out;
              const auto [x, f] = unknown_of[s];
              const double b    = (x != invalid ? f * rhs[i](x) : known[s][i]);
              double      *F    = result[c] + 6 * j + 3 * i;
              F[out]            = -eta - b + partial + source[s][i];
              F[in]             = eta - partial;
              F[2]              = b;
              partial += source[s][i];
              eta += b;
            }
        }
  }
} // namespace membranes
