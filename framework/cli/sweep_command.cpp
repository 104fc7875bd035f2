// Purpose: `trackflow sweep`: runs a pipeline at every point of a parameter grid and tabulates chosen metrics.
#include "cli_common.hpp"
#include "csv_text.hpp"
#include "html_report.hpp"
#include "report_command.hpp"

#include <trackflow/host/engine.hpp>
#include <trackflow/host/report.hpp>
#include <trackflow/host/suggest.hpp>
#include <trackflow/host/sweep.hpp>
#include <trackflow/number_text.hpp>
#include <trackflow/safe_output.hpp>
#include <trackflow/units.hpp>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <system_error>
#include <mutex>
#include <optional>
#include <thread>

namespace trackflow::cli {
namespace {

const char* kUsage = R"(Usage: trackflow sweep FILE --param node.param=v1,v2,... [--param ...] [--zip] [options]

Runs FILE once per point of the grid (the Cartesian product of the --param lists, first
--param slowest; with --zip the lists move together, point i taking the i-th value of each)
and prints one row per point with the chosen metrics. Every point uses the
same seed (common random numbers), so differences between rows come from the parameters.
Grid points run in parallel on --threads workers (each point's runs on one thread); the table
does not depend on the thread count. `expect:` checks are not applied in a sweep.
The --csv file holds numbers in SI with the unit in the column header (radar.sigma_range_m,
score.position_rmse_m); --report writes an HTML page with each metric against each numeric
axis that changes it. A parameter path reaches into components and lists of records, as --set
does: --param 'truth.segments[1].turn_rate=2 deg/s,4 deg/s'.

Example (paper 000 Table 10):
  trackflow sweep pipelines/quickstart.yaml --param kf.q=0.01,0.1,1,10,100 --runs 50 \
      --metric score.position_rmse --metric score.anees --csv q_sweep.csv
Two filters tuned alike, 4 points (without --zip, 16):
  trackflow sweep study.yaml --param kf.q=0.1,1,10,100 --param ukf.q=0.1,1,10,100 --zip
)";

struct MetricRef {
  std::string node, metric;
};

std::string cell(double v) {
  if (!std::isfinite(v)) return "";
  return number_text::general(v, 6);
}

// The declaration a parameter path names: "q", "segments[1].turn_rate" (a field of a record),
// "position[2]" (an element of a list of reals, declared as the list). Null where the path goes
// through a component (its parameters are its type's, not this node's) or names nothing.
std::optional<ParamSpec> path_spec(const std::vector<ParamSpec>& params, const std::string& path) {
  const std::vector<ParamSpec>* level = &params;
  const ParamSpec* spec = nullptr;
  std::size_t at = 0;
  while (at <= path.size()) {
    const std::size_t dot = std::min(path.find('.', at), path.size());
    const std::string step = path.substr(at, dot - at);
    const std::string name = step.substr(0, step.find('['));
    const bool indexed = name.size() != step.size();
    spec = nullptr;
    for (const auto& p : *level)
      if (p.name == name) spec = &p;
    if (!spec) return std::nullopt;
    if (dot == path.size()) {
      if (!indexed) return *spec;
      if (spec->type != ParamType::RealList) return std::nullopt;
      ParamSpec element = *spec;  // one element of a list of reals: a real of the list's dimension
      element.type = ParamType::Real;
      return element;
    }
    if (!indexed || spec->type != ParamType::Records) return std::nullopt;
    level = &spec->fields;
    at = dot + 1;
  }
  return std::nullopt;
}

// An axis' values in SI when its parameter is a real or an integer ("5 m" -> 5, "20 km" ->
// 20000), with the SI unit; NaN for values that are not one number (lists, choices, text).
report::SweepAxisView axis_view(const host::SweepAxis& a, const host::Graph& g,
                                const std::vector<std::vector<host::Override>>& grid, size_t axis) {
  report::SweepAxisView v;
  v.name = a.node + "." + a.param;
  std::optional<ParamSpec> spec;
  for (const auto& n : g.nodes)
    if (n.config.id == a.node) spec = path_spec(n.type->decl.params, a.param);
  const bool numeric = spec && (spec->type == ParamType::Real || spec->type == ParamType::Integer);
  if (numeric && spec->type == ParamType::Real && !spec->dimension.dimensionless()) v.unit = spec->dimension.str();
  for (const auto& point : grid) {
    const std::string& text = point[axis].value;
    v.text.push_back(text);
    double x = NAN;
    if (numeric) {
      try {
        x = parse_quantity(text).value;
      } catch (const std::exception&) {
        x = NAN;  // already refused by validation if it mattered; keep the text
      }
    }
    v.value.push_back(x);
  }
  return v;
}

}  // namespace

int cmd_sweep(int argc, char** argv) {
  Common c;
  std::string file, csv_path, report_path;
  std::vector<std::string> params, sets, metric_names;
  std::string runs_text, seed_text, threads_text = "1";
  bool quiet = false, zip = false;
  po::options_description o("trackflow sweep options");
  o.add_options()("help,h", "show this help")("file", po::value(&file), "pipeline YAML file")(
      "param,p", po::value(&params)->composing(), "a grid axis: node.param=v1,v2,... (repeatable)")(
      "zip", po::bool_switch(&zip),
      "tie the --param lists (all the same length): point i takes the i-th value of each, instead of the product")(
      "metric,m", po::value(&metric_names)->composing(),
      "node.metric to tabulate (repeatable; default: position_rmse, velocity_rmse and anees of every "
      "node that reports them)")("runs,n", po::value(&runs_text), "Monte Carlo runs per grid point (default: the pipeline's)")(
      "threads,j", po::value(&threads_text)->default_value("1"),
      "grid points run in parallel, at most 1024 (in an MPI job: threads per process for each point's runs)")(
      "seed", po::value(&seed_text), "base seed, 0 to 2^64-1 (default: the pipeline's)")(
      "set", po::value(&sets)->composing(), "fixed override for every point, as for run")(
      "csv", po::value(&csv_path), "also write the table to this CSV file (SI numbers, units in the header)")(
      "report", po::value(&report_path), "also write an HTML report: each metric against the first numeric axis")(
      "out,o", po::value<std::string>(), "folder for files written by sinks (default: out/<name>/sweep-<i>)")(
      "quiet,q", po::bool_switch(&quiet), "print only the table and errors (no progress, header or 'wrote' lines)");
  o.add(common_options(c));
  o.add(trust_options(c));
  po::positional_options_description pos;
  pos.add("file", 1);
  po::variables_map vm;
  if (!parse(argc, argv, o, pos, vm, kUsage)) return kOk;
  if (file.empty()) throw po::error("sweep needs a pipeline FILE");
  if (params.empty()) throw po::error("sweep needs at least one --param node.param=v1,v2,...");

  const std::uint64_t max64 = std::numeric_limits<std::uint64_t>::max();
  const bool runs_given = vm.count("runs") > 0, seed_given = vm.count("seed") > 0;
  const std::uint64_t runs = runs_given ? parse_count(runs_text, "--runs", 1, max64) : 0;
  const std::uint64_t seed = seed_given ? parse_count(seed_text, "--seed", 0, max64) : 0;
  const unsigned threads = static_cast<unsigned>(std::max<std::uint64_t>(1, parse_count(threads_text, "--threads", 0, 1024)));

  std::vector<host::SweepAxis> axes;
  for (const auto& p : params) {
    axes.push_back(host::parse_sweep_axis(p));
    // Two axes on one parameter: the later one would win at every point and the rows would be
    // labelled with the earlier one's values.
    for (size_t k = 0; k + 1 < axes.size(); ++k)
      if (axes[k].node == axes.back().node && axes[k].param == axes.back().param)
        throw po::error("--param " + host::quote_token(axes.back().node + "." + axes.back().param) +
                        " is given twice; give all its values in one --param");
  }
  std::vector<host::Override> fixed;
  for (const auto& s : sets) fixed.push_back(host::parse_override(s));
  const auto grid = zip ? host::sweep_zip(axes) : host::sweep_grid(axes);

  // Build (and so validate) every point's graph before running any: a bad value fails fast.
  apply_trust(c);
  host::PipelineConfig base;
  host::PluginRegistry reg;
  std::vector<host::Graph> graphs;
  agreed_setup([&] {
    const host::Value root = host::load_yaml_file(file);
    base = host::parse_pipeline(root, file, fixed);
    reg = load_plugins(c, &base);
    warn_problems(reg);
    for (size_t i = 0; i < grid.size(); ++i) {
      auto overrides = fixed;
      overrides.insert(overrides.end(), grid[i].begin(), grid[i].end());
      try {
        graphs.push_back(host::build_graph(host::parse_pipeline(root, file, overrides), reg));
      } catch (const ConfigError& e) {
        std::string point;
        for (const auto& ov : grid[i]) point += " " + ov.node + "." + ov.param + "=" + ov.value;
        throw ConfigError(std::string(e.what()) + " (grid point" + point + ")", e.where(), e.node());
      }
    }
  });
  // Each distinct warning once, however many grid points share it.
  std::vector<std::string> warnings;
  for (const auto& g : graphs)
    for (const auto& w : g.warnings)
      if (std::find(warnings.begin(), warnings.end(), w) == warnings.end()) warnings.push_back(w);
  warn_setup(warnings);
  const std::string out_root =
      vm.count("out") ? vm["out"].as<std::string>() : (std::filesystem::path("out") / base.name).string();
  // Outputs are checked before the grid runs; another trackflow writing into --out is refused.
  OutputFolderLock out_lock;
  if (is_root()) {
    if (vm.count("out")) check_output_folder(out_root, "--out");
    if (!csv_path.empty()) check_output_file(csv_path, "--csv");
    if (!report_path.empty()) check_output_file(report_path, "--report");
    // Neither the default out/<name> nor the sweep-<i> folders trackflow names are followed
    // through a link (safe_output.hpp).
    std::string why = vm.count("out") ? std::string() : linked_folder_problem(".", out_root);
    for (size_t i = 0; i < grid.size() && why.empty(); ++i) why = linked_folder_problem(out_root, "sweep-" + std::to_string(i));
    if (!why.empty()) throw ConfigError("--out '" + out_root + "': " + why);
    out_lock.hold(out_root, "--out", vm.count("out") > 0);
  }

  std::vector<host::Outcome> outcomes(grid.size());
  std::atomic<size_t> next{0}, done{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto worker = [&]() {
    for (;;) {
      const size_t i = next.fetch_add(1);
      if (i >= grid.size()) return;
      try {
        host::RunOptions ro;
        ro.runs = runs_given ? runs : graphs[i].config.runs;
        ro.seed = seed_given ? seed : graphs[i].config.seed;
        ro.threads = 1;
        ro.output_dir = (std::filesystem::path(out_root) / ("sweep-" + std::to_string(i))).string();
        outcomes[i] = host::run_graph(graphs[i], reg, ro);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next = grid.size();
      }
      const size_t d = ++done;
      if (!quiet && ::isatty(STDERR_FILENO)) std::cerr << "\rgrid point " << d << "/" << grid.size() << std::flush;
    }
  };
  if (host::MpiSession* mpi = mpi_session()) {
    // An MPI job runs the points one after another, each point's runs shared by all processes
    // (--threads per process); rank 0 merges, writes the sinks' files and prints the table.
    for (size_t i = 0; i < grid.size(); ++i) {
      host::RunOptions ro;
      ro.runs = runs_given ? runs : graphs[i].config.runs;
      ro.seed = seed_given ? seed : graphs[i].config.seed;
      ro.threads = std::max(1u, threads);
      ro.output_dir = (std::filesystem::path(out_root) / ("sweep-" + std::to_string(i))).string();
      outcomes[i] = run_ensemble(graphs[i], reg, ro);
      if (!quiet && is_root() && ::isatty(STDERR_FILENO)) std::cerr << "\rgrid point " << i + 1 << "/" << grid.size() << std::flush;
    }
    if (!is_root()) return kOk;
  } else {
    std::vector<std::thread> pool;
    // Every started thread is joined however this block is left (a joinable std::thread
    // destroyed would terminate the process).
    struct Joiner {
      std::vector<std::thread>& pool;
      ~Joiner() {
        for (auto& t : pool)
          if (t.joinable()) t.join();
      }
    } joiner{pool};
    const unsigned nthreads = std::max(1u, std::min<unsigned>(threads, static_cast<unsigned>(grid.size())));
    try {
      for (unsigned t = 0; t < nthreads; ++t) pool.emplace_back(worker);
    } catch (const std::system_error& e) {
      // A process limit: the points that started share the grid; none started: this thread runs it.
      std::cerr << "trackflow: warning: started " << pool.size() << " of " << nthreads << " threads (" << e.what()
                << "); the table is the same with fewer\n";
      if (pool.empty()) worker();
    }
  }
  if (!quiet && ::isatty(STDERR_FILENO)) std::cerr << "\n";
  if (error) std::rethrow_exception(error);

  std::vector<MetricRef> metrics;
  if (metric_names.empty()) {
    for (const auto& n : outcomes.front().nodes)
      for (const char* m : {"position_rmse", "velocity_rmse", "anees"})
        if (n.summary.find(m)) metrics.push_back({n.id, m});
  } else {
    for (const auto& name : metric_names) {
      const auto d = name.find('.');
      if (d == std::string::npos) throw po::error("--metric '" + name + "' must be node.metric");
      metrics.push_back({name.substr(0, d), name.substr(d + 1)});
    }
  }
  // Same rules as expect: a metric that does not exist is a mistake, listed with what does.
  for (const auto& m : metrics) {
    const host::NodeOutcome* n = outcomes.front().find(m.node);
    std::vector<std::string> names;
    if (n)
      for (const auto& x : n->summary.metrics) names.push_back(x.name);
    if (!n || !n->summary.find(m.metric))
      throw ConfigError("--metric " + m.node + "." + m.metric + ": " +
                        (n ? "no such metric" + host::did_you_mean(m.metric, names) + "; it reports: " + host::join(names)
                           : std::string("no such node")));
  }

  std::vector<std::string> header;
  for (const auto& a : axes) header.push_back(a.node + "." + a.param);
  for (const auto& m : metrics) header.push_back(m.node + "." + m.metric);
  std::vector<std::vector<std::string>> rows;
  for (size_t i = 0; i < grid.size(); ++i) {
    std::vector<std::string> row;
    for (const auto& ov : grid[i]) row.push_back(ov.value);
    for (const auto& m : metrics) row.push_back(cell(outcomes[i].find(m.node)->summary.find(m.metric)->value));
    rows.push_back(std::move(row));
  }
  std::vector<size_t> width(header.size());
  for (size_t k = 0; k < header.size(); ++k) {
    width[k] = header[k].size();
    for (const auto& r : rows) width[k] = std::max(width[k], r[k].size());
  }
  if (!quiet) std::cout << "sweep " << base.name << ": " << grid.size() << " grid points" << (zip && axes.size() > 1 ? " (zipped)" : "") << "\n";
  for (size_t k = 0; k < header.size(); ++k) std::cout << (k ? "  " : "") << std::setw(static_cast<int>(width[k])) << host::printable(header[k]);
  std::cout << "\n";
  for (const auto& r : rows) {
    for (size_t k = 0; k < r.size(); ++k) std::cout << (k ? "  " : "") << std::setw(static_cast<int>(width[k])) << host::printable(r[k]);
    std::cout << "\n";
  }
  std::vector<report::SweepAxisView> axis_views;
  for (size_t a = 0; a < axes.size(); ++a) axis_views.push_back(axis_view(axes[a], graphs.front(), grid, a));
  std::vector<report::SweepMetricView> metric_views;
  for (const auto& m : metrics) {
    report::SweepMetricView v{m.node + "." + m.metric, outcomes.front().find(m.node)->summary.find(m.metric)->unit, {}};
    for (const auto& o : outcomes) v.value.push_back(o.find(m.node)->summary.find(m.metric)->value);
    metric_views.push_back(std::move(v));
  }
  if (!csv_path.empty()) {
    // Numbers in SI, units in the header, text (lists, choices) quoted per RFC 4180.
    std::string text;
    std::vector<std::string> cols;
    for (const auto& a : axis_views) cols.push_back(report::column_header(a.name, a.unit));
    for (const auto& m : metric_views) cols.push_back(report::column_header(m.name, m.unit));
    for (size_t k = 0; k < cols.size(); ++k) text += (k ? "," : "") + report::csv_field(cols[k]);
    text += "\n";
    for (size_t i = 0; i < grid.size(); ++i) {
      size_t k = 0;
      for (const auto& a : axis_views)
        text += (k++ ? "," : "") + (std::isfinite(a.value[i]) ? report::csv_number(a.value[i]) : report::csv_field(a.text[i]));
      for (const auto& m : metric_views) text += (k++ ? "," : "") + report::csv_number(m.value[i]);
      text += "\n";
    }
    report::write_text_file(csv_path, text);
    if (!quiet) std::cout << "wrote " << csv_path << "\n";
  }
  if (!report_path.empty()) {
    report::SweepReport r;
    r.graph = &graphs.front();
    r.runs = outcomes.front().runs;
    r.command = command_line(argc, argv);
    r.axes = axis_views;
    r.metrics = metric_views;
    r.zipped = zip && axes.size() > 1;
    if (!csv_path.empty()) r.files.push_back(csv_path);
    report::write_text_file(report_path, report::render_sweep_report(r));
    if (!quiet) std::cout << "wrote " << report_path << "\n";
  }
  return kOk;
}

}  // namespace trackflow::cli
