// Purpose: the `trackflow` command: run, validate, plugins, describe.
#include "cli_common.hpp"

#include <trackflow/host/engine.hpp>
#include <trackflow/host/report.hpp>
#include <trackflow/host/suggest.hpp>
#include <trackflow/host/validate.hpp>
#include <trackflow/version.hpp>

#include <boost/program_options.hpp>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <thread>

using namespace trackflow;
using namespace trackflow::host;
using namespace trackflow::cli;

namespace {


const char* kTopHelp = R"(trackflow - plugin-based radar target-tracking pipelines

Usage: trackflow <command> [options]

Commands:
  run FILE        run a pipeline once or as a Monte Carlo ensemble, print a summary,
                  check its `expect:` block
  validate FILE   check a pipeline without running it (types, parameters, units, wiring)
  plugins         list the plugin files found and the component types they provide
  describe TYPE   show a component type's parameters (name, type, unit, default, doc)
  sweep FILE      run a pipeline over a grid of parameter values, one table row per point

Run `trackflow <command> --help` for the options of a command.

Exit codes: 0 ok, 1 an `expect` check failed, 2 bad configuration or input data,
3 internal error.
Plugins are searched in: --plugin-path DIRs, the pipeline's plugin_paths,
$TRACKFLOW_PLUGIN_PATH (colon-separated), then <trackflow>/../lib/trackflow/plugins.
)";

struct Loaded {
  PipelineConfig cfg;
  PluginRegistry reg;
  Graph graph;
};

Loaded load_pipeline(const std::string& file, const std::vector<std::string>& sets, const Common& c) {
  std::vector<Override> overrides;
  for (const auto& s : sets) overrides.push_back(parse_override(s));
  Value root = load_yaml_file(file);
  Loaded l;
  l.cfg = parse_pipeline(root, file, overrides);
  l.reg = load_plugins(c, l.cfg.plugin_paths);
  warn_problems(l.reg);
  l.graph = build_graph(l.cfg, l.reg);
  return l;
}

int cmd_run(int argc, char** argv) {
  Common c;
  std::string file, out_dir, metrics_json;
  std::vector<std::string> sets;
  std::uint64_t runs = 0, seed = 0;
  unsigned threads = 1;
  bool quiet = false, no_progress = false;
  po::options_description o("trackflow run options");
  o.add_options()("help,h", "show this help")("file", po::value(&file), "pipeline YAML file")(
      "runs,n", po::value(&runs), "Monte Carlo runs (default: the pipeline's `runs:`)")(
      "threads,j", po::value(&threads)->default_value(1),
      "worker threads; results are identical for any value")(
      "seed", po::value(&seed), "base seed (default: the pipeline's `seed:`)")(
      "set", po::value(&sets)->composing(),
      "override a parameter: --set kf.q=4 --set radar.sigma_range=\"20 m\" (repeatable)")(
      "out,o", po::value(&out_dir), "folder for files written by sinks (default: out/<pipeline name>)")(
      "metrics-json", po::value(&metrics_json), "write {sink id: {metric: value}} to this file")(
      "quiet,q", po::bool_switch(&quiet), "print only expect failures and errors")(
      "no-progress", po::bool_switch(&no_progress), "no progress bar even on a terminal");
  o.add(common_options(c));
  po::positional_options_description pos;
  pos.add("file", 1);
  po::variables_map vm;
  if (!parse(argc, argv, o, pos, vm, "Usage: trackflow run FILE [options]")) return kOk;
  if (file.empty()) throw po::error("run needs a pipeline FILE");
  Loaded l = load_pipeline(file, sets, c);
  RunOptions ro;
  ro.runs = vm.count("runs") ? runs : l.graph.config.runs;
  if (ro.runs == 0) throw ConfigError("--runs must be at least 1");
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  ro.threads = threads;
  ro.seed = vm.count("seed") ? seed : l.graph.config.seed;
  l.graph.config.seed = ro.seed;
  ro.output_dir = out_dir.empty() ? (std::filesystem::path("out") / l.graph.config.name).string() : out_dir;
  if (!no_progress && !quiet && ::isatty(STDERR_FILENO) && ro.runs > 1) {
    ro.progress = [](std::uint64_t done, std::uint64_t total) {
      const int width = 40;
      const int filled = static_cast<int>(width * done / std::max<std::uint64_t>(total, 1));
      std::cerr << "\r[" << std::string(filled, '#') << std::string(width - filled, '.') << "] " << done << "/"
                << total << " runs" << (done == total ? "\n" : "") << std::flush;
    };
  }
  Outcome out = run_graph(l.graph, l.reg, ro);
  auto results = check_expects(l.graph, out);
  if (!metrics_json.empty()) write_metrics_json(metrics_json, out);
  const bool all_pass = std::all_of(results.begin(), results.end(), [](const ExpectResult& r) { return r.passed; });
  if (!quiet) {
    print_summary(std::cout, l.graph, out, std::min<std::uint64_t>(ro.threads, ro.runs), results);
  } else {
    for (const auto& r : results)
      if (!r.passed) std::cout << "FAIL " << r.text << " (" << r.expect.loc.str() << ")\n";
  }
  return all_pass ? kOk : kExpectFailed;
}

int cmd_validate(int argc, char** argv) {
  Common c;
  std::string file;
  std::vector<std::string> sets;
  po::options_description o("trackflow validate options");
  o.add_options()("help,h", "show this help")("file", po::value(&file), "pipeline YAML file")(
      "set", po::value(&sets)->composing(), "override a parameter, as for run");
  o.add(common_options(c));
  po::positional_options_description pos;
  pos.add("file", 1);
  po::variables_map vm;
  if (!parse(argc, argv, o, pos, vm, "Usage: trackflow validate FILE [options]\n\nChecks types, parameters, units, wiring and data files; runs nothing.")) return kOk;
  if (file.empty()) throw po::error("validate needs a pipeline FILE");
  Loaded l = load_pipeline(file, sets, c);
  std::cout << file << ": ok (" << l.graph.nodes.size() << " nodes, " << l.graph.config.expects.size()
            << " expect checks)\n";
  return kOk;
}

int cmd_plugins(int argc, char** argv) {
  Common c;
  bool json = false;
  po::options_description o("trackflow plugins options");
  o.add_options()("help,h", "show this help")("json", po::bool_switch(&json), "machine-readable output");
  o.add(common_options(c));
  po::positional_options_description pos;
  po::variables_map vm;
  if (!parse(argc, argv, o, pos, vm, "Usage: trackflow plugins [--json]\n\nLists plugin files found and the component types each provides; exit 2 if any file failed to load.")) return kOk;
  PluginRegistry reg = load_plugins(c, {});
  if (json) {
    std::cout << "{\n  \"searched\": [";
    for (size_t i = 0; i < reg.searched().size(); ++i)
      std::cout << (i ? ", " : "") << "\"" << json_escape(reg.searched()[i]) << "\"";
    std::cout << "],\n  \"types\": [";
    bool first = true;
    for (const auto& t : reg.types()) {
      std::cout << (first ? "\n" : ",\n") << "    {\"type\": \"" << json_escape(t.decl.type) << "\", \"kind\": \""
                << to_string(t.decl.kind) << "\", \"file\": \"" << json_escape(t.file) << "\", \"summary\": \""
                << json_escape(t.decl.summary) << "\"}";
      first = false;
    }
    std::cout << "\n  ],\n  \"problems\": [";
    first = true;
    for (const auto& p : reg.problems()) {
      std::cout << (first ? "\n" : ",\n") << "    {\"file\": \"" << json_escape(p.file) << "\", \"stage\": \""
                << p.stage << "\", \"message\": \"" << json_escape(p.message) << "\"}";
      first = false;
    }
    std::cout << "\n  ]\n}\n";
  } else {
    std::cout << "searched: " << join(reg.searched()) << "\n";
    for (const auto& p : reg.plugins()) {
      std::cout << "\n" << p.file << "\n";
      for (const auto& type : p.types) {
        const auto* t = reg.find(type);
        std::cout << "  " << std::left << std::setw(24) << type << std::setw(11) << to_string(t->decl.kind)
                  << t->decl.summary << "\n";
      }
    }
    for (const auto& p : reg.problems()) std::cout << "\nnot loaded: " << p.str() << "\n";
  }
  return reg.problems().empty() ? kOk : kBadInput;
}

std::string kinds_text(ItemMask m) {
  std::vector<std::string> k;
  for (ItemKind i : {ItemKind::Truth, ItemKind::Measurement, ItemKind::Estimate})
    if (m & mask(i)) k.push_back(to_string(i));
  return k.empty() ? "-" : join(k, ", ");
}

void describe_params(std::ostream& os, const std::vector<ParamSpec>& ps, const std::string& indent, bool md) {
  for (const auto& p : ps) {
    std::string def = p.required ? "required" : p.default_text.empty() ? "optional" : "default " + p.default_text;
    if (md) {
      os << indent << "| `" << p.name << "` | " << describe_type(p) << " | " << def << " | " << p.doc << " |\n";
    } else {
      os << indent << std::left << std::setw(22) << p.name << " " << std::setw(26) << describe_type(p) << " "
         << std::setw(18) << def << " " << p.doc << "\n";
    }
    if (p.type == ParamType::Records) {
      if (md) {
        os << "\nFields of each `" << p.name << "` entry:\n\n| field | type | default | doc |\n|---|---|---|---|\n";
        describe_params(os, p.fields, "", true);
        os << "\n";
      } else {
        describe_params(os, p.fields, indent + "    ", false);
      }
    }
  }
}

void describe(std::ostream& os, const RegisteredType& t, bool md) {
  const auto& d = t.decl;
  if (md) {
    os << "## `" << d.type << "` (" << to_string(d.kind) << ")\n\n" << d.summary << "\n\n";
    if (!d.doc.empty()) os << d.doc << "\n\n";
    os << "Inputs: " << kinds_text(d.accepts) << " (" << d.min_inputs << " to "
       << (d.max_inputs < 0 ? std::string("any") : std::to_string(d.max_inputs)) << "); outputs: " << kinds_text(d.produces)
       << ".\n\n";
    if (!d.params.empty()) {
      os << "| parameter | type [unit] | default | doc |\n|---|---|---|---|\n";
      describe_params(os, d.params, "", true);
    }
    os << "\n";
    return;
  }
  os << d.type << " (" << to_string(d.kind) << ", from " << t.file << ")\n  " << d.summary << "\n";
  if (!d.doc.empty()) os << "\n" << d.doc << "\n";
  os << "\ninputs:  " << kinds_text(d.accepts) << " (" << d.min_inputs << " to "
     << (d.max_inputs < 0 ? std::string("any") : std::to_string(d.max_inputs)) << ")\noutputs: " << kinds_text(d.produces)
     << "\n\nparameters (bare numbers are SI: m, s, rad; or write a unit: 3 mrad, 1.5 km, 40 Hz):\n";
  describe_params(os, d.params, "  ", false);
}

int cmd_describe(int argc, char** argv) {
  Common c;
  std::string type;
  bool all = false, md = false;
  po::options_description o("trackflow describe options");
  o.add_options()("help,h", "show this help")("type", po::value(&type), "component type, e.g. filter.kalman")(
      "all", po::bool_switch(&all), "describe every type found")("markdown", po::bool_switch(&md),
                                                                   "Markdown output (used for docs/plugins.md)");
  o.add(common_options(c));
  po::positional_options_description pos;
  pos.add("type", 1);
  po::variables_map vm;
  if (!parse(argc, argv, o, pos, vm, "Usage: trackflow describe TYPE | --all [--markdown]")) return kOk;
  PluginRegistry reg = load_plugins(c, {});
  warn_problems(reg);
  if (all) {
    if (md) std::cout << "# Component reference\n\nGenerated by `trackflow describe --all --markdown` from each plugin's parameter declaration.\n\n";
    for (const auto& name : reg.type_names()) describe(std::cout, *reg.find(name), md);
    return kOk;
  }
  if (type.empty()) throw po::error("describe needs a TYPE (see `trackflow plugins`) or --all");
  const auto* t = reg.find(type);
  if (!t)
    throw ConfigError(unknown_type_message(type, reg));
  describe(std::cout, *t, md);
  return kOk;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h" || std::string(argv[1]) == "help") {
    std::cout << kTopHelp;
    return argc < 2 ? kBadInput : kOk;
  }
  const std::string cmd = argv[1];
  if (cmd == "--version") {
    std::cout << "trackflow " << kSdkVersion << " (plugin ABI " << kAbiVersion << ")\n";
    return kOk;
  }
  try {
    if (cmd == "run") return cmd_run(argc - 1, argv + 1);
    if (cmd == "validate") return cmd_validate(argc - 1, argv + 1);
    if (cmd == "plugins") return cmd_plugins(argc - 1, argv + 1);
    if (cmd == "describe") return cmd_describe(argc - 1, argv + 1);
    if (cmd == "sweep") return cmd_sweep(argc - 1, argv + 1);
    std::cerr << "trackflow: unknown command '" << cmd << "'"
              << did_you_mean(cmd, {"run", "validate", "plugins", "describe", "sweep"}) << "\n\n" << kTopHelp;
    return kBadInput;
  } catch (const ConfigError& e) {
    std::cerr << "trackflow: error: " << e.message() << "\n";
    return kBadInput;
  } catch (const DataError& e) {
    std::cerr << "trackflow: data error: " << e.what() << "\n";
    return kBadInput;
  } catch (const po::error& e) {
    std::cerr << "trackflow " << cmd << ": " << e.what() << " (see trackflow " << cmd << " --help)\n";
    return kBadInput;
  } catch (const std::exception& e) {
    std::cerr << "trackflow: internal error: " << e.what() << "\n";
    return kInternal;
  }
}
