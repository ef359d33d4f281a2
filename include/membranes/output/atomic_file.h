#ifndef membranes_atomic_file_h
#define membranes_atomic_file_h

#include <functional>
#include <ostream>
#include <string>

namespace membranes
{
  /**
   * Write the file @p file_name with @p write, all or nothing: to a
   * temporary name next to it first, renamed to @p file_name once complete
   * and closed (a rename within a directory replaces a file atomically).
   * Whatever fails, the temporary file is removed, an earlier file
   * @p file_name stays as it was, and the error is an InputError naming
   * `Output/Directory`. So neither a failed write nor a run stopped at any
   * moment leaves a half-written result file.
   */
  void
  write_atomically(const std::string                         &file_name,
                   const std::function<void(std::ostream &)> &write);
} // namespace membranes

#endif
