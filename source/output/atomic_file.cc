#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <membranes/output/atomic_file.h>
#include <sstream>
#include <unistd.h>

namespace membranes
{
  namespace
  {
    /**
     * Create or truncate the file @p file_name and write @p text to it;
     * 0, or the error number (errno) of the first step that failed.
     */
    int
    write_file(const std::string &file_name, const std::string &text)
    {
      const int file = ::open(file_name.c_str(),
                              O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC,
                              0666);
      if (file < 0)
        return errno;
      int error = 0;
      for (std::size_t written = 0; written < text.size() && error == 0;)
        {
          const ssize_t n =
            ::write(file, text.data() + written, text.size() - written);
          if (n >= 0)
            written += n;
          else if (errno != EINTR)
            error = errno;
        }
      if (::close(file) != 0 && error == 0)
        error = errno;
      return error;
    }
  } // namespace



  void
  write_atomically(const std::string                         &file_name,
                   const std::function<void(std::ostream &)> &write)
  {
    std::ostringstream text;
    write(text);
    const std::string temporary = file_name + ".tmp";
    int               error     = write_file(temporary, text.str());
    if (error == 0 && std::rename(temporary.c_str(), file_name.c_str()) != 0)
      error = errno;
    if (error == 0)
      return;
    std::remove(temporary.c_str());
    throw file_error("write", file_name, error);
  }



  Parameters::InputError
  file_error(const std::string &action,
             const std::string &file_name,
             const int          error)
  {
    const std::filesystem::path path(file_name);
    const std::string           directory = path.parent_path().string();
    // A long directory by its last characters (whole ones of UTF-8).
    const std::size_t longest = 80;
    std::size_t       start =
      directory.size() > longest ? directory.size() - longest : 0;
    while (start > 0 && (directory[start] & 0xc0) == 0x80)
      ++start;
    const std::string shown =
      (start > 0 ? "..." : "") + directory.substr(start);
    return Parameters::InputError(
      "Output/Directory = '" + shown + "': cannot " + action + " " +
      path.filename().string() + " (" + std::strerror(error) + ")");
  }
} // namespace membranes
