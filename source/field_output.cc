#include <cmath>
#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/data_postprocessor.h>
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

    const std::string name =
      "solution-" + Utilities::int_to_string(cycle, 2) + ".vtu";
    write_atomically(parameters.directory + "/" + name,
                     [&](std::ostream &out) { data_out.write_vtu(out); });

    cycles_written.emplace_back(cycle, name);
    write_atomically(parameters.directory + "/solution.pvd",
                     [&](std::ostream &out) {
                       DataOutBase::write_pvd_record(out, cycles_written);
                     });
  }



  template class FieldOutput<2>;
} // namespace membranes
