// Purpose: what the CLI commands share: exit codes, plugin search options, option parsing.
#pragma once

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

}  // namespace trackflow::cli
