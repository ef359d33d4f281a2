#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <dlfcn.h>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <membranes/scene/compiled_function.h>
#include <membranes/scene/expression_translation.h>
#include <random>
#include <spawn.h>
#include <sstream>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

extern char **environ;

namespace membranes
{
  namespace
  {
    /** The compiler: `MEMBRANES_CXX`, or the one that built the program. */
    std::string
    compiler()
    {
      const char *variable = std::getenv("MEMBRANES_CXX");
      return variable != nullptr && *variable != '\0' ? variable :
                                                        MEMBRANES_CXX_COMPILER;
    }

    /**
     * The flags of the compiler. -O3 vectorizes the loops of the groups
     * with vector math; -fno-trapping-math lets it evaluate both branches
     * of a conditional for several points and blend them. sin and cos as
     * plain functions: see the prelude of the generated source. No
     * reordering and no contraction into fused multiply-adds
     * (-ffp-contract=off): every operation is rounded as the parser rounds
     * it. AVX2 and FMA (four points at once) where the processor has
     * them: they are then part of the cache key, so that a cache shared
     * between machines holds one object for each kind.
     */
    std::vector<std::string>
    compiler_flags()
    {
      std::vector<std::string> flags{"-std=c++17",
                                     "-O3",
                                     "-fno-math-errno",
                                     "-fno-trapping-math",
                                     "-ffp-contract=off",
                                     "-fno-builtin-sin",
                                     "-fno-builtin-cos",
                                     "-fPIC",
                                     "-shared",
                                     "-w"};
#if defined(__x86_64__) && defined(__GNUC__)
      if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
        flags.insert(flags.end(), {"-mavx2", "-mfma"});
#endif
      return flags;
    }

    /** FNV-1a, 64 bits, as 16 hexadecimal digits. */
    std::string
    hash(const std::string &text)
    {
      std::uint64_t h = 14695981039346656037ull;
      for (const unsigned char c : text)
        h = (h ^ c) * 1099511628211ull;
      std::ostringstream out;
      out << std::hex << std::setw(16) << std::setfill('0') << h;
      return out.str();
    }

    /**
     * What identifies the compiler in the cache key: its command, and the
     * size and time of modification of its file (when found), so that an
     * upgraded compiler compiles anew.
     */
    std::string
    compiler_identity(const std::string &command)
    {
      std::string identity = command;
      for (const auto &flag : compiler_flags())
        identity += " " + flag;
      struct stat status;
      if (stat(command.c_str(), &status) == 0)
        identity += " " + std::to_string(status.st_size) + " " +
                    std::to_string(status.st_mtime);
      return identity;
    }

    /**
     * Run @p arguments (no shell), its output to @p log; the exit status,
     * or -1 if it could not be started.
     */
    int
    run(std::vector<std::string> arguments, const std::string &log)
    {
      // posix_spawnp() takes the arguments as char *: those of the copy.
      std::vector<char *> argv;
      for (std::string &argument : arguments)
        argv.push_back(argument.data());
      argv.push_back(nullptr);
      posix_spawn_file_actions_t actions;
      posix_spawn_file_actions_init(&actions);
      posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
      posix_spawn_file_actions_addopen(
        &actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
      posix_spawn_file_actions_adddup2(&actions, 1, 2);
      pid_t     pid = 0;
      const int error =
        posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
      posix_spawn_file_actions_destroy(&actions);
      if (error != 0)
        return -1;
      int status = 0;
      while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR)
          return -1;
      return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }

    /** Whether @p directory can be created (if needed) and written to. */
    bool
    usable(const std::filesystem::path &directory)
    {
      std::error_code error;
      std::filesystem::create_directories(directory, error);
      return std::filesystem::is_directory(directory, error) &&
             access(directory.c_str(), W_OK | X_OK) == 0;
    }

    /**
     * Compile @p source into the shared object @p target: under temporary
     * names of this process in the same directory, then renamed (atomic),
     * so that a concurrent run sees either no file or the whole one.
     */
    void
    compile(const std::string &source, const std::string &target)
    {
      std::random_device random;
      const std::string  stem = target + "." + std::to_string(getpid()) + "." +
                               std::to_string(random()) + ".tmp";
      const std::string source_file = stem + ".cc", object = stem + ".so",
                        log = stem + ".log";
      {
        std::ofstream out(source_file);
        out << source;
        if (!out.flush())
          throw CompiledFunctions::Unavailable(
            "cannot write the generated source '" + source_file + "'");
      }
      std::vector<std::string> command{compiler()};
      for (const auto &flag : compiler_flags())
        command.push_back(flag);
      command.insert(command.end(), {source_file, "-o", object});
      const int     status = run(command, log);
      std::string   message;
      std::ifstream log_file(log);
      std::getline(log_file, message);
      std::remove(source_file.c_str());
      std::remove(log.c_str());
      if (status != 0 || std::rename(object.c_str(), target.c_str()) != 0)
        {
          std::remove(object.c_str());
          throw CompiledFunctions::Unavailable(
            "the C++ compiler '" + compiler() + "' " +
            (status < 0 ? std::string("could not be run") :
                          "failed (exit status " + std::to_string(status) +
                            (message.empty() ? "" : ": " + message) + ")") +
            "; set MEMBRANES_CXX to a working one");
        }
    }

    /**
     * The directory of the cached shared objects: `MEMBRANES_CACHE_DIR`,
     * else `$XDG_CACHE_HOME/membranes`, else `$HOME/.cache/membranes`,
     * the first that can be created and written; else a directory of this
     * user in the system's temporary directory. Throws Unavailable if none
     * can be.
     */
    std::string
    cache_directory()
    {
      std::vector<std::filesystem::path> candidates;
      if (const char *variable = std::getenv("MEMBRANES_CACHE_DIR");
          variable != nullptr && *variable != '\0')
        candidates.emplace_back(variable);
      else
        {
          if (const char *xdg = std::getenv("XDG_CACHE_HOME");
              xdg != nullptr && *xdg == '/')
            candidates.emplace_back(std::filesystem::path(xdg) / "membranes");
          if (const char *home = std::getenv("HOME");
              home != nullptr && *home == '/')
            candidates.emplace_back(std::filesystem::path(home) / ".cache" /
                                    "membranes");
        }
      for (const auto &candidate : candidates)
        if (usable(candidate))
          return candidate.string();

      // A directory of this user only: another user could place an object
      // to be loaded in a directory that is not.
      std::error_code             error;
      const std::filesystem::path temporary =
        std::filesystem::temp_directory_path(error) /
        ("membranes-" + std::to_string(getuid()));
      mkdir(temporary.c_str(), 0700);
      struct stat status;
      if (!error && lstat(temporary.c_str(), &status) == 0 &&
          S_ISDIR(status.st_mode) && status.st_uid == getuid() &&
          (status.st_mode & 022) == 0 && usable(temporary))
        return temporary.string();
      throw CompiledFunctions::Unavailable(
        "no cache directory can be written (set "
        "MEMBRANES_CACHE_DIR to one)");
    }
  } // namespace



  CompiledFunctions::CompiledFunctions(
    const std::vector<Request>          &requests,
    const std::vector<std::string>      &variables,
    const std::map<std::string, double> &constants,
    const std::vector<Group>            &groups)
  {
    const auto        start = std::chrono::steady_clock::now();
    const std::string source =
      generated_source(requests, variables, constants, groups);
    const std::string target = cache_directory() + "/expressions-" +
                               hash(source + compiler_identity(compiler())) +
                               ".so";
    if (access(target.c_str(), R_OK) != 0)
      {
        compile(source, target);
        compiled_now = true;
      }
    handle = dlopen(target.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr && !compiled_now)
      {
        // A cached object that does not load (from another system, say):
        // compiled anew in its place.
        compile(source, target);
        compiled_now = true;
        handle       = dlopen(target.c_str(), RTLD_NOW | RTLD_LOCAL);
      }
    if (handle == nullptr)
      throw Unavailable("cannot load '" + target + "': " + dlerror());
    seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
        .count();
  }



  CompiledFunctions::~CompiledFunctions()
  {
    dlclose(handle);
  }



  void *
  CompiledFunctions::symbol(const std::string &kind, const unsigned int i) const
  {
    const std::string name    = "membranes_" + kind + "_" + std::to_string(i);
    void             *address = dlsym(handle, name.c_str());
    if (address == nullptr)
      throw Unavailable("the compiled expressions have no '" + name + "'");
    return address;
  }
} // namespace membranes
