#include <algorithm>
#include <array>
#include <cmath>
#include <deal.II/base/mpi.h>
#include <deal.II/numerics/data_out.h>
#include <iomanip>
#include <map>
#include <membranes/output/atomic_file.h>
#include <membranes/output/field_output.h>

namespace membranes
{
  template <int dim>
  FieldOutput<dim>::FieldOutput(const Parameters::Output  &parameters,
                                const Discretization<dim> &discretization,
                                const MPI_Comm             mpi_communicator)
    : parameters(parameters)
    , discretization(discretization)
    , mpi_communicator(mpi_communicator)
  {}



  template <int dim>
  std::vector<std::string>
  FieldOutput<dim>::write(const unsigned int     cycle,
                          const DoFHandler<dim> &dof_handler,
                          const BlockVectorType &ghosted_solution,
                          const VectorType      &lambda_h,
                          const IndexSet        &active_vertices,
                          const Vector<double>  *indicators)
  {
    std::vector<std::string> files;
    if (!parameters.write_vtu && !parameters.write_nodal_values)
      return files;
    const IndexSet &owned_dofs = dof_handler.locally_owned_dofs();
    VectorType      w(owned_dofs, mpi_communicator);
    for (const types::global_dof_index dof : owned_dofs)
      w[dof] = ghosted_solution.block(0)[dof] - ghosted_solution.block(1)[dof];
    w.compress(VectorOperation::insert);
    VectorType active_set(owned_dofs, mpi_communicator);
    for (const types::global_dof_index dof : active_vertices)
      active_set[dof] = 1;
    active_set.compress(VectorOperation::insert);

    // Ghosted, in the layout of the blocks of the solution.
    Fields fields{ghosted_solution.block(0), ghosted_solution.block(0)};
    fields.w          = w;
    fields.active_set = active_set;
    if (parameters.write_vtu)
      files.push_back(write_vtu(
        cycle, dof_handler, ghosted_solution, lambda_h, fields, indicators));
    if (parameters.write_nodal_values)
      files.push_back(write_nodal_values(
        cycle, dof_handler, ghosted_solution, lambda_h, fields));
    return files;
  }



  template <int dim>
  std::string
  FieldOutput<dim>::write_vtu(const unsigned int     cycle,
                              const DoFHandler<dim> &dof_handler,
                              const BlockVectorType &ghosted_solution,
                              const VectorType      &lambda_h,
                              const Fields          &fields,
                              const Vector<double>  *indicators)
  {
    // The types are given: on a mesh with as many vertices as cells, the
    // automatic choice could not tell nodal from cell data.
    constexpr auto nodal = DataOut<dim>::type_dof_data;
    DataOut<dim>   data_out;
    data_out.attach_dof_handler(dof_handler);
    data_out.add_data_vector(ghosted_solution.block(0), "u1", nodal);
    data_out.add_data_vector(ghosted_solution.block(1), "u2", nodal);
    data_out.add_data_vector(fields.w, "w", nodal);
    data_out.add_data_vector(lambda_h, "lambda_h", nodal);
    data_out.add_data_vector(fields.active_set, "active_set", nodal);
    const auto   &triangulation = dof_handler.get_triangulation();
    Vector<float> subdomain(triangulation.n_active_cells());
    subdomain = triangulation.locally_owned_subdomain();
    data_out.add_data_vector(subdomain,
                             "subdomain",
                             DataOut<dim>::type_cell_data);
    Vector<double> eta_K;
    if (indicators)
      {
        eta_K = *indicators;
        for (double &value : eta_K)
          value = std::sqrt(value);
        data_out.add_data_vector(eta_K,
                                 "indicator",
                                 DataOut<dim>::type_cell_data);
      }
    data_out.build_patches(*discretization.mapping);
    write_cycle(
      cycle,
      "solution",
      [&](std::ostream &out) { data_out.write_vtu(out); },
      [&](std::ostream &out, const std::vector<std::string> &pieces) {
        data_out.write_pvtu_record(out, pieces);
      },
      cycles_written);
    return cycles_written.back().second;
  }



  template <int dim>
  void
  FieldOutput<dim>::write_dual_mesh(
    const unsigned int                               cycle,
    const std::vector<DataOutBase::Patch<dim, dim>> &patches,
    const std::vector<std::string>                  &names)
  {
    write_cycle(
      cycle,
      "dual-mesh",
      [&](std::ostream &out) {
        DataOutBase::write_vtu(
          patches, names, {}, DataOutBase::VtkFlags(), out);
      },
      [&](std::ostream &out, const std::vector<std::string> &pieces) {
        DataOutBase::write_pvtu_record(
          out, pieces, names, {}, DataOutBase::VtkFlags());
      },
      dual_mesh_cycles_written);
  }



  template <int dim>
  std::pair<std::vector<std::pair<double, std::string>>,
            std::vector<std::pair<double, std::string>>>
  FieldOutput<dim>::written_files() const
  {
    return {cycles_written, dual_mesh_cycles_written};
  }



  template <int dim>
  void
  FieldOutput<dim>::resume(
    const std::vector<std::pair<double, std::string>> &solution_files,
    const std::vector<std::pair<double, std::string>> &dual_mesh_files)
  {
    cycles_written           = solution_files;
    dual_mesh_cycles_written = dual_mesh_files;
  }



  template <int dim>
  void
  FieldOutput<dim>::write_cycle(
    const unsigned int                         cycle,
    const std::string                         &name,
    const std::function<void(std::ostream &)> &write_piece,
    const std::function<void(std::ostream &, const std::vector<std::string> &)>
                                                &write_record,
    std::vector<std::pair<double, std::string>> &written)
  {
    const unsigned int n_processes =
      Utilities::MPI::n_mpi_processes(mpi_communicator);
    const unsigned int process =
      Utilities::MPI::this_mpi_process(mpi_communicator);
    const std::string base = name + "-" + Utilities::int_to_string(cycle, 2);
    const auto        piece_name = [&](const unsigned int p) {
      return n_processes == 1 ?
                      base + ".vtu" :
                      base + "." + Utilities::int_to_string(p, 4) + ".vtu";
    };
    write_atomically(parameters.directory + "/" + piece_name(process),
                     write_piece);

    std::string file_name = piece_name(0);
    if (n_processes > 1)
      {
        file_name = base + ".pvtu";
        std::vector<std::string> pieces;
        for (unsigned int p = 0; p < n_processes; ++p)
          pieces.push_back(piece_name(p));
        if (process == 0)
          write_atomically(parameters.directory + "/" + file_name,
                           [&](std::ostream &out) {
                             write_record(out, pieces);
                           });
      }
    written.emplace_back(cycle, file_name);
    if (process == 0)
      write_atomically(parameters.directory + "/" + name + ".pvd",
                       [&](std::ostream &out) {
                         DataOutBase::write_pvd_record(out, written);
                       });
  }



  template <int dim>
  std::string
  FieldOutput<dim>::write_nodal_values(const unsigned int     cycle,
                                       const DoFHandler<dim> &dof_handler,
                                       const BlockVectorType &ghosted_solution,
                                       const VectorType      &lambda_h,
                                       const Fields          &fields) const
  {
    // The locally owned vertices, each once (by its DoF), with their
    // values: x, y, u1, u2, λ_a, active set.
    using Row                  = std::array<double, 6>;
    const IndexSet &owned_dofs = dof_handler.locally_owned_dofs();
    std::map<types::global_dof_index, Row> owned_rows;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        for (const unsigned int v : cell->vertex_indices())
          {
            const auto dof = cell->vertex_dof_index(v, 0);
            if (owned_dofs.is_element(dof))
              owned_rows[dof] = {{cell->vertex(v)[0],
                                  cell->vertex(v)[1],
                                  ghosted_solution.block(0)[dof],
                                  ghosted_solution.block(1)[dof],
                                  lambda_h[dof],
                                  fields.active_set[dof]}};
          }
    std::vector<Row> rows;
    for (const auto &[dof, row] : owned_rows)
      rows.push_back(row);

    // All of them on the first process, in the order of their positions.
    const std::string file =
      "nodal-values-" + Utilities::int_to_string(cycle, 2) + ".csv";
    const auto gathered = Utilities::MPI::gather(mpi_communicator, rows, 0);
    if (Utilities::MPI::this_mpi_process(mpi_communicator) != 0)
      return file;
    rows.clear();
    for (const auto &process_rows : gathered)
      rows.insert(rows.end(), process_rows.begin(), process_rows.end());
    std::sort(rows.begin(), rows.end());

    write_atomically(parameters.directory + "/" + file, [&](std::ostream &out) {
      out << std::setprecision(17) << "x,y,u1,u2,lambda_h,active_set\n";
      for (const auto &row : rows)
        out << row[0] << ',' << row[1] << ',' << row[2] << ',' << row[3] << ','
            << row[4] << ',' << row[5] << '\n';
    });
    return file;
  }



  template class FieldOutput<2>;
} // namespace membranes
