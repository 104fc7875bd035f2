// Purpose: the `trackflow` command: run, report, validate, plugins, describe.
#include "cli_common.hpp"
#include "report_command.hpp"

#include <trackflow/host/engine.hpp>
#include <trackflow/host/guard.hpp>
#include <trackflow/host/output_names.hpp>
#include <trackflow/host/report.hpp>
#include <trackflow/host/suggest.hpp>
#include <trackflow/host/validate.hpp>
#include <trackflow/safe_output.hpp>
#include <trackflow/version.hpp>

#include <boost/program_options.hpp>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
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
  report FILE     run it and write one self-contained HTML report with plots (and the
                  per-step series as CSV): `run FILE --report FILE.html --series` in one word
  validate FILE   check a pipeline without running it (types, parameters, units, wiring)
  plugins         list the plugin files found and the component types they provide
  describe TYPE   show a component type's parameters (name, type, unit, default, doc)
  sweep FILE      run a pipeline over a grid of parameter values, one table row per point

Run `trackflow <command> --help` for the options of a command.

Exit codes: 0 ok, 1 an `expect` check failed, 2 bad configuration or input data
(or an output that cannot be written), 3 internal error (a bug, also a crash in a plugin).
Plugins are searched in: <trackflow>/../lib/trackflow/plugins (built in), --plugin-path
DIRs, the pipeline's plugin_paths (only with --trust-plugin-paths), then
$TRACKFLOW_PLUGIN_PATH (colon-separated). Built-in types are replaced only with --replace-type.

Across machines (a build with MPI: `trackflow --version` says so): `mpirun -np N trackflow run
FILE --threads T` (Slurm: `srun --mpi=pmix ...`) shares the runs among N processes of T threads;
every output is byte-identical to one process's with the same seed. Also for `sweep`.
Environment: TRACKFLOW_PLUGIN_PATH (above); TRACKFLOW_CRASH_HANDLER=0 leaves fatal signals to the
system (a core dump); TRACKFLOW_MPI_WINDOW=N, under mpirun, how many runs are handed out ahead of
the oldest one not yet merged (default 4 per thread of the job).
)";

// The thread counts accepted; 0 means one per core.
constexpr std::uint64_t kMaxThreads = 1024;

struct Loaded {
  PipelineConfig cfg;
  PluginRegistry reg;
  Graph graph;
};

// `track_run` >= 0: also record that run's items for the report (a sink.track node and, for a
// pipeline with a tracker, a sink.scene node are added; their ids go to `track_node`, `scene_node`).
Loaded load_pipeline(const std::string& file, const std::vector<std::string>& sets, const Common& c,
                     long long track_run = -1, std::string* track_node = nullptr, std::string* scene_node = nullptr) {
  std::vector<Override> overrides;
  for (const auto& s : sets) overrides.push_back(parse_override(s));
  apply_trust(c);
  Value root = load_yaml_file(file);
  Loaded l;
  l.cfg = parse_pipeline(root, file, overrides);
  l.reg = load_plugins(c, &l.cfg);
  warn_problems(l.reg);
  if (track_run >= 0 && track_node && l.reg.find("sink.track"))
    *track_node = add_track_recorder(l.cfg, l.reg, static_cast<std::uint64_t>(track_run));
  if (track_run >= 0 && scene_node && l.reg.find("sink.scene"))
    *scene_node = add_scene_recorder(l.cfg, l.reg, static_cast<std::uint64_t>(track_run));
  l.graph = build_graph(l.cfg, l.reg);
  warn_setup(l.graph.warnings);
  return l;
}

// `run` and `report` (= run with --report <out>/report.html --series).
int cmd_run(int argc, char** argv, bool report_mode = false) {
  Common c;
  std::string file, out_dir, metrics_json, report_html;
  std::vector<std::string> sets;
  // Numbers are read as text and checked here: program_options would wrap "-1" into 2^64-1.
  std::string runs_text, seed_text, threads_text = "1", track_run_text = "0";
  bool quiet = false, no_progress = false, series = false;
  po::options_description o(report_mode ? "trackflow report options" : "trackflow run options");
  o.add_options()("help,h", "show this help")("file", po::value(&file), "pipeline YAML file")(
      "runs,n", po::value(&runs_text), "Monte Carlo runs (default: the pipeline's `runs:`)")(
      "threads,j", po::value(&threads_text)->default_value("1"),
      "worker threads, 0: one per core (at most 1024); results are identical for any value")(
      "seed", po::value(&seed_text), "base seed, 0 to 2^64-1 (default: the pipeline's `seed:`)")(
      "set", po::value(&sets)->composing(),
      "override a parameter: --set kf.q=4 --set radar.sigma_range=\"20 m\" (repeatable)")(
      "out,o", po::value(&out_dir), "folder for files written by sinks (default: out/<pipeline name>)")(
      "metrics-json", po::value(&metrics_json),
      "write {node id: {metric: {value, unit[, band_lo, band_hi, confidence]}}} to this file")(
      "series", po::bool_switch(&series),
      "write every node's per-step series (e.g. sink.metrics' RMSE, ANEES, ANIS per time step) as CSV "
      "into the --out folder")(
      "report", po::value(&report_html),
      report_mode ? "the HTML file (default: <out>/report.html)" : "also write the HTML report with plots to this file")(
      "track-run", po::value(&track_run_text)->default_value("0"), "the run whose track the report draws")(
      "quiet,q", po::bool_switch(&quiet), "print only expect failures and errors")(
      "no-progress", po::bool_switch(&no_progress), "no progress bar even on a terminal");
  o.add(common_options(c));
  o.add(trust_options(c));
  po::positional_options_description pos;
  pos.add("file", 1);
  po::variables_map vm;
  if (!parse(argc, argv, o, pos, vm,
             report_mode ? "Usage: trackflow report FILE [options]\n\nRuns FILE like `trackflow run` and writes one "
                           "self-contained HTML report (plots inlined, opens offline) and the per-step series as CSV "
                           "into the --out folder."
                         : "Usage: trackflow run FILE [options]"))
    return kOk;
  if (file.empty()) throw po::error(std::string(report_mode ? "report" : "run") + " needs a pipeline FILE");
  const std::uint64_t max64 = std::numeric_limits<std::uint64_t>::max();
  const bool runs_given = vm.count("runs") > 0, seed_given = vm.count("seed") > 0;
  const std::uint64_t runs = runs_given ? parse_count(runs_text, "--runs", 1, max64) : 0;
  const std::uint64_t seed = seed_given ? parse_count(seed_text, "--seed", 0, max64) : 0;
  unsigned threads = static_cast<unsigned>(parse_count(threads_text, "--threads", 0, kMaxThreads));
  const std::uint64_t track_run = parse_count(track_run_text, "--track-run", 0, max64);
  const bool want_report = report_mode || !report_html.empty();
  std::string track_node, scene_node;
  Loaded l;
  agreed_setup([&] {
    l = load_pipeline(file, sets, c,
                      want_report ? static_cast<long long>(std::min<std::uint64_t>(track_run, 1ull << 62)) : -1,
                      &track_node, &scene_node);
  });
  RunOptions ro;
  ro.runs = runs_given ? runs : l.graph.config.runs;
  if (ro.runs == 0) throw ConfigError("--runs must be at least 1");
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  ro.threads = threads;
  ro.seed = seed_given ? seed : l.graph.config.seed;
  l.graph.config.seed = ro.seed;
  ro.output_dir = out_dir.empty() ? (std::filesystem::path("out") / l.graph.config.name).string() : out_dir;
  if (!no_progress && !quiet && is_root() && ::isatty(STDERR_FILENO) && ro.runs > 1) {
    ro.progress = [](std::uint64_t done, std::uint64_t total) {
      const int width = 40;
      const int filled = static_cast<int>(width * (static_cast<double>(done) / static_cast<double>(std::max<std::uint64_t>(total, 1))));
      std::cerr << "\r[" << std::string(filled, '#') << std::string(width - filled, '.') << "] " << done << "/"
                << total << " runs" << (done == total ? "\n" : "") << std::flush;
    };
  }
  if (want_report && track_run >= ro.runs)
    throw ConfigError("--track-run " + std::to_string(track_run) + ": there are only " + std::to_string(ro.runs) +
                      " runs (0 to " + std::to_string(ro.runs - 1) + ")");
  // Every output is checked before the runs: a typo in a path must not cost the whole ensemble.
  OutputFolderLock out_lock;
  if (is_root()) {
    if (!out_dir.empty() || series || want_report) check_output_folder(ro.output_dir, "--out");
    if (!metrics_json.empty()) check_output_file(metrics_json, "--metrics-json");
    if (!report_html.empty()) check_output_file(report_html, "--report");
    check_run_outputs(l.graph, {ro.output_dir, series || report_mode,
                                want_report && report_html.empty()
                                    ? (std::filesystem::path(ro.output_dir) / "report.html").string()
                                    : report_html,
                                metrics_json});
    // The default out/<name> is beneath the current folder, which a pipeline's repository may
    // be: a link there (out -> ~) would move every file.
    if (out_dir.empty())
      if (std::string why = linked_folder_problem(".", ro.output_dir); !why.empty())
        throw ConfigError("the default --out '" + ro.output_dir + "': " + why + " (pass --out to choose a folder)");
    // Another trackflow writing into this --out now is refused (flock on the folder, held to the end).
    out_lock.hold(ro.output_dir, "--out", !out_dir.empty() || series || want_report);
  }
  Outcome out = run_ensemble(l.graph, l.reg, ro);
  if (!is_root()) return kOk;  // rank 0 of the MPI job reports, checks and writes
  auto results = check_expects(l.graph, out);
  if (!metrics_json.empty()) write_metrics_json(metrics_json, out);
  ReportRequest req;
  if (series || report_mode) req.series_dir = ro.output_dir;
  if (want_report)
    req.html = report_html.empty() ? (std::filesystem::path(ro.output_dir) / "report.html").string() : report_html;
  if (want_report && report_html.empty()) req.html_out = ro.output_dir;
  req.track_node = track_node;
  req.scene_node = scene_node;
  req.track_run = track_run;
  req.command = command_line(argc, argv);
  const auto written = write_report_outputs(req, l.graph, out, results, static_cast<unsigned>(std::min<std::uint64_t>(ro.threads, ro.runs)));
  const bool all_pass = std::all_of(results.begin(), results.end(), [](const ExpectResult& r) { return r.passed; });
  if (!quiet) {
    print_summary(std::cout, l.graph, out, std::min<std::uint64_t>(ro.threads, ro.runs), results);
    if (const host::MpiSession* mpi = mpi_session())
      std::cout << "(runs shared by " << mpi->size() << " MPI processes, " << ro.threads << " thread"
                << (ro.threads == 1 ? "" : "s") << " each)\n";
    for (const auto& f : written) std::cout << "wrote " << printable(f) << "\n";
  } else {
    for (const auto& r : results)
      if (!r.passed) std::cout << "FAIL " << printable(r.text) << " (" << printable(r.expect.loc.str()) << ")\n";
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
  o.add(trust_options(c));
  po::positional_options_description pos;
  pos.add("file", 1);
  po::variables_map vm;
  if (!parse(argc, argv, o, pos, vm, "Usage: trackflow validate FILE [options]\n\nChecks types, parameters, units, wiring and data files; runs nothing.")) return kOk;
  if (file.empty()) throw po::error("validate needs a pipeline FILE");
  Loaded l = load_pipeline(file, sets, c);
  std::cout << printable(file) << ": ok (" << l.graph.nodes.size() << " nodes, " << l.graph.config.expects.size()
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
  PluginRegistry reg = load_plugins(c);
  if (json) {
    nlohmann::ordered_json j;
    j["searched"] = reg.searched();
    j["types"] = nlohmann::ordered_json::array();
    for (const auto& t : reg.types())
      j["types"].push_back(
          {{"type", t.decl.type}, {"kind", to_string(t.decl.kind)}, {"file", t.file}, {"summary", t.decl.summary}});
    j["problems"] = nlohmann::ordered_json::array();
    for (const auto& p : reg.problems())
      j["problems"].push_back({{"file", p.file}, {"stage", p.stage}, {"message", p.message}});
    std::cout << j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << "\n";
  } else {
    std::cout << "searched: " << join(reg.searched()) << "\n";
    // Columns as wide as their longest entry (plus two spaces), so long names never run into the kind.
    size_t type_w = 4, kind_w = 4;
    for (const auto& t : reg.types()) {
      type_w = std::max(type_w, t.decl.type.size());
      kind_w = std::max(kind_w, std::string(to_string(t.decl.kind)).size());
    }
    for (const auto& p : reg.plugins()) {
      std::cout << "\n" << printable(p.file) << "\n";
      for (const auto& type : p.types) {
        const auto* t = reg.find(type);
        std::cout << "  " << std::left << std::setw(static_cast<int>(type_w + 2)) << type
                  << std::setw(static_cast<int>(kind_w + 2)) << to_string(t->decl.kind) << printable(t->decl.summary) << "\n";
      }
    }
    for (const auto& p : reg.problems()) std::cout << "\nnot loaded: " << p.str() << "\n";
  }
  return reg.problems().empty() ? kOk : kBadInput;
}

std::string kinds_text(ItemMask m) {
  std::vector<std::string> k;
  for (ItemKind i : kItemKinds)
    if (m & mask(i)) k.push_back(to_string(i));
  return k.empty() ? "-" : join(k, ", ");
}

std::string default_text(const ParamSpec& p) {
  return p.required ? "required" : p.default_text.empty() ? "optional" : "default " + p.default_text;
}

void describe_params_md(std::ostream& os, const std::vector<ParamSpec>& ps) {
  for (const auto& p : ps) {
    os << "| `" << p.name << "` | " << describe_type(p) << " | " << default_text(p) << " | " << p.doc << " |\n";
    if (p.type == ParamType::Records) {
      os << "\nFields of each `" << p.name << "` entry:\n\n| field | type | default | doc |\n|---|---|---|---|\n";
      describe_params_md(os, p.fields);
      os << "\n";
    }
  }
}

// Text table: record fields indented under their list; every column as wide as its widest
// cell (over the nested fields too), so long names and `choice {...}` lists never misalign.
void describe_params_text(std::ostream& os, const std::vector<ParamSpec>& ps, const std::string& indent) {
  struct Row {
    std::string name, type, def, doc;
  };
  std::vector<Row> rows;
  auto collect = [&](auto& self, const std::vector<ParamSpec>& list, const std::string& in) -> void {
    for (const auto& p : list) {
      rows.push_back({in + p.name, describe_type(p), default_text(p), p.doc});
      if (p.type == ParamType::Records) self(self, p.fields, in + "    ");
    }
  };
  collect(collect, ps, "");
  size_t wn = 0, wt = 0, wd = 0;
  for (const auto& r : rows) {
    wn = std::max(wn, r.name.size());
    wt = std::max(wt, r.type.size());
    wd = std::max(wd, r.def.size());
  }
  for (const auto& r : rows)
    os << indent << std::left << std::setw(static_cast<int>(wn + 2)) << r.name << std::setw(static_cast<int>(wt + 2))
       << r.type << std::setw(static_cast<int>(wd + 2)) << r.def << r.doc << "\n";
}

// Said of a filter whose declaration has create_estimator (registry.hpp).
constexpr const char* kEstimatorNote =
    "Per-track estimator: yes (the same parameters make the estimator a tracker runs per track).";

// A node of this type as a pipeline writes it: its inputs and its required parameters as
// placeholders (issue 26: describe opened with prose; an analyst copies this first).
void describe_example(std::ostream& os, const ComponentDecl& d) {
  const std::string id = d.type.substr(d.type.rfind('.') + 1);
  os << "  - id: " << id << "\n    type: " << d.type << "\n";
  const std::string producer = "<a node producing " + kinds_text(d.accepts) + ">";
  if (d.max_inputs == 1) os << "    input: " << producer << "\n";
  else if (d.max_inputs != 0 && d.min_inputs > 0) {
    os << "    inputs: [" << producer;
    for (int k = 1; k < std::max(2, d.min_inputs); ++k) os << ", " << producer;
    os << "]\n";
  }
  std::string required;
  for (const auto& p : d.params)
    if (p.required) required += (required.empty() ? "" : ", ") + p.name + ": <" + describe_type(p) + ">";
  if (!required.empty()) os << "    params: { " << required << " }\n";
  os << "  (" << (required.empty() ? "every parameter has a default" : "the required parameters; the others have defaults")
     << ": the table below)\n";
}

void describe(std::ostream& os, const RegisteredType& t, bool md) {
  const auto& d = t.decl;
  if (md) {
    os << "## `" << d.type << "` (" << to_string(d.kind) << ")\n\n" << d.summary << "\n\n";
    if (!d.doc.empty()) os << d.doc << "\n\n";
    os << "Inputs: " << kinds_text(d.accepts) << " (" << d.min_inputs << " to "
       << (d.max_inputs < 0 ? std::string("any") : std::to_string(d.max_inputs)) << "); outputs: " << kinds_text(d.produces)
       << ".\n\n";
    if (d.create_estimator) os << kEstimatorNote << "\n\n";
    if (!d.params.empty()) {
      os << "| parameter | type [unit] | default | doc |\n|---|---|---|---|\n";
      describe_params_md(os, d.params);
    }
    os << "\n";
    return;
  }
  os << d.type << " (" << to_string(d.kind) << ", from " << t.file << ")\n  " << d.summary << "\n\n";
  describe_example(os, d);
  if (!d.doc.empty()) os << "\n" << d.doc << "\n";
  os << "\ninputs:  " << kinds_text(d.accepts) << " (" << d.min_inputs << " to "
     << (d.max_inputs < 0 ? std::string("any") : std::to_string(d.max_inputs)) << ")\noutputs: " << kinds_text(d.produces)
     << "\n" << (d.create_estimator ? std::string(kEstimatorNote) + "\n" : std::string())
     << "\nparameters (write a unit: 3 mrad, 1.5 km, 40 Hz; a bare number is SI, m or s, and an angle needs its unit):\n";
  describe_params_text(os, d.params, "  ");
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
  PluginRegistry reg = load_plugins(c);
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

std::string rank_prefix(const host::MpiSession* mpi) {
  return mpi && mpi->rank() != 0 ? "rank " + std::to_string(mpi->rank()) + ": " : std::string();
}

int run_command(const std::string& cmd, int argc, char** argv) {
  // Commands that only inspect: one process of an MPI job answers.
  if (!is_root() && (cmd == "validate" || cmd == "plugins" || cmd == "describe")) return kOk;
  if (cmd == "run") return cmd_run(argc - 1, argv + 1);
  if (cmd == "report") return cmd_run(argc - 1, argv + 1, true);
  if (cmd == "validate") return cmd_validate(argc - 1, argv + 1);
  if (cmd == "plugins") return cmd_plugins(argc - 1, argv + 1);
  if (cmd == "describe") return cmd_describe(argc - 1, argv + 1);
  if (cmd == "sweep") return cmd_sweep(argc - 1, argv + 1);
  if (is_root())
    std::cerr << "trackflow: unknown command '" << quote_token(cmd) << "'"
              << did_you_mean(cmd, {"run", "report", "validate", "plugins", "describe", "sweep"}) << "\n\n"
              << kTopHelp;
  return kBadInput;
}

int dispatch(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h" || std::string(argv[1]) == "help") {
    std::cout << kTopHelp;
    return argc < 2 ? kBadInput : kOk;
  }
  const std::string cmd = argv[1];
  if (cmd == "--version") {
    std::cout << "trackflow " << kSdkVersion << " (plugin ABI " << kAbiVersion << (host::mpi_built() ? ", MPI" : "")
              << ")\n";
    return kOk;
  }
  std::unique_ptr<host::MpiSession> mpi;
  int code = kOk;
  // In an MPI job only rank 0 prints errors: the others fail the same way (the same command
  // line), or report to rank 0 (agreed_setup, the distributed engine). Internal errors are
  // printed by whichever process has them.
  auto quiet = [&mpi] { return mpi && mpi->rank() != 0; };
  try {
    mpi = host::start_mpi_if_launched(argc, argv);
    set_mpi_session(mpi.get());
    code = run_command(cmd, argc, argv);
  } catch (const host::ReportedElsewhere&) {
    code = kBadInput;  // rank 0 prints it
  } catch (const ConfigError& e) {
    if (!quiet()) std::cerr << "trackflow: error: " << e.message() << "\n";
    code = kBadInput;
  } catch (const DataError& e) {
    if (!quiet()) std::cerr << "trackflow: data error: " << e.what() << "\n";
    code = kBadInput;
  } catch (const po::error& e) {
    if (!quiet())
      std::cerr << "trackflow " << quote_token(cmd) << ": " << e.what() << " (see trackflow " << quote_token(cmd)
                << " --help)\n";
    code = kBadInput;
  } catch (const InternalError& e) {
    std::cerr << "trackflow: internal error: " << rank_prefix(mpi.get()) << e.what() << "\n";
    code = kInternal;
  } catch (const std::bad_alloc&) {
    std::cerr << "trackflow: error: " << rank_prefix(mpi.get()) << "out of memory\n";
    code = kInternal;
  } catch (const std::exception& e) {
    std::cerr << "trackflow: internal error: " << rank_prefix(mpi.get()) << e.what() << "\n";
    code = kInternal;
  } catch (...) {
    std::cerr << "trackflow: internal error: " << rank_prefix(mpi.get())
              << "an exception that is not a std::exception\n";
    code = kInternal;
  }
  // Every process of an MPI job exits with the job's code (the largest).
  if (mpi) code = mpi->agree_exit_code(code);
  set_mpi_session(nullptr);
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  // TRACKFLOW_CRASH_HANDLER=0 leaves fatal signals to the system (a core dump for a debugger).
  const char* handler = std::getenv("TRACKFLOW_CRASH_HANDLER");
  if (!handler || std::string(handler) != "0") install_crash_handler();
  // Past RLIMIT_FSIZE a write fails with EFBIG (reported, the temporary removed: safe_output.hpp)
  // instead of SIGXFSZ killing the process with a truncated file left behind.
  std::signal(SIGXFSZ, SIG_IGN);
  int rc = dispatch(argc, argv);
  // Whatever was printed must have reached its destination: a full disk is not a success.
  std::cout.flush();
  if (!std::cout || std::fflush(stdout) != 0 || std::ferror(stdout)) {
    const int err = errno;
    std::cerr << "trackflow: error: cannot write the standard output" << (err ? std::string(": ") + std::strerror(err) : "")
              << "\n";
    if (rc == kOk || rc == kExpectFailed) rc = kBadInput;
  }
  return rc;
}
