#ifndef membranes_cell_loop_h
#define membranes_cell_loop_h

#include <atomic>
#include <deal.II/base/multithread_info.h>
#include <deal.II/base/work_stream.h>
#include <deal.II/dofs/dof_handler.h>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <type_traits>

namespace membranes
{
  using namespace dealii;

  /**
   * The scratch object of one thread of a WorkStream loop. WorkStream gives
   * every thread a copy of a sample scratch object, but scratch that holds
   * an FEValues object cannot be copied: this holder copies only the
   * function that makes one, and makes it on first use.
   */
  template <typename Scratch>
  class ThreadScratch
  {
  public:
    explicit ThreadScratch(
      const std::function<std::unique_ptr<Scratch>()> &make)
      : make(make)
    {}

    ThreadScratch(const ThreadScratch &other)
      : make(other.make)
    {}

    Scratch &
    get()
    {
      if (!data)
        data = make();
      return *data;
    }

  private:
    std::function<std::unique_ptr<Scratch>()> make;
    std::unique_ptr<Scratch>                  data;
  };



  /** Items per chunk of run_in_order(). */
  constexpr unsigned int chunk_size = 64;



  /**
   * Run @p worker(item, scratch, copy) on every item of [@p begin, @p end),
   * on the threads of MultithreadInfo (deal.II's WorkStream, as in
   * step-9), each thread with its own scratch object made by
   * @p make_scratch, and @p copier(copy) on the results one at a time, in
   * the order of the items. Sums formed in the copier are therefore the
   * same, to the last bit, for any number of threads.
   *
   * WorkStream hands the items to the threads in chunks of `chunk_size`
   * items instead of its default of 8 (benchmarks/choices.md, "The chunks of
   * the cell loops").
   *
   * An exception thrown by the worker (an expression of the scene that is
   * not finite at a point) would end the program in WorkStream, which
   * aborts on exceptions of its threads: the first one is kept, the
   * remaining items are skipped, and it is thrown again here, on the
   * calling thread, as from a loop without threads (hence not
   * MeshWorker::mesh_loop(): benchmarks/choices.md, "Cell loops that pass
   * exceptions on").
   */
  template <typename Copy,
            typename Iterator,
            typename MakeScratch,
            typename Worker,
            typename Copier>
  void
  run_in_order(const Iterator    &begin,
               const Iterator    &end,
               const MakeScratch &make_scratch,
               const Worker      &worker,
               const Copier      &copier)
  {
    using Scratch = typename std::invoke_result_t<MakeScratch>::element_type;
    std::exception_ptr failure;
    std::atomic<bool>  failed(false);
    std::mutex         failure_mutex;
    WorkStream::run(
      begin,
      end,
      [&](const Iterator &item, ThreadScratch<Scratch> &scratch, Copy &copy) {
        if (failed)
          return;
        try
          {
            worker(item, scratch.get(), copy);
          }
        catch (...)
          {
            std::lock_guard<std::mutex> lock(failure_mutex);
            if (!failed)
              failure = std::current_exception();
            failed = true;
          }
      },
      [&](const Copy &copy) {
        if (!failed)
          copier(copy);
      },
      ThreadScratch<Scratch>(make_scratch),
      Copy(),
      2 * MultithreadInfo::n_threads(),
      chunk_size);
    if (failure)
      std::rethrow_exception(failure);
  }



  /**
   * run_in_order() on the active cells of @p dof_handler. The worker
   * decides which cells it works on (locally owned ones, or all but
   * artificial ones) and leaves its copy object empty on the others.
   */
  template <typename Copy,
            int dim,
            typename MakeScratch,
            typename Worker,
            typename Copier>
  void
  run_on_cells(const DoFHandler<dim> &dof_handler,
               const MakeScratch     &make_scratch,
               const Worker          &worker,
               const Copier          &copier)
  {
    const typename DoFHandler<dim>::active_cell_iterator end =
      dof_handler.end();
    run_in_order<Copy>(
      dof_handler.begin_active(), end, make_scratch, worker, copier);
  }
} // namespace membranes

#endif
