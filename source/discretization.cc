#include <deal.II/base/quadrature_lib.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_in.h>
#include <deal.II/grid/manifold_lib.h>
#include <fstream>
#include <membranes/discretization.h>
#include <sstream>

namespace membranes
{
  namespace
  {
    template <int dim>
    std::unique_ptr<FESystem<dim>>
    make_fe(const Parameters::CellType cell_type)
    {
      if (cell_type == Parameters::CellType::triangle)
        return std::make_unique<FESystem<dim>>(FE_SimplexP<dim>(1), 2);
      return std::make_unique<FESystem<dim>>(FE_Q<dim>(1), 2);
    }

    template <int dim>
    std::unique_ptr<Mapping<dim>>
    make_mapping(const Parameters::CellType cell_type)
    {
      if (cell_type == Parameters::CellType::triangle)
        return std::make_unique<MappingFE<dim>>(FE_SimplexP<dim>(1));
      return std::make_unique<MappingQ1<dim>>();
    }

    template <int dim>
    Quadrature<dim>
    make_cell_quadrature(const Parameters::CellType cell_type)
    {
      if (cell_type == Parameters::CellType::triangle)
        return QGaussSimplex<dim>(3);
      return QGauss<dim>(3);
    }



    /** Read a Gmsh file, with every failure turned into an InputError. */
    template <int dim>
    void
    read_mesh_file(const std::string  &file_name,
                   Triangulation<dim> &triangulation)
    {
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
          std::ostringstream reason;
          if (const auto *dealii_error =
                dynamic_cast<const ExceptionBase *>(&e))
            dealii_error->print_info(reason);
          else
            reason << e.what();
          std::string text = reason.str();
          for (char &c : text)
            if (c == '\n')
              c = ' ';
          throw Parameters::invalid_entry("Geometry/Mesh file",
                                          file_name,
                                          "not a readable Gmsh mesh (" +
                                            Utilities::trim(text) + ")");
        }
      if (triangulation.n_active_cells() == 0)
        throw Parameters::invalid_entry("Geometry/Mesh file",
                                        file_name,
                                        "the mesh has no cells");
    }
  } // namespace



  template <int dim>
  Discretization<dim>::Discretization(const Parameters::CellType cell_type)
    : cell_type(cell_type)
    , fe(make_fe<dim>(cell_type))
    , mapping(make_mapping<dim>(cell_type))
    , cell_quadrature(make_cell_quadrature<dim>(cell_type))
  {}



  template <int dim>
  void
  create_mesh(const Parameters::Geometry &geometry,
              Triangulation<dim>         &triangulation)
  {
    const bool want_triangles =
      (geometry.cell_type == Parameters::CellType::triangle);

    // The coarse mesh, as deal.II makes it (quadrilaterals) or as the file
    // has it. It is built in place unless it has to be split into
    // triangles, so that manifolds tied to it (the disk's transfinite
    // interior) stay valid.
    Triangulation<dim>  to_be_split;
    Triangulation<dim> &coarse = want_triangles ? to_be_split : triangulation;
    switch (geometry.domain)
      {
        case Parameters::Domain::square:
          GridGenerator::hyper_cube(coarse, -1, 1);
          break;
        case Parameters::Domain::lshape:
          GridGenerator::hyper_L(coarse, -1, 1);
          break;
        case Parameters::Domain::disk:
          GridGenerator::hyper_ball(coarse);
          break;
        case Parameters::Domain::file:
          read_mesh_file(geometry.mesh_file, coarse);
          break;
      }

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

    if (want_triangles)
      {
        if (has_triangles)
          triangulation.copy_triangulation(to_be_split);
        else
          GridGenerator::convert_hypercube_to_simplex_mesh(to_be_split,
                                                           triangulation);
        // The split disk keeps its circle: every boundary face follows a
        // spherical manifold under refinement.
        if (geometry.domain == Parameters::Domain::disk)
          {
            // (Triangulation::set_all_manifold_ids_on_boundary() crashes on
            // simplex meshes in deal.II 9.4: mark the coarse faces one by
            // one.)
            for (const auto &face : triangulation.active_face_iterators())
              if (face->at_boundary())
                face->set_manifold_id(0);
            triangulation.set_manifold(0, SphericalManifold<dim>());
          }
      }

    triangulation.refine_global(geometry.initial_refinement);
  }



  template class Discretization<2>;
  template void
  create_mesh<2>(const Parameters::Geometry &, Triangulation<2> &);
} // namespace membranes
