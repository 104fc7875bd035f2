// Purpose: plugin search options and option parsing shared by the CLI commands.
#include "cli_common.hpp"

#include <trackflow/host/suggest.hpp>
#include <trackflow/output_path.hpp>
#include <trackflow/safe_output.hpp>

#include <fcntl.h>
#include <sys/file.h>

#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <iostream>

namespace trackflow::cli {

po::options_description common_options(Common& c) {
  po::options_description o("Plugin options");
  o.add_options()("plugin-path", po::value(&c.plugin_paths)->composing(),
                  "also search DIR for tfplugin_*.so (repeatable; after the built-in folder)")(
      "no-default-plugins", po::bool_switch(&c.no_default_plugins),
      "do not search $TRACKFLOW_PLUGIN_PATH or the built-in plugin folder")(
      "replace-type", po::value(&c.replace_types)->composing(),
      "let a plugin from --plugin-path or $TRACKFLOW_PLUGIN_PATH replace this built-in TYPE (repeatable); "
      "otherwise built-in types are never replaced");
  return o;
}

po::options_description trust_options(Common& c) {
  po::options_description o("Trust options (a pipeline file alone can neither load code nor write outside --out)");
  o.add_options()("trust-plugin-paths", po::bool_switch(&c.trust_plugin_paths),
                  "load plugins from the folders the pipeline's plugin_paths: names (refused otherwise)")(
      "allow-outside-out", po::bool_switch(&c.allow_outside_out),
      "let sinks write to absolute paths or paths with '..' (otherwise only under --out)");
  return o;
}

host::PluginRegistry load_plugins(const Common& c, const host::PipelineConfig* pipeline) {
  if (pipeline && !pipeline->plugin_paths.empty() && !c.trust_plugin_paths)
    throw ConfigError("this pipeline asks to load plugins from " + host::join_some(pipeline->plugin_paths, 5) +
                          " (plugin_paths:); a pipeline file cannot make trackflow run code: pass --plugin-path DIR, "
                          "or --trust-plugin-paths if you trust this file and those folders",
                      pipeline->plugin_paths_loc);
  host::PluginRegistry reg;
  reg.allow_replacing(c.replace_types);
  if (!c.no_default_plugins) reg.load_directories(host::builtin_plugin_dirs(), true);
  reg.load_directories(c.plugin_paths);
  if (pipeline) reg.load_directories(pipeline->plugin_paths);
  if (!c.no_default_plugins) reg.load_directories(host::environment_plugin_dirs());
  return reg;
}

void apply_trust(const Common& c) { allow_output_outside(c.allow_outside_out); }

std::uint64_t parse_count(const std::string& text, const std::string& option, std::uint64_t min, std::uint64_t max) {
  std::uint64_t v = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  const bool digits = !text.empty() && std::isdigit(static_cast<unsigned char>(text[0]));
  if (!digits || ec != std::errc() || ptr != end || v < min || v > max)
    throw ConfigError(option + " must be a whole number from " + std::to_string(min) + " to " + std::to_string(max) +
                      ", got '" + host::quote_token(text) + "'");
  return v;
}

namespace {

namespace fs = std::filesystem;

// The nearest existing folder at or above `p`, or empty.
fs::path existing_ancestor(fs::path p) {
  std::error_code ec;
  if (p.empty()) p = ".";
  p = fs::absolute(p, ec);
  while (!p.empty()) {
    if (fs::exists(p, ec)) return p;
    if (p == p.parent_path()) break;
    p = p.parent_path();
  }
  return {};
}

void check_parent_writable(const fs::path& p, const std::string& option, const std::string& path) {
  const fs::path ancestor = existing_ancestor(p);
  std::error_code ec;
  if (ancestor.empty() || !fs::is_directory(ancestor, ec))
    throw ConfigError(option + " '" + path + "': '" + ancestor.string() + "' is not a folder");
  if (::access(ancestor.c_str(), W_OK | X_OK) != 0)
    throw ConfigError(option + " '" + path + "': cannot write in '" + ancestor.string() + "': " + std::strerror(errno));
}

}  // namespace

void check_output_file(const std::string& path, const std::string& option) {
  std::error_code ec;
  const fs::path p(path);
  if (path.empty()) throw ConfigError(option + " needs a file name");
  if (fs::is_directory(p, ec)) throw ConfigError(option + " '" + path + "' is a folder, not a file");
  if (fs::exists(p, ec)) {
    if (::access(p.c_str(), W_OK) != 0) throw ConfigError(option + " '" + path + "': " + std::strerror(errno));
  } else {
    check_parent_writable(p.parent_path(), option, path);
  }
  // access() says yes to root in /proc: the temporary the file will be written through is
  // created and removed here, so such a path is refused before the runs (safe_output.hpp).
  if (std::string why = user_file_problem(path); !why.empty()) throw ConfigError(option + ": " + why);
}

OutputFolderLock::~OutputFolderLock() {
  if (fd_ >= 0) ::close(fd_);
}

void OutputFolderLock::hold(const std::string& path, const std::string& option, bool create) {
  std::error_code ec;
  if (create) fs::create_directories(path, ec);
  const int fd = ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ENOENT && !create) return;
    throw ConfigError(option + " '" + path + "': cannot open the folder: " + std::strerror(errno));
  }
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    ::close(fd);
    if (err == EWOULDBLOCK)
      throw ConfigError(option + " '" + path + "' is in use by another running trackflow (it holds the folder until it "
                        "ends); wait for it or choose another --out");
    throw ConfigError(option + " '" + path + "': cannot lock the folder: " + std::strerror(err));
  }
  if (fd_ >= 0) ::close(fd_);
  fd_ = fd;
}

void check_output_folder(const std::string& path, const std::string& option) {
  std::error_code ec;
  const fs::path p(path);
  if (fs::exists(p, ec)) {
    if (!fs::is_directory(p, ec)) throw ConfigError(option + " '" + path + "' exists and is not a folder");
    if (::access(p.c_str(), W_OK | X_OK) != 0) throw ConfigError(option + " '" + path + "': " + std::strerror(errno));
    return;
  }
  check_parent_writable(p, option, path);
}

void warn_problems(const host::PluginRegistry& reg) {
  if (!is_root()) return;  // the same warning from every process of an MPI job would be noise
  for (const auto& p : reg.problems()) std::cerr << "trackflow: warning: plugin not loaded: " << p.str() << "\n";
}

void warn_setup(const std::vector<std::string>& warnings) {
  if (!is_root()) return;
  for (const auto& w : warnings) std::cerr << "trackflow: warning: " << host::printable(w) << "\n";
}

namespace {
host::MpiSession* g_mpi = nullptr;
}
host::MpiSession* mpi_session() { return g_mpi; }
void set_mpi_session(host::MpiSession* s) { g_mpi = s; }

std::string error_text(const std::exception& e) {
  if (const auto* c = dynamic_cast<const ConfigError*>(&e)) return c->message();
  return e.what();
}

host::Outcome run_ensemble(const host::Graph& g, const host::PluginRegistry& reg, const host::RunOptions& ro) {
  if (host::MpiSession* mpi = mpi_session()) return host::run_graph_distributed(g, reg, ro, *mpi);
  return host::run_graph(g, reg, ro);
}

bool parse(int argc, char** argv, po::options_description& opts, po::positional_options_description& pos,
           po::variables_map& vm, const std::string& usage) {
  po::options_description all;
  all.add(opts);
  po::store(po::command_line_parser(argc, argv).options(all).positional(pos).run(), vm);
  if (vm.count("help")) {
    std::cout << usage << "\n" << opts << "\n";
    return false;
  }
  po::notify(vm);
  return true;
}


}  // namespace trackflow::cli
