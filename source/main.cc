/**
 * membranes: the unilateral contact between two elastic membranes,
 *
 *   −μ1 Δu1 − λ = f1,  −μ2 Δu2 + λ = f2,  u1 − u2 ≥ 0,  λ ≥ 0,
 *   (u1 − u2) λ = 0 in ω,  u1 = g, u2 = g2 on ∂ω,
 *
 * by P1/Q1 finite elements, a primal-dual active set method, and the
 * discrete action λ_h on the dual mesh.
 *
 *   membranes [--set "Subsection/Entry=value"]... scene.prm
 *   membranes --print-parameters
 */

#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/utilities.h>
#include <filesystem>
#include <iostream>
#include <membranes/membrane_problem.h>
#include <membranes/parameters.h>
#include <sstream>
#include <string>
#include <vector>

namespace
{
  using namespace dealii;

  const char *usage =
    "Usage: membranes [options] scene.prm\n"
    "\n"
    "Solves the contact problem between two membranes described by the\n"
    "parameter file scene.prm (deal.II ParameterHandler syntax; a scene sets\n"
    "only what differs from the defaults).\n"
    "\n"
    "Options:\n"
    "  -h, --help                 print this message\n"
    "  -p, --print-parameters     print every parameter with its default and\n"
    "                             documentation, in parameter file syntax\n"
    "  -s, --set 'Sub/Entry=val'  override one entry after reading the scene,\n"
    "                             e.g. --set 'Refinement/Cycles=4'\n"
    "\n"
    "Exit status: 0 on success, 1 with a one-line message on any error.\n";

  /** Collapse a multi-line message into one line. */
  std::string
  one_line(const std::string &text)
  {
    std::istringstream in(text);
    std::string        word, line;
    while (in >> word)
      line += (line.empty() ? "" : " ") + word;
    return line;
  }

  std::string
  message_of(const ExceptionBase &e)
  {
    std::ostringstream info;
    e.print_info(info);
    return one_line(info.str());
  }

  /** Apply `Sub/Section/Entry=value` to @p prm. */
  void
  set_entry(ParameterHandler &prm, const std::string &assignment)
  {
    const auto equal = assignment.find('=');
    const auto slash = assignment.rfind('/', equal);
    if (equal == std::string::npos || slash == std::string::npos)
      throw membranes::Parameters::InputError(
        "--set '" + assignment + "': expected 'Subsection/Entry=value'");
    const auto subsections =
      Utilities::split_string_list(assignment.substr(0, slash), '/');
    const std::string entry =
      Utilities::trim(assignment.substr(slash + 1, equal - slash - 1));
    const std::string value = Utilities::trim(assignment.substr(equal + 1));
    for (const auto &subsection : subsections)
      prm.enter_subsection(subsection);
    try
      {
        prm.set(entry, value);
      }
    catch (const ExceptionBase &e)
      {
        throw membranes::Parameters::InputError("--set '" + assignment +
                                                "': " + message_of(e));
      }
    for (unsigned int i = 0; i < subsections.size(); ++i)
      prm.leave_subsection();
  }
} // namespace



int
main(int argc, char **argv)
{
  using namespace membranes;
  Utilities::MPI::MPI_InitFinalize mpi_initialization(argc, argv, 1);
  const bool                       first_process =
    (Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0);

  try
    {
      ParameterHandler prm;
      Parameters::All::declare_parameters(prm);

      std::vector<std::string> assignments;
      std::string              scene;
      for (int i = 1; i < argc; ++i)
        {
          const std::string arg = argv[i];
          if (arg == "-h" || arg == "--help")
            {
              if (first_process)
                std::cout << usage;
              return 0;
            }
          else if (arg == "-p" || arg == "--print-parameters")
            {
              if (first_process)
                prm.print_parameters(std::cout, ParameterHandler::PRM);
              return 0;
            }
          else if (arg == "-s" || arg == "--set")
            {
              if (i + 1 == argc)
                throw Parameters::InputError(arg + " needs an argument");
              assignments.push_back(argv[++i]);
            }
          else if (!arg.empty() && arg[0] == '-')
            throw Parameters::InputError("unknown option '" + arg +
                                         "' (see --help)");
          else if (scene.empty())
            scene = arg;
          else
            throw Parameters::InputError("more than one scene file given ('" +
                                         scene + "', '" + arg + "')");
        }
      if (scene.empty())
        throw Parameters::InputError("no scene file given (see --help)");

      try
        {
          prm.parse_input(scene, "", false, false);
        }
      catch (const ExceptionBase &e)
        {
          throw Parameters::InputError(scene + ": " + message_of(e));
        }
      for (const auto &assignment : assignments)
        set_entry(prm, assignment);

      Parameters::All parameters;
      parameters.parse_parameters(prm);
      // A relative mesh file is found next to the scene that names it.
      auto &mesh_file = parameters.geometry.mesh_file;
      if (!mesh_file.empty() && std::filesystem::path(mesh_file).is_relative())
        mesh_file =
          (std::filesystem::path(scene).parent_path() / mesh_file).string();

      MembraneProblem<2> problem(parameters);
      problem.run();
    }
  catch (const ExceptionBase &e)
    {
      if (first_process)
        std::cerr << "membranes: error: " << e.get_exc_name() << ": "
                  << message_of(e) << std::endl;
      return 1;
    }
  catch (const std::exception &e)
    {
      if (first_process)
        std::cerr << "membranes: error: " << one_line(e.what()) << std::endl;
      return 1;
    }
  return 0;
}
