// Purpose: the worker threads of both engines: one graph instance each, runs pulled from a RunSource.
#include "worker_pool.hpp"

#include <trackflow/error.hpp>
#include <trackflow/host/guard.hpp>

#include <system_error>

namespace trackflow::host {

RunExecutor::RunExecutor(const Graph& g, const PluginRegistry& registry, std::uint64_t seed)
    : g_(g), seed_(seed), inst_(instantiate(g, registry)), filters_(filters_of(inst_)), labels_(labels_of(g, inst_)) {}

RunRecord RunExecutor::run(std::uint64_t run) {
  Activity running{"running", &labels_};
  running.run = run;
  running.has_run = true;
  ActivityScope scope(running);
  try {
    return run_one(g_, inst_, filters_, seed_, run);
  } catch (...) {
    rethrow_from_plugin();  // names the run, the node and its plugin file
  }
}

std::string WorkerPool::start(unsigned n) {
  try {
    for (unsigned t = 0; t < n; ++t) {
      ++live_;
      try {
        threads_.emplace_back([this] {
          work();
          --live_;
        });
      } catch (...) {
        --live_;
        throw;
      }
    }
  } catch (const std::system_error& e) {
    return "engine: started " + std::to_string(threads_.size()) + " of " + std::to_string(n) + " worker threads (" +
           e.what() + "); results are the same with fewer";
  }
  return {};
}

void WorkerPool::work() {
  prepare_thread_for_crash_reports();  // a stack overflow in a plugin is named here too
  // A sink that keeps a large run's rows in a temporary file, or streams its file while runs are
  // merged on this thread, asks output_directory(): every thread answers with this run's --out.
  OutputDirectoryScope dir(opt_.output_dir);
  std::optional<RunExecutor> executor;
  std::string setup_error;
  try {
    Activity building{"building the graph for a worker"};
    ActivityScope building_scope(building);
    executor.emplace(g_, registry_, opt_.seed);
  } catch (...) {
    const std::exception_ptr error = std::current_exception();
    try {
      std::rethrow_exception(error);
    } catch (const std::exception& e) {
      setup_error = e.what();
    } catch (...) {
      setup_error = "unknown error";
    }
    source_.failed(std::nullopt, error);
  }
  while (const std::optional<std::uint64_t> run = source_.next_run()) {
    if (!executor) {
      source_.failed(*run, std::make_exception_ptr(DataError("could not build the pipeline on this process: " + setup_error)));
      continue;
    }
    RunRecord rec;
    try {
      rec = executor->run(*run);
    } catch (...) {
      source_.failed(*run, std::current_exception());
      continue;
    }
    source_.finished(*run, std::move(rec), executor->instance());
  }
}

void WorkerPool::join() {
  for (auto& t : threads_)
    if (t.joinable()) t.join();
}

}  // namespace trackflow::host
