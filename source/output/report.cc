#include <algorithm>
#include <fstream>
#include <iomanip>
#include <membranes/output/atomic_file.h>
#include <membranes/output/report.h>
#include <set>

namespace membranes
{
  namespace
  {
    /**
     * One field of a row of report.csv: the column name, the value (empty
     * when the run does not compute it), whether it counts something (a
     * whole number), and for a column against the exact solution the error
     * column of `Exact solution/Norms` without which the run leaves it out.
     */
    struct Field
    {
      std::string           name;
      std::optional<double> value;
      bool                  count = false;
      std::string           norm  = "";
    };

    /** The row of one cycle, its fields in the order of the columns. */
    std::vector<Field>
    row(const CycleRecord &r)
    {
      const bool count = true;
      // The columns against the exact solution.
      const auto error = [&r](const std::string          &name,
                              const std::optional<double> ErrorRecord::*norm) {
        return Field{name, r.errors.*norm, false, name};
      };
      const auto flux = [&r](const double FluxRecord::*part) {
        return r.flux ? std::optional<double>((*r.flux).*part) : std::nullopt;
      };
      const auto flux_defect =
        [&r](const std::optional<double> FluxRecord::*defect) {
          return r.flux ? (*r.flux).*defect : std::nullopt;
        };
      const auto effectivity = [&r](const std::string           &name,
                                    const std::optional<double> &estimator) {
        return Field{name,
                     estimator && r.errors.energy ?
                       std::optional<double>(*estimator / *r.errors.energy) :
                       std::nullopt,
                     false,
                     "err_energy"};
      };
      const std::optional<double> flux_estimator = flux(&FluxRecord::estimator);
      const SolveRecord          &solve          = r.solve;
      const IdentityRecord       &identities     = r.identities;
      const TimeRecord           &times          = r.times;
      return {{"cycle", r.mesh.cycle, count},
              {"cells", r.mesh.cells, count},
              {"dofs", static_cast<double>(r.mesh.dofs), count},
              {"active_set_iterations", solve.active_set_iterations, count},
              {"active_vertices", solve.active_vertices, count},
              {"wall_time_s", times.method()},
              {"cumulative_wall_time_s", r.cumulative_wall_time},
              error("err_u1_H1", &ErrorRecord::u1_H1),
              error("err_u2_H1", &ErrorRecord::u2_H1),
              error("err_u1_L2", &ErrorRecord::u1_L2),
              error("err_u2_L2", &ErrorRecord::u2_L2),
              error("err_lambda_L2", &ErrorRecord::lambda_L2),
              {"estimator", r.estimator},
              effectivity("effectivity", r.estimator),
              {"kkt_residual", solve.kkt_residual},
              {"min_w", identities.min_w},
              {"min_lambda", identities.min_lambda},
              {"prop12_defect", identities.prop12_defect},
              {"complementarity_defect", identities.complementarity_defect},
              {"linear_iterations", solve.linear_iterations, count},
              {"time_setup_s", times.setup},
              {"time_assembly_s", times.assembly},
              {"time_solve_s", times.solve},
              {"time_postprocess_s", times.postprocess},
              error("err_energy", &ErrorRecord::energy),
              {"time_estimate_s", times.estimate},
              {"flux_estimator", flux_estimator},
              effectivity("flux_effectivity", flux_estimator),
              {"measure_defect", flux_defect(&FluxRecord::measure_defect)},
              {"conservation_defect",
               flux_defect(&FluxRecord::conservation_defect)},
              {"balance_defect", flux_defect(&FluxRecord::balance_defect)},
              {"time_flux_s", times.flux},
              {"levels", r.mesh.levels, count},
              {"processes", r.processes, count},
              {"memory_mb", r.memory_mb},
              {"eta_linearization", solve.linearization_estimate},
              {"eta_algebraic", solve.algebraic_estimate},
              {"flux_estimator_flux", flux(&FluxRecord::flux)},
              {"flux_estimator_oscillation", flux(&FluxRecord::oscillation)},
              {"flux_estimator_contact", flux(&FluxRecord::contact)},
              {"flux_estimator_boundary", flux(&FluxRecord::boundary)},
              {"time_errors_s", times.errors},
              error("err_lambda_L2_omega_h", &ErrorRecord::lambda_L2_omega_h),
              error("err_lambda_Hm1", &ErrorRecord::lambda_Hm1)};
    }
  } // namespace



  Report::Report(const Parameters::Output        &parameters,
                 const Parameters::ExactSolution &exact,
                 const ConditionalOStream        &pcout)
    : parameters(parameters)
    , exact(exact)
    , pcout(pcout)
  {}



  std::pair<std::vector<bool>, std::string>
  Report::columns() const
  {
    // Every column but those against the exact solution that this run does
    // not compute.
    const std::vector<Field> names = row(CycleRecord());
    std::vector<bool>        written(names.size());
    std::string              header;
    for (unsigned int c = 0; c < names.size(); ++c)
      {
        written[c] = names[c].norm.empty() || exact.computes(names[c].norm);
        if (written[c])
          header += (header.empty() ? "" : ",") + names[c].name;
      }
    return {written, header};
  }



  void
  Report::add(const CycleRecord &record)
  {
    records.push_back(record);
    if (!parameters.report || !pcout.is_active())
      return;
    const auto [written, header] = columns();
    write_atomically(parameters.directory + "/report.csv",
                     [&](std::ostream &out) {
                       out << header << '\n';
                       for (const std::string &line : earlier_rows)
                         out << line << '\n';
                       out << std::setprecision(12);
                       for (const CycleRecord &r : records)
                         {
                           const auto  fields    = row(r);
                           const char *separator = "";
                           for (unsigned int c = 0; c < fields.size(); ++c)
                             if (written[c])
                               {
                                 out << separator;
                                 separator = ",";
                                 if (fields[c].value)
                                   out << *fields[c].value;
                               }
                           out << '\n';
                         }
                     });
  }



  void
  Report::resume(const unsigned int last_cycle)
  {
    if (!parameters.report)
      return;
    // Every process reads the file, so that all stop alike if it does not
    // fit.
    const std::string name = parameters.directory + "/report.csv";
    std::ifstream     in(name);
    std::string       line;
    if (!std::getline(in, line) || line != columns().second)
      throw Parameters::CollectiveError(
        "Output/Resume: " + name +
        " is missing or has other columns than this scene writes");
    while (std::getline(in, line))
      {
        const std::string cycle = line.substr(0, line.find(','));
        if (cycle.empty() ||
            cycle.find_first_not_of("0123456789") != std::string::npos)
          throw Parameters::CollectiveError("Output/Resume: " + name +
                                            " has a row that is not one: '" +
                                            line + "'");
        if (std::stoul(cycle) <= last_cycle)
          earlier_rows.push_back(line);
      }
    if (earlier_rows.size() != last_cycle + 1)
      throw Parameters::CollectiveError(
        "Output/Resume: " + name + " holds " +
        std::to_string(earlier_rows.size()) + " rows up to cycle " +
        std::to_string(last_cycle) + ", the cycle of the checkpoint");
  }



  void
  Report::print_convergence_table(const bool rates_in_dofs)
  {
    ConvergenceTable               table;
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
                                         "err_lambda_Hm1",
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
      for (const Field &field : row(record))
        if (std::find(shown.begin(), shown.end(), field.name) != shown.end() &&
            field.value)
          {
            if (field.count)
              table.add_value(field.name,
                              static_cast<unsigned long long>(*field.value));
            else
              table.add_value(field.name, *field.value);
            filled.insert(field.name);
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
