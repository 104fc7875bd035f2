// Purpose: running one Monte Carlo ensemble across the processes of an MPI job (mpirun, srun): who this process is, agreement on failures and exit codes, and the distributed counterpart of run_graph.
#pragma once

#include <trackflow/host/engine.hpp>

#include <memory>
#include <stdexcept>
#include <string>

namespace trackflow::host {

// Thrown on the processes other than rank 0 when the job stops because of a failure that rank 0
// reports (a run that failed elsewhere, a pipeline another process could not load): they exit
// with the job's code and print nothing, so the error is printed once.
class ReportedElsewhere : public std::runtime_error {
 public:
  ReportedElsewhere() : std::runtime_error("reported by rank 0") {}
};

// This process's place in an MPI job of more than one process. Rank 0 merges, prints and writes
// every output; the others only run runs.
class MpiSession {
 public:
  virtual ~MpiSession() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  // Collective: every process says whether its set-up (loading the pipeline, the plugins)
  // succeeded. If all did, returns normally. Otherwise rank 0 throws the first failure — its own,
  // or the lowest failing rank's message prefixed "rank k: " (as a ConfigError) — and the others
  // throw ReportedElsewhere.
  virtual void agree_setup(bool ok, const std::string& error_message) = 0;
  // Collective, last: the job's exit code is the largest of the processes' codes.
  virtual int agree_exit_code(int code) = 0;
};

// Whether this build has MPI (Boost.MPI and Open MPI were found when it was configured).
bool mpi_built();

// When this process was started by an MPI launcher (mpirun, srun) in a job of more than one
// process: initialises MPI and returns the session; null for a plain start or a job of one.
// A build without MPI started in a job of several processes throws ConfigError (otherwise each
// would run the whole ensemble and write the same files).
std::unique_ptr<MpiSession> start_mpi_if_launched(int& argc, char**& argv);

// run_graph across the job: every process calls it with the same graph and options; runs are
// handed out by rank 0 in order as processes ask for them (each process runs opt.threads at a
// time), results are sent to rank 0 as bytes (RunResultCodec) and merged there in run order, so
// rank 0's Outcome, summary and files are byte-identical to run_graph's with the same seed for
// any number of processes and threads. finish() runs on rank 0 only; the other processes get
// an Outcome with ids and run counts only. A run that fails on any process stops the job:
// rank 0 throws DataError "rank k: run r: ..." (or the ConfigError), the others
// ReportedElsewhere, after every process has stopped. A component that returns a per-run result
// without implementing RunResultCodec is refused by name (ConfigError).
Outcome run_graph_distributed(const Graph& g, const PluginRegistry& registry, const RunOptions& opt, MpiSession& mpi);

}  // namespace trackflow::host
