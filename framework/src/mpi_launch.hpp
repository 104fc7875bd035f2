// Purpose: how this process was started — by an MPI launcher (mpirun, srun --mpi=pmix) or as one of several srun tasks without MPI — read from the launchers' environment variables.
#pragma once

#include <trackflow/error.hpp>

#include <cstdlib>
#include <string>

namespace trackflow::host::detail {

// Started as a process of an MPI job (Open MPI's mpirun, or a PMI/PMIx launcher such as srun
// --mpi=pmix): MPI_Init will find its peers.
inline bool mpi_launched() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMIX_RANK") || std::getenv("PMI_RANK");
}

// The number of tasks Slurm started for this job step (0 outside srun).
inline int slurm_tasks() {
  const char* procid = std::getenv("SLURM_PROCID");
  const char* n = std::getenv("SLURM_NTASKS");
  return procid && n ? std::atoi(n) : 0;
}

// Several processes were started but they do not form one MPI job: each would run the whole
// ensemble and write the same files, so this is refused.
[[noreturn]] inline void refuse_unconnected(int tasks, const std::string& why) {
  throw ConfigError("started as one of " + std::to_string(tasks) + " processes, but " + why +
                    ": each would run the whole ensemble and write the same files. Run one process, or see "
                    "docs/performance.md (MPI) for mpirun and srun --mpi=pmix");
}

}  // namespace trackflow::host::detail
