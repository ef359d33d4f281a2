/**
 * membranes: the unilateral contact between two elastic membranes,
 *
 *   −μ1 Δu1 − λ = f1,  −μ2 Δu2 + λ = f2,  u1 − u2 ≥ 0,  λ ≥ 0,
 *   (u1 − u2) λ = 0 in ω,  u1 = g, u2 = g2 on ∂ω,
 *
 * by P1/Q1 finite elements, a primal-dual active set method, and the
 * discrete action λ_h on the dual mesh.
 *
 *   membranes [--set "Subsection/Entry=value"]... [--resume] scene.prm
 *   membranes --print-parameters
 */

#include <algorithm>
#include <csignal>
#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/multithread_info.h>
#include <deal.II/base/parameter_handler.h>
#include <filesystem>
#include <iostream>
#include <membranes/membrane_problem.h>
#include <membranes/scene/parameters.h>
#include <sched.h>
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
    "  -r, --resume               continue the study of the output directory\n"
    "                             from its checkpoint (--set 'Output/Resume=true')\n"
    "\n"
    "Run on N processes with 'mpirun -np N membranes scene.prm'.\n"
    "\n"
    "Exit status: 0 on success, 1 with a one-line message on any error.\n";

  /**
   * The command line @p argv, each word as a POSIX shell reads it back:
   * in single quotes unless it consists of characters that need none.
   */
  std::string
  command_line(const int argc, char **argv)
  {
    std::string line;
    for (int i = 0; i < argc; ++i)
      {
        const std::string word = argv[i];
        const bool        plain =
          !word.empty() &&
          word.find_first_not_of("abcdefghijklmnopqrstuvwxyz"
                                 "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                                 "_-+=/.,:@%") == std::string::npos;
        std::string quoted = "'";
        for (const char c : word)
          quoted += (c == '\'' ? std::string("'\\''") : std::string(1, c));
        line += (i == 0 ? "" : " ") + (plain ? word : quoted + "'");
      }
    return line;
  }

  /** The number of CPUs in the affinity mask of this process. */
  unsigned int
  cpus_of_this_process()
  {
    cpu_set_t cpus;
    if (sched_getaffinity(0, sizeof(cpus), &cpus) != 0)
      return MultithreadInfo::n_cores();
    return std::max(CPU_COUNT(&cpus), 1);
  }



  /** What the command line asks for. */
  struct Arguments
  {
    bool                     help             = false;
    bool                     print_parameters = false;
    std::vector<std::string> assignments;
    std::string              scene;
  };

  /**
   * The options and the scene file of @p argv; an InputError for an
   * unknown option, a missing scene or a second one.
   */
  Arguments
  read_arguments(const int argc, char **argv)
  {
    Arguments arguments;
    for (int i = 1; i < argc; ++i)
      {
        const std::string arg = argv[i];
        arguments.help        = (arg == "-h" || arg == "--help");
        arguments.print_parameters =
          (arg == "-p" || arg == "--print-parameters");
        if (arguments.help || arguments.print_parameters)
          return arguments;
        if (arg == "-r" || arg == "--resume")
          arguments.assignments.push_back("Output/Resume=true");
        else if (arg == "-s" || arg == "--set")
          {
            if (i + 1 == argc)
              throw membranes::Parameters::InputError(arg +
                                                      " needs an argument");
            arguments.assignments.push_back(argv[++i]);
          }
        else if (!arg.empty() && arg[0] == '-')
          throw membranes::Parameters::InputError("unknown option '" + arg +
                                                  "' (see --help)");
        else if (arguments.scene.empty())
          arguments.scene = arg;
        else
          throw membranes::Parameters::InputError(
            "more than one scene file given ('" + arguments.scene + "', '" +
            arg + "')");
      }
    if (arguments.scene.empty())
      throw membranes::Parameters::InputError(
        "no scene file given (see --help)");
    return arguments;
  }



  /**
   * The parameters of the scene of @p arguments with its --set assignments
   * applied, read into @p prm and parsed. A relative mesh file is found
   * next to the scene that names it; @p prm, the record of the parameters,
   * names it by its absolute path, to be found from the output directory
   * too.
   */
  membranes::Parameters::All
  read_parameters(ParameterHandler &prm, const Arguments &arguments)
  {
    namespace Parameters = membranes::Parameters;
    Parameters::read_scene(prm, arguments.scene);
    for (const auto &assignment : arguments.assignments)
      Parameters::set_entry(prm, assignment);

    Parameters::All parameters;
    parameters.parse_parameters(prm);
    auto &mesh_file = parameters.geometry.mesh_file;
    if (!mesh_file.empty() && std::filesystem::path(mesh_file).is_relative())
      {
        mesh_file =
          (std::filesystem::path(arguments.scene).parent_path() / mesh_file)
            .string();
        Parameters::set_entry(prm,
                              "Geometry/Mesh file=" +
                                std::filesystem::absolute(mesh_file).string());
      }
    return parameters;
  }
} // namespace



int
main(int argc, char **argv)
{
  using namespace membranes;
  // A failed assertion of deal.II (checked in a Debug build only) throws
  // instead of aborting, so that it ends in the one-line error below like
  // every other failure: deal.II's readers assert on some malformed input
  // (a Gmsh cell that names one vertex twice) that they do not check
  // otherwise.
  deal_II_exceptions::disable_abort_on_exception();
  // A write beyond the file size limit (ulimit -f) fails with EFBIG, which
  // write_atomically() reports in one line naming the file, instead of
  // ending the process by the signal SIGXFSZ, without a word.
  std::signal(SIGXFSZ, SIG_IGN);
  // The loops over cells outside the linear solver (data, errors,
  // estimators) run on threads: as many per process as there are cores
  // per process on the node (deal.II's default; DEAL_II_NUM_THREADS limits
  // it), but no more than the CPUs this process may run on. Open MPI binds
  // each process to one core when it starts one or two of them, and two
  // threads on one core are slower than one.
  Utilities::MPI::MPI_InitFinalize mpi_initialization(argc, argv);
  MultithreadInfo::set_thread_limit(
    std::min(MultithreadInfo::n_threads(), cpus_of_this_process()));
  const unsigned int process = Utilities::MPI::this_mpi_process(MPI_COMM_WORLD);
  const bool         first_process = (process == 0);
  const unsigned int n_processes =
    Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD);
  // Up to the start of the run every process reads the same input and
  // fails in the same way; in the run, one process may fail alone (a load
  // that is NaN on its cells), and the others must not wait for it.
  bool running = false;

  try
    {
      ParameterHandler prm;
      Parameters::All::declare_parameters(prm);
      const Arguments arguments = read_arguments(argc, argv);
      if (arguments.help || arguments.print_parameters)
        {
          if (first_process && arguments.help)
            std::cout << usage;
          if (first_process && arguments.print_parameters)
            prm.print_parameters(std::cout, ParameterHandler::PRM);
          return 0;
        }
      const Parameters::All parameters = read_parameters(prm, arguments);
      // The record of the run describes the study: run again, it makes the
      // whole of it, also when this run resumes it.
      prm.enter_subsection("Output");
      prm.set("Resume", false);
      prm.leave_subsection();

      MembraneProblem<2> problem(parameters,
                                 {Parameters::parameter_file(prm),
                                  command_line(argc, argv)});
      running = true;
      problem.run();
    }
  catch (const std::exception &e)
    {
      // The active set method's decision to give up, the refusal of the
      // output directory: every process stops there with the same message.
      const bool on_every_process =
        dynamic_cast<const Parameters::CollectiveError *>(&e) != nullptr;
      if (running && n_processes > 1 && !on_every_process)
        {
          std::cerr << "membranes: error (process " << process << " of "
                    << n_processes << "): " << Parameters::one_line_message(e)
                    << std::endl;
          MPI_Abort(MPI_COMM_WORLD, 1);
        }
      if (first_process)
        std::cerr << "membranes: error: " << Parameters::one_line_message(e)
                  << std::endl;
      return 1;
    }
  catch (...)
    {
      // Libraries may throw what is not a std::exception (muparser does).
      if (first_process)
        std::cerr << "membranes: error: unexpected exception" << std::endl;
      return 1;
    }
  return 0;
}
