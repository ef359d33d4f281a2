#ifndef membranes_atomic_file_h
#define membranes_atomic_file_h

#include <functional>
#include <membranes/scene/parameters.h>
#include <ostream>
#include <string>

namespace membranes
{
  /**
   * Write the file @p file_name with @p write, all or nothing. @p write
   * writes into memory; an exception it throws passes through before any
   * file is touched. The text then goes to a temporary name next to
   * @p file_name (the name with `.tmp` appended), which is renamed to
   * @p file_name once complete and closed (a rename within a directory
   * replaces a file atomically).
   *
   * If the system refuses any step (no space left on the device, a file
   * size limit, no permission, the directory removed), the temporary file
   * is removed, an earlier file @p file_name stays as it was, and the error
   * is the file_error() of the step. So neither a failed write nor a run
   * stopped at any moment leaves a half-written result file; only a
   * directory made read-only during a write keeps the temporary file, which
   * the next run on the directory removes.
   *
   * A file size limit (`ulimit -f`) fails a write only if the signal
   * SIGXFSZ is ignored, as main() does; otherwise the system ends the
   * process.
   */
  void
  write_atomically(const std::string                         &file_name,
                   const std::function<void(std::ostream &)> &write);

  /**
   * The error for the file @p file_name in the output directory that the
   * system refused to @p action ("write", "lock", ...) for the reason
   * @p error (an errno value): one line,
   * `Output/Directory = 'dir': cannot write name (reason)` with the
   * system's text of the reason ("No space left on device", "File too
   * large", ...), shorter than 200 characters: a directory longer than 80
   * characters is shown by its end.
   */
  Parameters::InputError
  file_error(const std::string &action,
             const std::string &file_name,
             const int          error);
} // namespace membranes

#endif
