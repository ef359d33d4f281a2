#include <algorithm>
#include <cstdint>
#include <deal.II/distributed/cell_data_transfer.templates.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/lac/la_parallel_vector.h>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <membranes/mesh/discretization.h>
#include <membranes/output/atomic_file.h>
#include <membranes/output/checkpoint.h>
#include <membranes/scene/parameters.h>
#include <memory>
#include <set>
#include <sstream>
#include <tuple>

namespace membranes
{
  namespace
  {
    namespace fs = std::filesystem;

    using DistributedVector = LinearAlgebra::distributed::Vector<double>;

    const std::string format_line = "membranes checkpoint 1";
    const std::string state_name  = "state.txt";
    /** The file of a mesh that every process holds whole. */
    const std::string replicated_name = "replicated.bin";
    /** The refinements of a p4est mesh, by the CellIds of their cells. */
    const std::string history_name = "history.bin";

    /**
     * A 64-bit hash of the bytes of the file @p path: FNV-1a over its
     * 8-byte words (and the bytes of its tail), which sees a changed or
     * missing byte anywhere at the speed of reading the file.
     */
    std::uint64_t
    file_hash(const std::string &path)
    {
      std::ifstream              in(path, std::ios::binary);
      std::uint64_t              hash = 0xcbf29ce484222325ull;
      std::vector<std::uint64_t> buffer(1 << 15);
      while (in)
        {
          in.read(reinterpret_cast<char *>(buffer.data()),
                  buffer.size() * sizeof(std::uint64_t));
          const std::streamsize n = in.gcount();
          for (std::streamsize i = 0; i < n / 8; ++i)
            hash = (hash ^ buffer[i]) * 0x100000001b3ull;
          const auto *tail =
            reinterpret_cast<const unsigned char *>(buffer.data() + n / 8);
          for (std::streamsize i = 0; i < n % 8; ++i)
            hash = (hash ^ tail[i]) * 0x100000001b3ull;
        }
      return hash;
    }

    /**
     * @p problem, found on the first process, as the same
     * Parameters::CollectiveError on every process; nothing if it is empty.
     */
    void
    throw_collective(const std::string &problem, const MPI_Comm communicator)
    {
      const std::string shared =
        Utilities::MPI::broadcast(communicator, problem, 0);
      if (!shared.empty())
        throw Parameters::CollectiveError(shared);
    }

    template <typename T>
    void
    write_binary(std::ostream &out, const std::vector<T> &values)
    {
      const std::uint64_t n = values.size();
      out.write(reinterpret_cast<const char *>(&n), sizeof n);
      out.write(reinterpret_cast<const char *>(values.data()), n * sizeof(T));
    }

    /** What write_binary() wrote; an empty optional if the file ends. */
    template <typename T>
    std::optional<std::vector<T>>
    read_binary(std::istream &in)
    {
      std::uint64_t n = 0;
      if (!in.read(reinterpret_cast<char *>(&n), sizeof n) ||
          n > (std::uint64_t(1) << 40))
        return std::nullopt;
      std::vector<T> values(n);
      if (!in.read(reinterpret_cast<char *>(values.data()), n * sizeof(T)))
        return std::nullopt;
      return values;
    }

    /** @p flags as bytes, one per cell (vector<bool> has no data()). */
    std::vector<char>
    bytes(const std::vector<bool> &flags)
    {
      return std::vector<char>(flags.begin(), flags.end());
    }

    /** A list of (cycle, file) pairs of the state file. */
    void
    write_files(std::ostream                                      &out,
                const std::string                                 &name,
                const std::vector<std::pair<double, std::string>> &files)
    {
      out << name << ' ' << files.size() << '\n';
      for (const auto &[cycle, file] : files)
        out << cycle << ' ' << file << '\n';
    }

    bool
    read_files(std::istream                                &in,
               const std::string                           &name,
               std::vector<std::pair<double, std::string>> &files)
    {
      std::string  word;
      unsigned int n = 0;
      if (!(in >> word >> n) || word != name)
        return false;
      files.resize(n);
      for (auto &[cycle, file] : files)
        if (!(in >> cycle >> file))
          return false;
      return true;
    }

    /** The contents of a state file. */
    struct StateFile
    {
      CheckpointState state;
      std::string     mesh;
      unsigned int    processes  = 0;
      bool            indicators = false;
      /** Each other file of the checkpoint: name, size, hash. */
      std::vector<std::tuple<std::string, std::uintmax_t, std::uint64_t>> files;
    };

    /** The state file @p path; an empty optional if it does not read. */
    std::optional<StateFile>
    read_state(const std::string &path)
    {
      std::ifstream in(path);
      std::string   line, word;
      StateFile     file;
      bool          estimator = false;
      double        value     = 0;
      std::size_t   n_files   = 0;
      if (!std::getline(in, line) || line != format_line ||
          !(in >> word >> file.mesh) || word != "mesh" ||
          !(in >> word >> file.processes) || word != "processes" ||
          !(in >> word >> file.state.cycle) || word != "cycle" ||
          !(in >> word >> file.state.dofs) || word != "dofs" ||
          !(in >> word >> estimator >> value) || word != "estimator" ||
          !(in >> word >> file.state.cumulative_wall_time) ||
          word != "cumulative_wall_time" || !(in >> word >> file.indicators) ||
          word != "indicators" ||
          !read_files(in, "solution_files", file.state.solution_files) ||
          !read_files(in, "dual_mesh_files", file.state.dual_mesh_files) ||
          !(in >> word >> n_files) || word != "files")
        return std::nullopt;
      if (estimator)
        file.state.estimator = value;
      file.files.resize(n_files);
      for (auto &[name, size, hash] : file.files)
        if (!(in >> name >> size >> hash))
          return std::nullopt;
      return file;
    }

    /**
     * What is wrong with the checkpoint in @p directory (empty if there is
     * none) for a mesh of the kind @p mesh; empty if nothing.
     */
    std::string
    problem_of(const std::string &directory, const std::string &mesh)
    {
      if (directory.empty())
        return "Output/Resume: no checkpoint in the output directory (a run "
               "writes one after each cycle with 'Output/Checkpoint every' "
               "> 0)";
      const std::string damaged =
        "the checkpoint " + directory + " is damaged: ";
      const auto file = read_state(directory + "/" + state_name);
      if (!file)
        return damaged + state_name + " does not read";
      if (file->mesh != mesh)
        return "the checkpoint " + directory + " is of a " + file->mesh +
               " mesh, this scene's is " + mesh;
      for (const auto &[name, size, hash] : file->files)
        {
          const std::string path = directory + "/" + name;
          std::error_code   error;
          const auto        found = fs::file_size(path, error);
          if (error)
            return damaged + name + " is missing";
          if (found != size)
            return damaged + name + " has " + std::to_string(found) +
                   " bytes, " + std::to_string(size) + " were written";
          if (file_hash(path) != hash)
            return damaged + name +
                   " is not what was written (its hash "
                   "differs)";
        }
      return "";
    }
  } // namespace



  template <int dim>
  Checkpoint<dim>::Checkpoint(const std::string &output_directory,
                              const MPI_Comm     mpi_communicator)
    : output_directory(output_directory)
    , mpi_communicator(mpi_communicator)
  {}



  template <int dim>
  void
  Checkpoint<dim>::record_refinement(const Triangulation<dim> &triangulation)
  {
    if (dynamic_cast<const parallel::distributed::Triangulation<dim> *>(
          &triangulation) != nullptr)
      {
        // The cells of a p4est mesh by their CellId, which names a cell on
        // any partition; all of them on the first process, which writes
        // them.
        std::array<std::vector<unsigned int>, 2> flagged;
        for (const auto &cell : triangulation.active_cell_iterators())
          if (cell->is_locally_owned())
            for (unsigned int f = 0; f < 2; ++f)
              if (f == 0 ? cell->refine_flag_set() : cell->coarsen_flag_set())
                {
                  const auto id = cell->id().template to_binary<dim>();
                  flagged[f].insert(flagged[f].end(), id.begin(), id.end());
                }
        std::array<std::vector<unsigned int>, 2> all;
        for (unsigned int f = 0; f < 2; ++f)
          for (const auto &part :
               Utilities::MPI::gather(mpi_communicator, flagged[f], 0))
            all[f].insert(all[f].end(), part.begin(), part.end());
        cell_refinements.emplace_back(all[0], all[1]);
        return;
      }
    refinements.emplace_back();
    triangulation.save_refine_flags(refinements.back().first);
    triangulation.save_coarsen_flags(refinements.back().second);
  }



  template <int dim>
  void
  Checkpoint<dim>::write(const State                             &state,
                         const DoFHandler<dim>                   &dof_handler,
                         const std::array<const VectorType *, 3> &vectors,
                         const Vector<double>                    &indicators)
  {
    const bool first = Utilities::MPI::this_mpi_process(mpi_communicator) == 0;
    const std::string written = output_directory + "/checkpoint.tmp";
    std::string       problem;
    if (first)
      try
        {
          fs::remove_all(written);
          fs::create_directory(written);
        }
      catch (const fs::filesystem_error &error)
        {
          problem = "cannot write a checkpoint into " + written + ": " +
                    error.code().message();
        }
    throw_collective(problem, mpi_communicator);

    const auto *const distributed =
      dynamic_cast<const parallel::distributed::Triangulation<dim> *>(
        &dof_handler.get_triangulation());
    if (distributed != nullptr)
      problem = write_distributed(written, dof_handler, vectors, indicators);
    else
      problem = write_replicated(written, dof_handler, vectors, indicators);
    throw_collective(problem, mpi_communicator);
    const int ierr = MPI_Barrier(mpi_communicator);
    AssertThrowMPI(ierr);

    if (first)
      try
        {
          std::vector<std::string> names;
          for (const auto &entry : fs::directory_iterator(written))
            names.push_back(entry.path().filename().string());
          std::sort(names.begin(), names.end());
          write_atomically(written + "/" + state_name, [&](std::ostream &out) {
            out << format_line << '\n'
                << "mesh "
                << (distributed != nullptr ? "distributed" : "replicated")
                << '\n'
                << "processes "
                << Utilities::MPI::n_mpi_processes(mpi_communicator) << '\n'
                << std::setprecision(17) << "cycle " << state.cycle << '\n'
                << "dofs " << state.dofs << '\n'
                << "estimator " << state.estimator.has_value() << ' '
                << state.estimator.value_or(0.) << '\n'
                << "cumulative_wall_time " << state.cumulative_wall_time << '\n'
                << "indicators " << (indicators.size() > 0) << '\n';
            write_files(out, "solution_files", state.solution_files);
            write_files(out, "dual_mesh_files", state.dual_mesh_files);
            out << "files " << names.size() << '\n';
            for (const auto &name : names)
              out << name << ' ' << fs::file_size(written + "/" + name) << ' '
                  << file_hash(written + "/" + name) << '\n';
          });
          // The previous checkpoint is whole until the new one has its
          // name; between the renames, checkpoint.old/ is.
          const std::string current = output_directory + "/checkpoint";
          const std::string old     = output_directory + "/checkpoint.old";
          fs::remove_all(old);
          if (fs::exists(current))
            fs::rename(current, old);
          fs::rename(written, current);
          fs::remove_all(old);
        }
      catch (const std::exception &error)
        {
          problem = "cannot write a checkpoint into " + output_directory +
                    "/checkpoint: " + Parameters::one_line_message(error);
        }
    throw_collective(problem, mpi_communicator);
  }



  template <int dim>
  std::vector<typename Checkpoint<dim>::CellRecord>
  Checkpoint<dim>::cell_records(
    const DoFHandler<dim>                   &dof_handler,
    const std::array<const VectorType *, 3> &vectors,
    const Vector<double>                    &indicators) const
  {
    // Read through copies in deal.II's own vectors: the ghost entries of a
    // Trilinos vector are slow to read one by one.
    const IndexSet relevant =
      DoFTools::extract_locally_relevant_dofs(dof_handler);
    std::vector<DistributedVector> copies;
    for (const VectorType *vector : vectors)
      {
        copies.emplace_back(dof_handler.locally_owned_dofs(),
                            relevant,
                            mpi_communicator);
        for (const auto i : dof_handler.locally_owned_dofs())
          copies.back()[i] = (*vector)[i];
        copies.back().update_ghost_values();
      }
    std::vector<CellRecord> records(
      dof_handler.get_triangulation().n_active_cells());
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          CellRecord &record = records[cell->active_cell_index()];
          for (const unsigned int v : cell->vertex_indices())
            for (unsigned int k = 0; k < 3; ++k)
              record[k * n_vertices_per_cell + v] =
                copies[k](cell->vertex_dof_index(v, 0));
          record.back() =
            indicators.size() > 0 ? indicators[cell->active_cell_index()] : 0.;
        }
    return records;
  }



  template <int dim>
  std::string
  Checkpoint<dim>::write_distributed(
    const std::string                       &directory,
    const DoFHandler<dim>                   &dof_handler,
    const std::array<const VectorType *, 3> &vectors,
    const Vector<double>                    &indicators) const
  {
    // The nodal values of each locally owned cell and its indicator, one
    // fixed-size record per cell that p4est's save() writes with the cell
    // (parallel::distributed::SolutionTransfer, which packs a
    // variable-length vector per cell and vector, takes twice as long).
    const auto &triangulation =
      dynamic_cast<const parallel::distributed::Triangulation<dim> &>(
        dof_handler.get_triangulation());
    const auto records = cell_records(dof_handler, vectors, indicators);
    parallel::distributed::CellDataTransfer<dim, dim, std::vector<CellRecord>>
      transfer(triangulation);
    transfer.prepare_for_serialization(records);
    triangulation.save(directory + "/mesh");
    if (Utilities::MPI::this_mpi_process(mpi_communicator) != 0)
      return "";
    std::ofstream out(directory + "/" + history_name, std::ios::binary);
    write_binary(out, std::vector<std::uint64_t>{cell_refinements.size()});
    for (const auto &[refine, coarsen] : cell_refinements)
      {
        write_binary(out, refine);
        write_binary(out, coarsen);
      }
    return out.flush() ? "" :
                         "cannot write a checkpoint: cannot write " +
                           directory + "/" + history_name;
  }



  template <int dim>
  std::string
  Checkpoint<dim>::write_replicated(
    const std::string                       &directory,
    const DoFHandler<dim>                   &dof_handler,
    const std::array<const VectorType *, 3> &vectors,
    const Vector<double>                    &indicators) const
  {
    // Each nodal value by the process that owns its DoF, zero elsewhere,
    // summed: exact, and in the numbering of the vertices, which the
    // replayed mesh repeats on any number of processes.
    const auto         &triangulation = dof_handler.get_triangulation();
    const unsigned int  n_vertices    = triangulation.n_vertices();
    std::vector<double> by_vertex(3 * n_vertices, 0.);
    const IndexSet     &owned = dof_handler.locally_owned_dofs();
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        for (const unsigned int v : cell->vertex_indices())
          if (const auto dof = cell->vertex_dof_index(v, 0);
              owned.is_element(dof))
            for (unsigned int k = 0; k < 3; ++k)
              by_vertex[k * n_vertices + cell->vertex_index(v)] =
                (*vectors[k])[dof];
    Utilities::MPI::sum(by_vertex, mpi_communicator, by_vertex);
    std::vector<double> all_indicators(indicators.begin(), indicators.end());
    if (!all_indicators.empty())
      for (const auto &cell : triangulation.active_cell_iterators())
        if (!cell->is_locally_owned())
          all_indicators[cell->active_cell_index()] = 0;
    Utilities::MPI::sum(all_indicators, mpi_communicator, all_indicators);

    if (Utilities::MPI::this_mpi_process(mpi_communicator) != 0)
      return "";
    std::ofstream out(directory + "/" + replicated_name, std::ios::binary);
    write_binary(out,
                 std::vector<std::uint64_t>{refinements.size(), n_vertices});
    for (const auto &[refine, coarsen] : refinements)
      {
        write_binary(out, bytes(refine));
        write_binary(out, bytes(coarsen));
      }
    write_binary(out, by_vertex);
    write_binary(out, all_indicators);
    return out.flush() ? "" :
                         "cannot write a checkpoint: cannot write " +
                           directory + "/" + replicated_name;
  }



  template <int dim>
  std::string
  Checkpoint<dim>::readable_directory() const
  {
    for (const std::string name : {"/checkpoint", "/checkpoint.old"})
      if (fs::is_regular_file(output_directory + name + "/" + state_name))
        return output_directory + name;
    return "";
  }



  template <int dim>
  typename Checkpoint<dim>::State
  Checkpoint<dim>::load_mesh(
    Triangulation<dim>                              &triangulation,
    const std::function<void(Triangulation<dim> &)> &make_coarse_mesh)
  {
    const std::string directory = readable_directory();
    auto *const       distributed =
      dynamic_cast<parallel::distributed::Triangulation<dim> *>(&triangulation);
    throw_collective(Utilities::MPI::this_mpi_process(mpi_communicator) == 0 ?
                       problem_of(directory,
                                  distributed != nullptr ? "distributed" :
                                                           "replicated") :
                       "",
                     mpi_communicator);
    const StateFile file = *read_state(directory + "/" + state_name);
    has_indicators       = file.indicators;
    const State state    = file.state;

    if (distributed != nullptr)
      {
        load_distributed(*distributed,
                         directory,
                         file.processes ==
                           Utilities::MPI::n_mpi_processes(mpi_communicator),
                         make_coarse_mesh);
        return state;
      }
    std::ifstream in(directory + "/" + replicated_name, std::ios::binary);
    const auto    sizes = read_binary<std::uint64_t>(in);
    refinements.clear();
    for (std::uint64_t r = 0; r < sizes->at(0); ++r)
      {
        const auto refine  = read_binary<char>(in);
        const auto coarsen = read_binary<char>(in);
        refinements.emplace_back(
          std::vector<bool>(refine->begin(), refine->end()),
          std::vector<bool>(coarsen->begin(), coarsen->end()));
        triangulation.load_refine_flags(refinements.back().first);
        triangulation.load_coarsen_flags(refinements.back().second);
        triangulation.execute_coarsening_and_refinement();
        complete_ghost_layer(triangulation);
      }
    loaded_by_vertex  = *read_binary<double>(in);
    loaded_indicators = *read_binary<double>(in);
    return state;
  }



  template <int dim>
  void
  Checkpoint<dim>::load_distributed(
    parallel::distributed::Triangulation<dim>       &triangulation,
    const std::string                               &directory,
    const bool                                       same_processes,
    const std::function<void(Triangulation<dim> &)> &make_coarse_mesh)
  {
    // The saved mesh, with the cells of each process as saved if the number
    // of processes is the same, and the record of each locally owned cell
    // by its CellId.
    triangulation.load(directory + "/mesh", !same_processes);
    std::vector<CellRecord> records(triangulation.n_active_cells());
    parallel::distributed::CellDataTransfer<dim, dim, std::vector<CellRecord>>
      transfer(triangulation);
    transfer.deserialize(records);
    loaded_records.clear();
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        loaded_records.emplace(cell->id().template to_binary<dim>(),
                               records[cell->active_cell_index()]);

    std::ifstream in(directory + "/" + history_name, std::ios::binary);
    const auto    n_refinements = read_binary<std::uint64_t>(in);
    cell_refinements.clear();
    for (std::uint64_t r = 0; r < n_refinements->at(0); ++r)
      {
        auto refine  = read_binary<unsigned int>(in);
        auto coarsen = read_binary<unsigned int>(in);
        cell_refinements.emplace_back(std::move(*refine), std::move(*coarsen));
      }
    if (!same_processes)
      return;
    // On as many processes as before, the mesh made again by its
    // refinements: its cells in the order in which they were made, so that
    // the DoFs are numbered as in the study that wrote the checkpoint (the
    // loaded mesh numbers them in p4est's order). The partition is that of
    // the loaded one, whose records each process holds.
    triangulation.clear();
    make_coarse_mesh(triangulation);
    for (const auto &[refine, coarsen] : cell_refinements)
      {
        std::array<std::set<CellId::binary_type>, 2> flagged;
        for (unsigned int f = 0; f < 2; ++f)
          for (std::size_t i = 0; i < (f == 0 ? refine : coarsen).size();
               i += 4)
            {
              CellId::binary_type id;
              std::copy_n((f == 0 ? refine : coarsen).begin() + i,
                          4,
                          id.begin());
              flagged[f].insert(id);
            }
        for (const auto &cell : triangulation.active_cell_iterators())
          if (cell->is_locally_owned())
            {
              const auto id = cell->id().template to_binary<dim>();
              if (flagged[0].count(id) > 0)
                cell->set_refine_flag();
              if (flagged[1].count(id) > 0)
                cell->set_coarsen_flag();
            }
        triangulation.execute_coarsening_and_refinement();
      }
  }



  template <int dim>
  void
  Checkpoint<dim>::load_vectors(const DoFHandler<dim>             &dof_handler,
                                const std::array<VectorType *, 3> &vectors,
                                Vector<double>                    &indicators)
  {
    const std::string directory = readable_directory();
    const auto *const distributed =
      dynamic_cast<const parallel::distributed::Triangulation<dim> *>(
        &dof_handler.get_triangulation());
    indicators.reinit(
      has_indicators ? dof_handler.get_triangulation().n_active_cells() : 0);
    if (distributed != nullptr)
      {
        // A cell without a record: the mesh made again is not the saved one.
        bool            complete = true;
        const IndexSet &owned    = dof_handler.locally_owned_dofs();
        for (const auto &cell : dof_handler.active_cell_iterators())
          if (cell->is_locally_owned())
            {
              const auto found =
                loaded_records.find(cell->id().template to_binary<dim>());
              if (found == loaded_records.end())
                {
                  complete = false;
                  continue;
                }
              const CellRecord &record = found->second;
              for (const unsigned int v : cell->vertex_indices())
                if (const auto dof = cell->vertex_dof_index(v, 0);
                    owned.is_element(dof))
                  for (unsigned int k = 0; k < 3; ++k)
                    (*vectors[k])[dof] = record[k * n_vertices_per_cell + v];
              if (has_indicators)
                indicators[cell->active_cell_index()] = record.back();
            }
        loaded_records.clear();
        if (Utilities::MPI::logical_or(!complete, mpi_communicator))
          throw Parameters::CollectiveError(
            "the checkpoint " + directory +
            " is damaged: its refinements do not make its mesh");
        for (VectorType *vector : vectors)
          vector->compress(VectorOperation::insert);
        return;
      }

    // The values that load_mesh() read with the refinements.
    const unsigned int n_vertices = loaded_by_vertex.size() / 3;
    const IndexSet    &owned      = dof_handler.locally_owned_dofs();
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        for (const unsigned int v : cell->vertex_indices())
          if (const auto dof = cell->vertex_dof_index(v, 0);
              owned.is_element(dof))
            for (unsigned int k = 0; k < 3; ++k)
              (*vectors[k])[dof] =
                loaded_by_vertex[k * n_vertices + cell->vertex_index(v)];
    for (VectorType *vector : vectors)
      vector->compress(VectorOperation::insert);
    std::copy(loaded_indicators.begin(),
              loaded_indicators.end(),
              indicators.begin());
    loaded_by_vertex.clear();
    loaded_indicators.clear();
  }



  template class Checkpoint<2>;
} // namespace membranes
