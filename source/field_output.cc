#include <cmath>
#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/data_postprocessor.h>
#include <fstream>
#include <iomanip>
#include <map>
#include <membranes/atomic_file.h>
#include <membranes/field_output.h>

namespace membranes
{
  namespace
  {
    /** w = u1 − u2 from the two components of the solution. */
    template <int dim>
    class GapPostprocessor : public DataPostprocessorScalar<dim>
    {
    public:
      GapPostprocessor()
        : DataPostprocessorScalar<dim>("u1_minus_u2", update_values)
      {}

      void
      evaluate_vector_field(
        const DataPostprocessorInputs::Vector<dim> &inputs,
        std::vector<Vector<double>> &computed_quantities) const override
      {
        for (unsigned int q = 0; q < inputs.solution_values.size(); ++q)
          computed_quantities[q](0) =
            inputs.solution_values[q](0) - inputs.solution_values[q](1);
      }
    };
  } // namespace



  template <int dim>
  FieldOutput<dim>::FieldOutput(const Parameters::Output  &parameters,
                                const Discretization<dim> &discretization)
    : parameters(parameters)
    , discretization(discretization)
  {}



  template <int dim>
  void
  FieldOutput<dim>::write(const unsigned int     cycle,
                          const DoFHandler<dim> &dof_handler,
                          const VectorType      &ghosted_solution,
                          const VectorType      &contact_fields,
                          const Vector<double>  *indicators)
  {
    if (parameters.write_vtu)
      write_vtu(
        cycle, dof_handler, ghosted_solution, contact_fields, indicators);
    if (parameters.write_nodal_values)
      write_nodal_values(cycle, dof_handler, ghosted_solution, contact_fields);
  }



  template <int dim>
  void
  FieldOutput<dim>::write_vtu(const unsigned int     cycle,
                              const DoFHandler<dim> &dof_handler,
                              const VectorType      &ghosted_solution,
                              const VectorType      &contact_fields,
                              const Vector<double>  *indicators)
  {
    const GapPostprocessor<dim> gap;
    DataOut<dim>                data_out;
    data_out.attach_dof_handler(dof_handler);
    data_out.add_data_vector(ghosted_solution,
                             std::vector<std::string>{"u1", "u2"});
    data_out.add_data_vector(ghosted_solution, gap);
    data_out.add_data_vector(contact_fields,
                             std::vector<std::string>{"lambda_h",
                                                      "active_set"});
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
      cycles_written);
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
      dual_mesh_cycles_written);
  }



  template <int dim>
  void
  FieldOutput<dim>::write_cycle(
    const unsigned int                           cycle,
    const std::string                           &name,
    const std::function<void(std::ostream &)>   &writer,
    std::vector<std::pair<double, std::string>> &written)
  {
    const std::string file_name =
      name + "-" + Utilities::int_to_string(cycle, 2) + ".vtu";
    write_atomically(parameters.directory + "/" + file_name, writer);
    written.emplace_back(cycle, file_name);
    write_atomically(parameters.directory + "/" + name + ".pvd",
                     [&](std::ostream &out) {
                       DataOutBase::write_pvd_record(out, written);
                     });
  }



  template <int dim>
  void
  FieldOutput<dim>::write_nodal_values(const unsigned int     cycle,
                                       const DoFHandler<dim> &dof_handler,
                                       const VectorType      &ghosted_solution,
                                       const VectorType &contact_fields) const
  {
    // Every vertex once, by its u1 DoF: its position and its u2 DoF.
    const FiniteElement<dim>            &fe = dof_handler.get_fe();
    std::vector<types::global_dof_index> dof_indices(fe.n_dofs_per_cell());
    std::map<types::global_dof_index,
             std::pair<Point<dim>, types::global_dof_index>>
      vertices;
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        cell->get_dof_indices(dof_indices);
        for (const unsigned int v : cell->vertex_indices())
          vertices.emplace(
            dof_indices[fe.component_to_system_index(0, v)],
            std::make_pair(cell->vertex(v),
                           dof_indices[fe.component_to_system_index(1, v)]));
      }

    const std::string name = parameters.directory + "/nodal-values-" +
                             Utilities::int_to_string(cycle, 2) + ".csv";
    write_atomically(name, [&](std::ostream &out) {
      out << std::setprecision(17) << "x,y,u1,u2,lambda_h,active_set\n";
      for (const auto &[u1_dof, vertex] : vertices)
        {
          const auto &[point, u2_dof] = vertex;
          out << point[0] << ',' << point[1] << ',' << ghosted_solution[u1_dof]
              << ',' << ghosted_solution[u2_dof] << ','
              << contact_fields[u1_dof] << ',' << contact_fields[u2_dof]
              << '\n';
        }
    });
  }



  template class FieldOutput<2>;
} // namespace membranes
