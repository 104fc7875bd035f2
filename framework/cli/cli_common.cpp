// Purpose: plugin search options and option parsing shared by the CLI commands.
#include "cli_common.hpp"

#include <iostream>

namespace trackflow::cli {

po::options_description common_options(Common& c) {
  po::options_description o("Plugin options");
  o.add_options()("plugin-path", po::value(&c.plugin_paths)->composing(),
                  "also search DIR for tfplugin_*.so (repeatable; searched first)")(
      "no-default-plugins", po::bool_switch(&c.no_default_plugins),
      "do not search $TRACKFLOW_PLUGIN_PATH or the built-in plugin folder");
  return o;
}

host::PluginRegistry load_plugins(const Common& c, const std::vector<std::string>& pipeline_paths) {
  std::vector<std::string> dirs = c.plugin_paths;
  dirs.insert(dirs.end(), pipeline_paths.begin(), pipeline_paths.end());
  if (!c.no_default_plugins) {
    auto d = host::default_plugin_dirs();
    dirs.insert(dirs.end(), d.begin(), d.end());
  }
  host::PluginRegistry reg;
  reg.load_directories(dirs);
  return reg;
}

void warn_problems(const host::PluginRegistry& reg) {
  if (!is_root()) return;  // the same warning from every process of an MPI job would be noise
  for (const auto& p : reg.problems()) std::cerr << "trackflow: warning: plugin not loaded: " << p.str() << "\n";
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
