#include <algorithm>
#include <cerrno>
#include <deal.II/base/mpi.h>
#include <exception>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <membranes/output/atomic_file.h>
#include <membranes/output/output_directory.h>
#include <membranes/scene/parameters.h>
#include <membranes/version.h>
#include <regex>
#include <sstream>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <vector>

namespace membranes
{
  namespace
  {
    namespace fs = std::filesystem;

    const std::string lock_name       = ".membranes-lock";
    const std::string parameters_name = "parameters.prm";
    const std::string run_info_name   = "run-info.txt";

    /**
     * Whether @p name is that of a file that the program writes into an
     * output directory or into its unconverged/, or its temporary name.
     */
    bool
    is_output_file(const std::string &name)
    {
      static const std::regex names(
        "(report\\.csv|parameters\\.prm|run-info\\.txt"
        "|(solution|dual-mesh)(-[0-9]{2,}(\\.[0-9]{4,})?\\.vtu"
        "|-[0-9]{2,}\\.pvtu|\\.pvd)"
        "|nodal-values-[0-9]{2,}\\.csv)(\\.tmp)?");
      return std::regex_match(name, names);
    }

    /**
     * Remove the regular files in @p directory whose names are output
     * names; whether nothing else is in it.
     */
    bool
    remove_output_files(const fs::path &directory)
    {
      bool only_output = true;
      for (const auto &entry : fs::directory_iterator(directory))
        if (entry.symlink_status().type() == fs::file_type::regular &&
            is_output_file(entry.path().filename().string()))
          fs::remove(entry.path());
        else
          only_output = false;
      return only_output;
    }

    /**
     * Create @p directory and its parents where missing; whether it was
     * missing. An InputError naming `Output/Directory` if it cannot be made.
     */
    bool
    create_directory(const std::string &directory)
    {
      std::error_code error;
      const bool      created = fs::create_directories(directory, error);
      if (error || !fs::is_directory(directory))
        throw Parameters::invalid_entry(
          "Output/Directory",
          directory,
          "cannot create this directory (" +
            (error ? error.message() : "a file of that name exists") + ")");
      return created;
    }
  } // namespace



  OutputDirectory::OutputDirectory(const std::string &directory,
                                   const Provenance  &provenance,
                                   const MPI_Comm     mpi_communicator)
    : directory(directory)
    , provenance(provenance)
    , mpi_communicator(mpi_communicator)
  {}



  OutputDirectory::~OutputDirectory()
  {
    if (lock_file < 0)
      return;
    if (created && std::uncaught_exceptions() > 0)
      {
        // A run that fails before its first result: if nothing but its
        // records is in the directory it made, the directory goes too.
        const std::vector<std::string> records{parameters_name,
                                               run_info_name,
                                               lock_name};
        std::error_code                error;
        fs::directory_iterator         entry(directory, error);
        bool                           only_records = !error;
        for (; !error && entry != fs::directory_iterator();
             entry.increment(error))
          only_records &= std::count(records.begin(),
                                     records.end(),
                                     entry->path().filename().string()) > 0;
        if (only_records && !error)
          {
            for (const std::string &name : records)
              fs::remove(directory + "/" + name, error);
            fs::remove(directory, error);
          }
      }
    ::close(lock_file);
  }



  void
  OutputDirectory::check() const
  {
    std::string problem;
    if (dealii::Utilities::MPI::this_mpi_process(mpi_communicator) == 0)
      {
        std::error_code error;
        const fs::path  path =
          fs::absolute(fs::path(directory).lexically_normal(), error);
        // Up to the deepest part of the path that exists; any other error
        // than a missing part (a file in the path, no permission) is the
        // answer.
        fs::path existing = path;
        while (!error &&
               fs::status(existing, error).type() == fs::file_type::not_found &&
               existing != existing.parent_path())
          {
            error.clear();
            existing = existing.parent_path();
          }
        // The probe: the first missing part of the path itself (its name
        // may be too long), or a new name inside the existing directory.
        const fs::path probe =
          existing == path ?
            existing / (".membranes-probe-" + std::to_string(::getpid())) :
            existing / *fs::relative(path, existing).begin();
        if (error)
          problem = error.message();
        else if (!fs::is_directory(existing))
          problem = existing.string() + " is not a directory";
        else if (!fs::create_directory(probe, error))
          problem = "no directory can be made in " + existing.string() +
                    (error ? " (" + error.message() + ")" : "");
        else
          fs::remove(probe, error);
      }
    problem = dealii::Utilities::MPI::broadcast(mpi_communicator, problem, 0);
    if (!problem.empty())
      throw Parameters::invalid_entry("Output/Directory",
                                      directory,
                                      "cannot create this directory (" +
                                        problem + ")");
  }



  std::string
  OutputDirectory::create_subdirectory(const std::string &name) const
  {
    const std::string subdirectory = directory + "/" + name;
    if (dealii::Utilities::MPI::this_mpi_process(mpi_communicator) == 0)
      create_directory(subdirectory);
    // The other processes write their own pieces into it.
    const int ierr = MPI_Barrier(mpi_communicator);
    AssertThrowMPI(ierr);
    return subdirectory;
  }



  void
  OutputDirectory::claim(const bool resume)
  {
    std::string problem;
    if (dealii::Utilities::MPI::this_mpi_process(mpi_communicator) == 0)
      try
        {
          lock();
          if (resume)
            check_resumed_scene();
          else
            remove_earlier_output();
          write_atomically(
            directory + "/" + parameters_name, [this](std::ostream &out) {
              out << "# The parameters of the run that wrote this "
                     "directory (see run-info.txt);\n"
                  << "# 'membranes parameters.prm' runs it again.\n"
                  << provenance.parameters;
            });
          std::error_code   error;
          const std::string working_directory =
            fs::current_path(error).string();
          write_atomically(
            directory + "/" + run_info_name, [&](std::ostream &out) {
              out << "version: " << MEMBRANES_VERSION << '\n'
                  << "command: " << provenance.command_line << '\n'
                  << "working directory: " << working_directory << '\n'
                  << "processes: "
                  << dealii::Utilities::MPI::n_mpi_processes(mpi_communicator)
                  << '\n';
            });
        }
      catch (const std::exception &error)
        {
          problem = Parameters::one_line_message(error);
        }
    // Also the other processes' wait for the directory, into which they
    // write their pieces of the field output.
    problem = dealii::Utilities::MPI::broadcast(mpi_communicator, problem, 0);
    if (!problem.empty())
      throw Parameters::CollectiveError(problem);
  }



  void
  OutputDirectory::lock()
  {
    created                     = create_directory(directory);
    const std::string lock_path = directory + "/" + lock_name;
    // A failing run that made the directory removes the lock file while it
    // holds it (see the destructor): a lock taken on the file that another
    // process opened before is on a file without a name, and is taken anew.
    for (unsigned int attempt = 0; attempt < 10; ++attempt)
      {
        const int file =
          ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
        if (file < 0)
          throw file_error("open", lock_path, errno);
        if (::flock(file, LOCK_EX | LOCK_NB) != 0)
          {
            const int reason = errno;
            // Who holds it, at most a line of text.
            char              text[200];
            const ssize_t     length = ::pread(file, text, sizeof(text) - 1, 0);
            const std::string holder =
              length > 0 ? std::string(text, length) : "";
            ::close(file);
            if (reason == EWOULDBLOCK)
              throw Parameters::InputError(
                "Output/Directory = '" + directory +
                "' is in use by another run" +
                (holder.empty() ? "" : " (" + holder + ")"));
            throw file_error("lock", lock_path, reason);
          }
        struct stat locked, named;
        if (::fstat(file, &locked) == 0 &&
            ::stat(lock_path.c_str(), &named) == 0 &&
            locked.st_dev == named.st_dev && locked.st_ino == named.st_ino)
          {
            lock_file = file;
            // Who holds it, for the message of a refused run.
            char host[256] = "";
            ::gethostname(host, sizeof(host) - 1);
            const std::string holder =
              "process " + std::to_string(::getpid()) + " on " + host;
            if (::ftruncate(file, 0) != 0 ||
                ::pwrite(file, holder.data(), holder.size(), 0) < 0)
              throw file_error("write", lock_path, errno);
            return;
          }
        ::close(file);
      }
    throw Parameters::invalid_entry("Output/Directory",
                                    directory,
                                    "cannot lock it: its lock file " +
                                      lock_name + " keeps being replaced");
  }



  void
  OutputDirectory::check_resumed_scene() const
  {
    // The entries a resumed study may change: the number of cycles, and
    // what the run writes where (but the fluxes, which are columns of the
    // report).
    static const std::vector<std::string> free{"Refinement/Cycles",
                                               "Output/Directory",
                                               "Output/Report",
                                               "Output/Write vtu",
                                               "Output/Write nodal values",
                                               "Output/Checkpoint every",
                                               "Output/Resume"};
    std::ifstream                         in(directory + "/" + parameters_name);
    if (!in)
      throw Parameters::InputError("Output/Resume: " + directory +
                                   " holds no study to resume (no " +
                                   parameters_name + ")");
    std::stringstream recorded;
    recorded << in.rdbuf();
    std::string difference;
    try
      {
        difference = Parameters::first_difference(recorded.str(),
                                                  provenance.parameters,
                                                  free);
      }
    catch (const std::exception &error)
      {
        throw Parameters::InputError(
          "Output/Resume: " + directory + "/" + parameters_name +
          " does not read: " + Parameters::one_line_message(error));
      }
    if (!difference.empty())
      throw Parameters::InputError(
        "Output/Resume: the scene is not the one that wrote " + directory +
        ": " + difference);
  }



  void
  OutputDirectory::remove_earlier_output() const
  {
    const fs::path path(directory);
    try
      {
        remove_output_files(path);
        for (const auto &entry : fs::directory_iterator(path))
          {
            const std::string name = entry.path().filename().string();
            if (entry.symlink_status().type() != fs::file_type::directory)
              continue;
            if (name == "unconverged" && remove_output_files(entry.path()))
              fs::remove(entry.path());
            else if (std::regex_match(name,
                                      std::regex("checkpoint(\\.tmp|\\.old)?")))
              fs::remove_all(entry.path());
            else if (std::regex_match(name,
                                      std::regex("\\.membranes-probe-[0-9]+")))
              {
                std::error_code not_empty;
                fs::remove(entry.path(), not_empty);
              }
          }
      }
    catch (const fs::filesystem_error &error)
      {
        throw Parameters::invalid_entry(
          "Output/Directory",
          directory,
          "cannot remove the output of an earlier run there (" +
            error.path1().filename().string() + ": " + error.code().message() +
            ")");
      }
  }
} // namespace membranes
