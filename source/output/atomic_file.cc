#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <membranes/output/atomic_file.h>
#include <membranes/scene/parameters.h>

namespace membranes
{
  void
  write_atomically(const std::string                         &file_name,
                   const std::function<void(std::ostream &)> &write)
  {
    const std::string temporary = file_name + ".tmp";
    errno                       = 0;
    try
      {
        std::ofstream out(temporary);
        if (out)
          write(out);
        out.close();
        if (!out.fail() &&
            std::rename(temporary.c_str(), file_name.c_str()) == 0)
          return;
      }
    catch (...)
      {
        std::remove(temporary.c_str());
        throw;
      }
    const std::string reason = errno != 0 ? std::strerror(errno) : "I/O error";
    std::remove(temporary.c_str());
    const std::filesystem::path path(file_name);
    throw Parameters::invalid_entry("Output/Directory",
                                    path.parent_path().string(),
                                    "cannot write " + path.filename().string() +
                                      " there (" + reason + ")");
  }
} // namespace membranes
