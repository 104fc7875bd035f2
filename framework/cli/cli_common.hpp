// Purpose: what the CLI commands share: exit codes, plugin search options, option parsing.
#pragma once

#include <trackflow/host/mpi.hpp>
#include <trackflow/host/plugins.hpp>

#include <boost/program_options.hpp>

#include <string>
#include <vector>

namespace trackflow::cli {

namespace po = boost::program_options;

constexpr int kOk = 0, kExpectFailed = 1, kBadInput = 2, kInternal = 3;

struct Common {
  std::vector<std::string> plugin_paths;
  bool no_default_plugins = false;
};

po::options_description common_options(Common& c);
// --plugin-path dirs, then the pipeline's plugin_paths, then the defaults (unless disabled).
host::PluginRegistry load_plugins(const Common& c, const std::vector<std::string>& pipeline_paths);
void warn_problems(const host::PluginRegistry& reg);
// Parses argv after the command word; prints help and returns false when asked.
bool parse(int argc, char** argv, po::options_description& opts, po::positional_options_description& pos,
           po::variables_map& vm, const std::string& usage);

int cmd_sweep(int argc, char** argv);

// The MPI job this process belongs to (mpirun / srun with more than one process), or null.
// Set once by main() before any command runs.
host::MpiSession* mpi_session();
void set_mpi_session(host::MpiSession* s);
// True on the process that prints and writes: rank 0 of an MPI job, or the only process.
inline bool is_root() { return !mpi_session() || mpi_session()->rank() == 0; }
// The text main() prints for an error, for sending to rank 0 under MPI.
std::string error_text(const std::exception& e);
// Under MPI: every process reports whether `setup` succeeded before any runs; a failure on
// another process stops this one (rank 0 prints it). Without MPI: runs setup.
template <class F>
void agreed_setup(F&& setup) {
  host::MpiSession* mpi = mpi_session();
  if (!mpi) {
    setup();
    return;
  }
  std::exception_ptr error;
  std::string text;
  try {
    setup();
  } catch (const std::exception& e) {
    error = std::current_exception();
    text = error_text(e);
  }
  mpi->agree_setup(!error, text);
  if (error) std::rethrow_exception(error);
}
// run_graph, or its distributed counterpart inside an MPI job.
host::Outcome run_ensemble(const host::Graph& g, const host::PluginRegistry& reg, const host::RunOptions& ro);

}  // namespace trackflow::cli
