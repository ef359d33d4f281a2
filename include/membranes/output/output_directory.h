#ifndef membranes_output_directory_h
#define membranes_output_directory_h

#include <deal.II/base/mpi.h>
#include <string>

namespace membranes
{
  /** What a run records about itself in its output directory. */
  struct Provenance
  {
    /** Every parameter as the run uses it (Parameters::parameter_file()). */
    std::string parameters;
    /** The command line, each word quoted for a POSIX shell where needed. */
    std::string command_line;
  };

  /**
   * `Output/Directory`, held by one run for its whole life, so that the
   * directory holds the results of that run only, and says how they were
   * made.
   *
   * claim() creates the directory if it is missing and takes an exclusive
   * advisory lock (flock) on the file `.membranes-lock` in it. The kernel
   * releases the lock when the process ends, however it ends, so a killed
   * run never blocks the next one; a directory that another run holds is
   * refused with one line naming it. Holding the lock, claim() removes the
   * files that an earlier run of the program wrote there (its own names
   * only, see remove_earlier_output()) and records this run:
   * `parameters.prm`, every parameter as the run uses it, from which
   * `membranes parameters.prm` makes the same run, and `run-info.txt`,
   * the version of the program (the git commit it was built from, or
   * "unknown"), the command line, the working directory and the number of
   * processes.
   *
   * The first process decides and does all this; the others follow its
   * decision, so that a refusal ends every process alike (a
   * Parameters::CollectiveError).
   *
   * The lock lasts as long as this object. A run that made the directory
   * and ends by an error before it wrote anything but its records into it
   * removes the directory again, so that a scene rejected on the first mesh
   * leaves nothing behind.
   */
  class OutputDirectory
  {
  public:
    OutputDirectory(const std::string &directory,
                    const Provenance  &provenance,
                    const MPI_Comm     mpi_communicator);

    /** Releases the lock (see the class documentation). */
    ~OutputDirectory();

    OutputDirectory(const OutputDirectory &) = delete;
    OutputDirectory &
    operator=(const OutputDirectory &) = delete;

    /**
     * Whether the directory can be created, found out before the first
     * cycle and without leaving anything behind: every part of its path
     * that exists must be a directory, and in the deepest one that exists a
     * directory must be creatable (a probe, removed at once; a read-only or
     * virtual file system such as /proc refuses it); an InputError naming
     * `Output/Directory` otherwise, on every process alike. The directory
     * itself is created by claim(), after the checks of the data on the
     * coarse mesh.
     */
    void
    check() const;

    /**
     * Create the directory @p name in the claimed directory (for
     * unconverged/), on the first process, for all processes to write
     * into; returns its path.
     */
    std::string
    create_subdirectory(const std::string &name) const;

    /**
     * Claim the directory as the class documentation says; a
     * Parameters::CollectiveError if it is in use or any step fails. With
     * @p resume, the earlier output stays, and the scene must be the one
     * that wrote it (check_resumed_scene()).
     */
    void
    claim(const bool resume);

  private:
    /**
     * Create the directory if missing and take the lock on its lock file;
     * an InputError if another process holds it, the file_error() of a
     * step that the system refuses.
     */
    void
    lock();

    /**
     * That the parameters.prm of the directory records the scene of this
     * run but for the number of cycles and the entries of `Output` that
     * say what is written where; an InputError naming the first entry that
     * differs otherwise.
     */
    void
    check_resumed_scene() const;

    /**
     * Remove what an earlier run of the program wrote into the directory,
     * recognized by name and kind: the regular files report.csv,
     * solution-NN.vtu, solution-NN.PPPP.vtu, solution-NN.pvtu,
     * solution.pvd, the same of dual-mesh, nodal-values-NN.csv,
     * parameters.prm and run-info.txt, each also with the suffix .tmp of an
     * interrupted write (write_atomically()); the directory unconverged/
     * with the same files in it (it stays if anything else is in it); the
     * checkpoint directories checkpoint/, checkpoint.tmp/ and
     * checkpoint.old/ (Checkpoint); and the empty directories
     * .membranes-probe-PID that a run killed in its check of the output
     * directory may leave. Nothing else is touched.
     */
    void
    remove_earlier_output() const;

    const std::string directory;
    const Provenance  provenance;
    const MPI_Comm    mpi_communicator;
    /** The open lock file, while this run holds the directory; else -1. */
    int lock_file = -1;
    /** Whether this run created the directory. */
    bool created = false;
  };
} // namespace membranes

#endif
