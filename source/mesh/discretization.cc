#include <cmath>
#include <deal.II/distributed/shared_tria.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/mapping_cartesian.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_in.h>
#include <deal.II/grid/grid_tools.h>
#include <filesystem>
#include <fstream>
#include <membranes/mesh/discretization.h>
#include <sstream>

namespace membranes
{
  namespace
  {
    /**
     * A Gmsh file announces how many nodes and elements follow, and
     * GridIn allocates that much before it reads them: reject a count that
     * the file cannot hold (each item takes more than one byte), so that a
     * corrupt file cannot make the program allocate gigabytes or read on
     * for minutes.
     */
    void
    check_announced_sizes(const std::string &file_name)
    {
      const auto    size = std::filesystem::file_size(file_name);
      std::ifstream in(file_name);
      std::string   header, line;
      while (std::getline(in, header))
        if (header.rfind("$", 0) == 0 && header.rfind("$End", 0) != 0 &&
            std::getline(in, line))
          {
            std::istringstream counts(line);
            double             count;
            while (counts >> count)
              if (!(count >= 0 && count <= size))
                throw Parameters::invalid_entry(
                  "Geometry/Mesh file",
                  file_name,
                  "the counts '" + line.substr(0, 40) + "' after " +
                    header.substr(0, 40) + " cannot be right in a file of " +
                    std::to_string(size) + " bytes");
          }
    }



    /**
     * Check that every cell of a mesh read from a file is a proper one:
     * coordinates finite and within Parameters::max_magnitude, and, at
     * every vertex, the two edges through it turn counterclockwise (the
     * Jacobian of the cell's map is positive there, hence everywhere for
     * P1 and Q1: no degenerate, inverted or self-intersecting cell).
     * GridIn has already turned cells given clockwise, as Gmsh writes them
     * for a surface whose normal points down, counterclockwise.
     */
    template <int dim>
    void
    check_cells(const std::string &file_name, const Triangulation<dim> &mesh)
    {
      for (const auto &cell : mesh.active_cell_iterators())
        {
          // The vertices in counterclockwise order: deal.II numbers those
          // of a quadrilateral lexicographically.
          const std::vector<unsigned int> order =
            cell->n_vertices() == 3 ? std::vector<unsigned int>{0, 1, 2} :
                                      std::vector<unsigned int>{0, 1, 3, 2};
          const unsigned int n = order.size();
          for (unsigned int k = 0; k < n; ++k)
            {
              const Point<dim>  &a = cell->vertex(order[k]);
              std::ostringstream allowed;
              if (!(std::abs(a[0]) <= Parameters::max_magnitude &&
                    std::abs(a[1]) <= Parameters::max_magnitude))
                allowed << "vertex (" << a << ") of cell " << cell->index()
                        << ": coordinates must be finite and at most "
                        << Parameters::max_magnitude << " in magnitude";
              const Tensor<1, dim> next = cell->vertex(order[(k + 1) % n]) - a;
              const Tensor<1, dim> previous =
                cell->vertex(order[(k + n - 1) % n]) - a;
              if (allowed.str().empty() &&
                  !(next[0] * previous[1] - next[1] * previous[0] > 0))
                allowed << "cell " << cell->index() << " is degenerate, "
                        << "inverted or self-intersecting at its vertex (" << a
                        << ")";
              if (!allowed.str().empty())
                throw Parameters::invalid_entry("Geometry/Mesh file",
                                                file_name,
                                                allowed.str());
            }
        }
    }



    /** Read a Gmsh file, with every failure turned into an InputError. */
    template <int dim>
    void
    read_mesh_file(const std::string  &file_name,
                   Triangulation<dim> &triangulation)
    {
      if (const std::string problem = Parameters::unreadable_file(file_name);
          !problem.empty())
        throw Parameters::invalid_entry("Geometry/Mesh file",
                                        file_name,
                                        problem +
                                          "; expected a Gmsh .msh file");
      check_announced_sizes(file_name);
      std::ifstream in(file_name);
      if (!in)
        throw Parameters::invalid_entry("Geometry/Mesh file",
                                        file_name,
                                        "cannot open this file");
      try
        {
          GridIn<dim> grid_in(triangulation);
          grid_in.read_msh(in);
        }
      catch (const std::exception &e)
        {
          throw Parameters::invalid_entry("Geometry/Mesh file",
                                          file_name,
                                          "not a readable Gmsh mesh (" +
                                            Parameters::one_line_message(e) +
                                            ")");
        }
      if (triangulation.n_active_cells() == 0)
        throw Parameters::invalid_entry("Geometry/Mesh file",
                                        file_name,
                                        "the mesh has no cells");
      check_cells(file_name, triangulation);
    }
  } // namespace



  template <int dim>
  Discretization<dim>::Discretization(const Parameters::CellType cell_type)
    : cell_type(cell_type)
    , fe(cell_type == Parameters::CellType::triangle ?
           std::unique_ptr<FiniteElement<dim>>(new FE_SimplexP<dim>(1)) :
           std::make_unique<FE_Q<dim>>(1))
    , mapping(
        fe->reference_cell().template get_default_linear_mapping<dim>().clone())
    , cell_quadrature(
        fe->reference_cell().template get_gauss_type_quadrature<dim>(3))
    , dual_cell_quadrature(fe->reference_cell(), 2)
  {}



  template <int dim>
  void
  Discretization<dim>::select_mapping(const Triangulation<dim> &triangulation)
  {
    if (cell_type == Parameters::CellType::triangle)
      return;
    // A cell is a rectangle with axis-parallel edges when coordinate d of
    // each vertex v is that of vertex 0 or of vertex 2^d, as bit d of v
    // says (in 2D: vertices 0 and 1 share y, 0 and 2 share x, 3 has the x
    // of 1 and the y of 2). The comparisons are exact: deal.II's generators
    // and the slit's quarter turn make such meshes exactly. Refinement
    // keeps the property: it halves the edges.
    const auto is_rectangle = [](const auto &cell) {
      if (cell->manifold_id() != numbers::flat_manifold_id)
        return false;
      for (const unsigned int v : cell->vertex_indices())
        for (unsigned int d = 0; d < dim; ++d)
          if (cell->vertex(v)[d] != cell->vertex(v & (1u << d))[d])
            return false;
      for (const unsigned int f : cell->face_indices())
        if (cell->face(f)->manifold_id() != numbers::flat_manifold_id)
          return false;
      return true;
    };
    for (const auto &cell : triangulation.cell_iterators_on_level(0))
      if (!is_rectangle(cell))
        return;
    mapping = std::make_unique<MappingCartesian<dim>>();
  }



  template <int dim>
  bool
  Discretization<dim>::rectangles() const
  {
    return dynamic_cast<const MappingCartesian<dim> *>(mapping.get()) !=
           nullptr;
  }



  template <int dim>
  std::unique_ptr<Triangulation<dim>>
  make_triangulation(const Parameters::CellType cell_type,
                     const MPI_Comm             mpi_communicator)
  {
    if (cell_type == Parameters::CellType::quadrilateral)
      return std::make_unique<parallel::distributed::Triangulation<dim>>(
        mpi_communicator);
    return std::make_unique<parallel::shared::Triangulation<dim>>(
      mpi_communicator,
      Triangulation<dim>::none,
      /* allow_artificial_cells = */ true,
      parallel::shared::Triangulation<dim>::partition_zorder);
  }



  namespace
  {
    /**
     * The coarse mesh of @p geometry's domain in @p coarse: as deal.II
     * makes it (quadrilaterals) or as the mesh file has it.
     */
    template <int dim>
    void
    make_coarse_mesh(const Parameters::Geometry &geometry,
                     Triangulation<dim>         &coarse)
    {
      switch (geometry.domain)
        {
          case Parameters::Domain::square:
            GridGenerator::hyper_cube(coarse, -1, 1);
            break;
          case Parameters::Domain::lshape:
            GridGenerator::hyper_L(coarse, -1, 1);
            break;
          case Parameters::Domain::slit:
            // deal.II's slit runs from the bottom edge (0,-1) to the centre;
            // the quarter turn (x, y) -> (-y, x), exact in floating point,
            // puts it on [0,1) x {0}. Its four cells do not share the
            // vertices along the slit: each face of the slit has its own, so
            // both are boundary.
            GridGenerator::hyper_cube_slit(coarse, -1, 1);
            GridTools::transform(
              [](const Point<dim> &p) { return Point<dim>(-p[1], p[0]); },
              coarse);
            break;
          case Parameters::Domain::disk:
            GridGenerator::hyper_ball(coarse);
            break;
          case Parameters::Domain::file:
            read_mesh_file(geometry.mesh_file, coarse);
            break;
        }
    }



    /**
     * Keep the disk split into triangles, @p triangulation, on its circle:
     * the vertices on its boundary (after a refinement, the new ones in the
     * middle of chords) are moved onto the unit circle, where a spherical
     * manifold on the boundary faces would put them. Such a manifold cannot
     * be used: MappingFE, the mapping of simplices, requires a cell and all
     * its faces to share one manifold id (a Debug build stops on it), so the
     * manifolds that the split copied from the disk of quadrilaterals are
     * removed too.
     */
    template <int dim>
    void
    keep_on_circle(Triangulation<dim> &triangulation)
    {
      for (const auto &cell : triangulation.active_cell_iterators())
        cell->set_all_manifold_ids(numbers::flat_manifold_id);
      triangulation.reset_all_manifolds();
      const auto onto_circle = [&triangulation]() {
        for (const auto &face : triangulation.active_face_iterators())
          if (face->at_boundary())
            for (const unsigned int v : face->vertex_indices())
              face->vertex(v) /= face->vertex(v).norm();
      };
      onto_circle();
      triangulation.signals.post_refinement.connect(onto_circle);
    }



    /**
     * Each refinement makes four cells of one: refuse a first mesh that
     * would not fit in memory (@p triangulation refined by @p geometry's
     * initial refinement) before trying to build it.
     */
    template <int dim>
    void
    check_initial_refinement(const Parameters::Geometry &geometry,
                             const Triangulation<dim>   &triangulation)
    {
      const std::uint64_t max_cells = 1 << 22;
      const double        cells     = triangulation.n_global_active_cells() *
                           std::pow(GeometryInfo<dim>::max_children_per_cell,
                                    geometry.initial_refinement);
      if (cells > max_cells)
        {
          std::ostringstream allowed;
          allowed << "the first mesh would have "
                  << static_cast<std::uint64_t>(cells) << " cells ("
                  << triangulation.n_global_active_cells()
                  << " coarse cells, each "
                  << "refined into " << GeometryInfo<dim>::max_children_per_cell
                  << "^" << geometry.initial_refinement << "); at most "
                  << max_cells
                  << " are allowed, finer meshes come from the cycles";
          throw Parameters::invalid_entry("Geometry/Initial refinement",
                                          std::to_string(
                                            geometry.initial_refinement),
                                          allowed.str());
        }
    }
  } // namespace



  template <int dim>
  void
  create_mesh(const Parameters::Geometry &geometry,
              Triangulation<dim>         &triangulation)
  {
    const bool want_triangles =
      (geometry.cell_type == Parameters::CellType::triangle);

    // The coarse mesh is built in place unless it has to be split into
    // triangles, so that manifolds tied to it (the disk's transfinite
    // interior) stay valid; a file is read into a serial triangulation
    // first, because it may hold triangles, which p4est cannot take, and
    // the slit is rotated there, before p4est takes its coarse cells.
    const bool serial_first = (geometry.domain == Parameters::Domain::file ||
                               geometry.domain == Parameters::Domain::slit);
    Triangulation<dim>  serial_coarse;
    Triangulation<dim> &coarse =
      (want_triangles || serial_first) ? serial_coarse : triangulation;
    make_coarse_mesh(geometry, coarse);

    const auto &cell_types = coarse.get_reference_cells();
    if (cell_types.size() != 1)
      throw Parameters::invalid_entry("Geometry/Mesh file",
                                      geometry.mesh_file,
                                      "mixed meshes are not supported");
    const bool has_triangles = cell_types[0].is_simplex();
    if (has_triangles && !want_triangles)
      throw Parameters::invalid_entry(
        "Geometry/Cell type",
        "quadrilateral",
        "the mesh file holds triangles: use 'Cell type = triangle'");

    if (!want_triangles && serial_first)
      triangulation.copy_triangulation(serial_coarse);
    if (want_triangles)
      {
        if (has_triangles)
          triangulation.copy_triangulation(serial_coarse);
        else
          GridGenerator::convert_hypercube_to_simplex_mesh(serial_coarse,
                                                           triangulation);
        if (geometry.domain == Parameters::Domain::disk)
          keep_on_circle(triangulation);
      }

    check_initial_refinement(geometry, triangulation);
    triangulation.refine_global(geometry.initial_refinement);
    complete_ghost_layer(triangulation);
  }



  template <int dim>
  void
  complete_ghost_layer(Triangulation<dim> &triangulation)
  {
    auto *const shared =
      dynamic_cast<parallel::shared::Triangulation<dim> *>(&triangulation);
    if (shared == nullptr || !shared->with_artificial_cells())
      return;
    // The vertices a cell touches: its corners and the middle vertices of
    // its edges that have children.
    const auto for_each_touched_vertex = [](const auto &cell,
                                            const auto &visit) {
      for (const unsigned int v : cell->vertex_indices())
        visit(cell->vertex_index(v));
      for (const unsigned int f : cell->face_indices())
        if (cell->face(f)->has_children())
          visit(cell->face(f)->child(0)->vertex_index(1));
    };
    std::vector<bool> touched_by_owned(triangulation.n_vertices(), false);
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        for_each_touched_vertex(cell, [&](const unsigned int vertex) {
          touched_by_owned[vertex] = true;
        });
    const std::vector<types::subdomain_id> &owner =
      shared->get_true_subdomain_ids_of_cells();
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_artificial())
        {
          bool touches = false;
          for_each_touched_vertex(cell, [&](const unsigned int vertex) {
            touches = touches || touched_by_owned[vertex];
          });
          if (touches)
            cell->set_subdomain_id(owner[cell->active_cell_index()]);
        }
  }



  template class Discretization<2>;
  template std::unique_ptr<Triangulation<2>>
  make_triangulation<2>(const Parameters::CellType, const MPI_Comm);
  template void
  create_mesh<2>(const Parameters::Geometry &, Triangulation<2> &);
  template void
  complete_ghost_layer<2>(Triangulation<2> &);
} // namespace membranes
