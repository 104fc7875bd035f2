// Purpose: the MPI entry points of a build without MPI (Boost.MPI or Open MPI not found at configure time): refuse to be started as several processes.
#include <trackflow/host/mpi.hpp>

#include "mpi_launch.hpp"

#include <stdexcept>

namespace trackflow::host {

bool mpi_built() { return false; }

std::unique_ptr<MpiSession> start_mpi_if_launched(int&, char**&) {
  int tasks = 0;
  if (const char* n = std::getenv("OMPI_COMM_WORLD_SIZE")) tasks = std::atoi(n);
  if (tasks < 2) tasks = detail::slurm_tasks();
  if (tasks > 1)
    detail::refuse_unconnected(tasks, "this trackflow was built without MPI (install libboost-mpi-dev and openmpi-bin, "
                                      "then configure and build again)");
  return nullptr;
}

Outcome run_graph_distributed(const Graph&, const PluginRegistry&, const RunOptions&, MpiSession&) {
  throw std::logic_error("run_graph_distributed: this trackflow was built without MPI");
}

}  // namespace trackflow::host
