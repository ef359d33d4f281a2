#include <algorithm>
#include <iomanip>
#include <membranes/atomic_file.h>
#include <membranes/report.h>
#include <set>
#include <sstream>

namespace membranes
{
  namespace
  {
    /** The values of one row, in the order of Report::column_names(). */
    std::vector<std::optional<double>>
    row_values(const CycleRecord &r)
    {
      return {r.cycle,
              r.cells,
              static_cast<double>(r.dofs),
              r.active_set_iterations,
              r.active_vertices,
              r.wall_time,
              r.cumulative_wall_time,
              r.err_u1_H1,
              r.err_u2_H1,
              r.err_u1_L2,
              r.err_u2_L2,
              r.err_lambda_L2,
              r.estimator,
              r.effectivity,
              r.kkt_residual,
              r.min_w,
              r.min_lambda,
              r.prop12_defect,
              r.complementarity_defect,
              r.linear_iterations,
              r.time_setup,
              r.time_assembly,
              r.time_solve,
              r.time_postprocess,
              r.err_energy,
              r.time_estimate,
              r.hanging_active_vertices,
              r.flux_estimator,
              r.flux_effectivity,
              r.measure_defect,
              r.conservation_defect,
              r.balance_defect,
              r.time_flux,
              r.levels,
              r.processes,
              r.memory_mb,
              r.linearization_estimate,
              r.algebraic_estimate,
              r.flux_estimator_flux,
              r.flux_estimator_oscillation,
              r.flux_estimator_contact,
              r.flux_estimator_boundary,
              r.time_errors};
    }

    /** Columns that hold whole numbers. */
    bool
    is_count(const std::string &column)
    {
      return column == "cycle" || column == "cells" || column == "dofs" ||
             column == "active_set_iterations" || column == "active_vertices" ||
             column == "linear_iterations" ||
             column == "hanging_active_vertices" || column == "levels" ||
             column == "processes";
    }
  } // namespace



  const std::vector<std::string> &
  Report::column_names()
  {
    static const std::vector<std::string> names{"cycle",
                                                "cells",
                                                "dofs",
                                                "active_set_iterations",
                                                "active_vertices",
                                                "wall_time_s",
                                                "cumulative_wall_time_s",
                                                "err_u1_H1",
                                                "err_u2_H1",
                                                "err_u1_L2",
                                                "err_u2_L2",
                                                "err_lambda_L2",
                                                "estimator",
                                                "effectivity",
                                                "kkt_residual",
                                                "min_w",
                                                "min_lambda",
                                                "prop12_defect",
                                                "complementarity_defect",
                                                "linear_iterations",
                                                "time_setup_s",
                                                "time_assembly_s",
                                                "time_solve_s",
                                                "time_postprocess_s",
                                                "err_energy",
                                                "time_estimate_s",
                                                "hanging_active_vertices",
                                                "flux_estimator",
                                                "flux_effectivity",
                                                "measure_defect",
                                                "conservation_defect",
                                                "balance_defect",
                                                "time_flux_s",
                                                "levels",
                                                "processes",
                                                "memory_mb",
                                                "eta_linearization",
                                                "eta_algebraic",
                                                "flux_estimator_flux",
                                                "flux_estimator_oscillation",
                                                "flux_estimator_contact",
                                                "flux_estimator_boundary",
                                                "time_errors_s"};
    return names;
  }



  Report::Report(const Parameters::Output &parameters,
                 const ConditionalOStream &pcout)
    : parameters(parameters)
    , pcout(pcout)
  {}



  void
  Report::add(const CycleRecord &record)
  {
    records.push_back(record);
    if (parameters.report && pcout.is_active())
      write_csv();
  }



  void
  Report::write_csv() const
  {
    write_atomically(parameters.directory + "/report.csv",
                     [this](std::ostream &out) {
                       const auto &names = column_names();
                       for (unsigned int c = 0; c < names.size(); ++c)
                         out << (c == 0 ? "" : ",") << names[c];
                       out << '\n' << std::setprecision(12);
                       for (const CycleRecord &record : records)
                         {
                           const auto values = row_values(record);
                           for (unsigned int c = 0; c < values.size(); ++c)
                             {
                               if (c > 0)
                                 out << ',';
                               if (values[c])
                                 out << *values[c];
                             }
                           out << '\n';
                         }
                     });
  }



  void
  Report::print_convergence_table(const bool rates_in_dofs)
  {
    ConvergenceTable               table;
    const auto                    &names = column_names();
    const std::vector<std::string> shown{"cycle",
                                         "cells",
                                         "dofs",
                                         "active_set_iterations",
                                         "active_vertices",
                                         "cumulative_wall_time_s",
                                         "err_u1_H1",
                                         "err_u2_H1",
                                         "err_u1_L2",
                                         "err_u2_L2",
                                         "err_lambda_L2",
                                         "err_energy",
                                         "estimator",
                                         "effectivity",
                                         "flux_estimator",
                                         "flux_effectivity"};
    // The columns that have values: the table knows no others (an
    // adaptive run without exact solution has an estimator, but no
    // effectivity).
    std::set<std::string> filled;
    for (const CycleRecord &record : records)
      {
        const auto values = row_values(record);
        for (unsigned int c = 0; c < names.size(); ++c)
          if (std::find(shown.begin(), shown.end(), names[c]) != shown.end() &&
              values[c])
            {
              if (is_count(names[c]))
                table.add_value(names[c],
                                static_cast<unsigned long long>(*values[c]));
              else
                table.add_value(names[c], *values[c]);
              filled.insert(names[c]);
            }
      }
    for (const std::string &column : shown)
      if (filled.count(column) != 0 &&
          (column.rfind("err_", 0) == 0 ||
           column.find("estimator") != std::string::npos ||
           column.find("effectivity") != std::string::npos))
        {
          table.set_precision(column, 3);
          table.set_scientific(column, true);
          if (column.rfind("err_", 0) == 0)
            table.evaluate_convergence_rates(
              column,
              "dofs",
              ConvergenceTable::reduction_rate_log2,
              rates_in_dofs ? 1 : 2);
        }
    table.set_precision("cumulative_wall_time_s", 2);
    const bool with_rates =
      std::any_of(filled.begin(), filled.end(), [](const std::string &c) {
        return c.rfind("err_", 0) == 0;
      });
    if (pcout.is_active())
      {
        pcout << std::endl;
        if (with_rates)
          pcout << (rates_in_dofs ?
                      "Observed rates (red.rate.log2) in DoFs: e ~ N^-rate" :
                      "Observed rates (red.rate.log2) in h: e ~ h^rate, "
                      "h ~ N^-1/2")
                << std::endl;
        table.write_text(pcout.get_stream(),
                         TableHandler::TextOutputFormat::org_mode_table);
      }
  }
} // namespace membranes
