// Purpose: `trackflow sweep`: runs a pipeline at every point of a parameter grid and tabulates chosen metrics.
#include "cli_common.hpp"

#include <trackflow/host/engine.hpp>
#include <trackflow/host/report.hpp>
#include <trackflow/host/suggest.hpp>
#include <trackflow/host/sweep.hpp>

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
#include <mutex>
#include <thread>

namespace trackflow::cli {
namespace {

const char* kUsage = R"(Usage: trackflow sweep FILE --param node.param=v1,v2,... [--param ...] [options]

Runs FILE once per point of the grid (the Cartesian product of the --param lists, first
--param slowest) and prints one row per point with the chosen metrics. Every point uses the
same seed (common random numbers), so differences between rows come from the parameters.
Grid points run in parallel on --threads workers (each point's runs on one thread); the table
does not depend on the thread count. `expect:` checks are not applied in a sweep.

Example (paper 000 Table 10):
  trackflow sweep pipelines/quickstart.yaml --param kf.q=0.01,0.1,1,10,100 --runs 50 \
      --metric score.position_rmse --metric score.anees --csv q_sweep.csv
)";

struct MetricRef {
  std::string node, metric;
};

std::string cell(double v) {
  if (!std::isfinite(v)) return "";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

int cmd_sweep(int argc, char** argv) {
  Common c;
  std::string file, csv_path;
  std::vector<std::string> params, sets, metric_names;
  std::uint64_t runs = 0, seed = 0;
  unsigned threads = 1;
  po::options_description o("trackflow sweep options");
  o.add_options()("help,h", "show this help")("file", po::value(&file), "pipeline YAML file")(
      "param,p", po::value(&params)->composing(), "a grid axis: node.param=v1,v2,... (repeatable)")(
      "metric,m", po::value(&metric_names)->composing(),
      "node.metric to tabulate (repeatable; default: position_rmse, velocity_rmse and anees of every "
      "node that reports them)")("runs,n", po::value(&runs), "Monte Carlo runs per grid point (default: the pipeline's)")(
      "threads,j", po::value(&threads)->default_value(1), "grid points run in parallel")(
      "seed", po::value(&seed), "base seed (default: the pipeline's)")(
      "set", po::value(&sets)->composing(), "fixed override for every point, as for run")(
      "csv", po::value(&csv_path), "also write the table to this CSV file")(
      "out,o", po::value<std::string>(), "folder for files written by sinks (default: out/<name>/sweep-<i>)");
  o.add(common_options(c));
  po::positional_options_description pos;
  pos.add("file", 1);
  po::variables_map vm;
  if (!parse(argc, argv, o, pos, vm, kUsage)) return kOk;
  if (file.empty()) throw po::error("sweep needs a pipeline FILE");
  if (params.empty()) throw po::error("sweep needs at least one --param node.param=v1,v2,...");

  std::vector<host::SweepAxis> axes;
  for (const auto& p : params) axes.push_back(host::parse_sweep_axis(p));
  std::vector<host::Override> fixed;
  for (const auto& s : sets) fixed.push_back(host::parse_override(s));
  const auto grid = host::sweep_grid(axes);

  // Build (and so validate) every point's graph before running any: a bad value fails fast.
  const host::Value root = host::load_yaml_file(file);
  const host::PipelineConfig base = host::parse_pipeline(root, file, fixed);
  host::PluginRegistry reg = load_plugins(c, base.plugin_paths);
  warn_problems(reg);
  std::vector<host::Graph> graphs;
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

  std::vector<host::Outcome> outcomes(grid.size());
  std::atomic<size_t> next{0}, done{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  const std::string out_root =
      vm.count("out") ? vm["out"].as<std::string>() : (std::filesystem::path("out") / base.name).string();
  auto worker = [&]() {
    for (;;) {
      const size_t i = next.fetch_add(1);
      if (i >= grid.size()) return;
      try {
        host::RunOptions ro;
        ro.runs = vm.count("runs") ? runs : graphs[i].config.runs;
        ro.seed = vm.count("seed") ? seed : graphs[i].config.seed;
        ro.threads = 1;
        ro.output_dir = (std::filesystem::path(out_root) / ("sweep-" + std::to_string(i))).string();
        outcomes[i] = host::run_graph(graphs[i], reg, ro);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next = grid.size();
      }
      const size_t d = ++done;
      if (::isatty(STDERR_FILENO)) std::cerr << "\rgrid point " << d << "/" << grid.size() << std::flush;
    }
  };
  std::vector<std::thread> pool;
  const unsigned nthreads = std::max(1u, std::min<unsigned>(threads, static_cast<unsigned>(grid.size())));
  for (unsigned t = 0; t < nthreads; ++t) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  if (::isatty(STDERR_FILENO)) std::cerr << "\n";
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
  std::cout << "sweep " << base.name << ": " << grid.size() << " grid points\n";
  for (size_t k = 0; k < header.size(); ++k) std::cout << (k ? "  " : "") << std::setw(static_cast<int>(width[k])) << header[k];
  std::cout << "\n";
  for (const auto& r : rows) {
    for (size_t k = 0; k < r.size(); ++k) std::cout << (k ? "  " : "") << std::setw(static_cast<int>(width[k])) << r[k];
    std::cout << "\n";
  }
  if (!csv_path.empty()) {
    const auto parent = std::filesystem::path(csv_path).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
    std::ofstream f(csv_path);
    auto quote = [](const std::string& s) {
      return s.find_first_of(",\"") == std::string::npos ? s : "\"" + std::string(s) + "\"";
    };
    for (size_t k = 0; k < header.size(); ++k) f << (k ? "," : "") << quote(header[k]);
    f << "\n";
    for (const auto& r : rows) {
      for (size_t k = 0; k < r.size(); ++k) f << (k ? "," : "") << quote(r[k]);
      f << "\n";
    }
    if (!f) throw ConfigError("cannot write '" + csv_path + "'");
    std::cout << "wrote " << csv_path << "\n";
  }
  return kOk;
}

}  // namespace trackflow::cli
