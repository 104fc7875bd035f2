// Purpose: what the CLI commands share: exit codes, plugin search options, option parsing.
#pragma once

#include <trackflow/host/config.hpp>
#include <trackflow/host/mpi.hpp>
#include <trackflow/host/plugins.hpp>

#include <boost/program_options.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace trackflow::cli {

namespace po = boost::program_options;

constexpr int kOk = 0, kExpectFailed = 1, kBadInput = 2, kInternal = 3;

struct Common {
  std::vector<std::string> plugin_paths;
  std::vector<std::string> replace_types;
  bool no_default_plugins = false;
  // Trust: what only the command line may allow (docs/architecture.md, "Trust").
  bool trust_plugin_paths = false;
  bool allow_outside_out = false;
};

po::options_description common_options(Common& c);
// For the commands that open a pipeline (run, report, validate, sweep).
po::options_description trust_options(Common& c);
// The built-in plugin folder first (its types are replaced only by --replace-type), then
// --plugin-path, the pipeline's plugin_paths (only with --trust-plugin-paths: a pipeline file
// cannot make trackflow load code), then $TRACKFLOW_PLUGIN_PATH.
host::PluginRegistry load_plugins(const Common& c, const host::PipelineConfig* pipeline = nullptr);
// Applies --allow-outside-out for the sinks built after this call.
void apply_trust(const Common& c);

// A whole number given on the command line, checked against [min, max]: "-1", "1e3", "12abc"
// and values beyond 64 bits are refused instead of wrapping.
std::uint64_t parse_count(const std::string& text, const std::string& option, std::uint64_t min, std::uint64_t max);
// Refuses, before anything runs, an output file (or folder) that cannot be written: a folder
// where a file is wanted, a parent that is a file or not writable, a folder where its temporary
// cannot be created (tried and removed again: /proc). Leaves nothing behind.
void check_output_file(const std::string& path, const std::string& option);
void check_output_folder(const std::string& path, const std::string& option);
// Holds the --out folder for this process: flock(LOCK_EX | LOCK_NB) on the folder itself
// (nothing is created for it; released at exit), so a second trackflow writing into the same
// folder at the same time is refused (exit 2) instead of mixing the two runs' files. `create`:
// make the folder first (it will be written); otherwise a missing folder is not held (the
// unique temporaries of safe_output.hpp still keep each file whole).
class OutputFolderLock {
 public:
  OutputFolderLock() = default;
  OutputFolderLock(const OutputFolderLock&) = delete;
  OutputFolderLock& operator=(const OutputFolderLock&) = delete;
  ~OutputFolderLock();
  void hold(const std::string& path, const std::string& option, bool create);

 private:
  int fd_ = -1;
};
void warn_problems(const host::PluginRegistry& reg);
// A graph's valid-but-implausible parameters (host::Graph::warnings), on stderr, from rank 0.
void warn_setup(const std::vector<std::string>& warnings);
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
