// Purpose: benchmark: sink.csv rows per second (estimates of a 9-state filter plus truth, quickstart-sized runs), this build's plugin against another build's side by side.
//
// Usage: trackflow-bench-csv [--old-plugins DIR] [--runs N] [--rounds R] [--plugins DIR]
// Single thread. The items of one quickstart-like run (601 steps at 10 Hz of a CV target at
// ~10 km; each step a truth sample and the estimate of a 9-state constant-acceleration filter:
// state, 9x9 covariance and its ENU block, NIS) are made once; every round then delivers them N
// times (default 200 runs, as the quickstart) to a fresh sink.csv in the engine's order (truth,
// then the estimate of the same step), ends and merges each run and finishes the file under a
// temporary --out, and counts rows per second of CPU time (and of wall time). Three layouts: the
// default columns (21 numbers a row), the same with precision: 10, and full_covariance: true (42).
// With --old-plugins (e.g. /work/main/build/lib/trackflow/plugins) the other build's sink.csv
// takes turns with this one's (alternating, best round each) and the two files are compared byte
// for byte; when they differ, every number of this build's file is rounded to "%.10g" (the
// default before sink.csv wrote shortest round-trip numbers) and compared again.
#include "bench_common.hpp"

#include <trackflow/estimate_state.hpp>
#include <trackflow/host/guard.hpp>
#include <trackflow/number_text.hpp>
#include <trackflow/rng.hpp>

#include <unistd.h>

#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

using namespace trackflow;
using namespace trackflow::bench;

namespace {

struct Step {
  Truth truth;
  Estimate estimate;
};

// One run's items: the quickstart's target, a 9-state [x y z vx vy vz ax ay az] estimate a few
// metres off with a dense covariance (full-precision doubles, as a filter's are).
std::vector<Step> make_run() {
  const double T = 0.1;
  const Vec3 p0(6000, 8000, 1000), v0(-150, 50, 0);
  Rng rng(1);
  std::vector<Step> steps(601);
  const int enu_index[6] = {0, 1, 2, 3, 4, 5};
  for (int k = 0; k < 601; ++k) {
    Step& s = steps[static_cast<size_t>(k)];
    const double t = k * T;
    s.truth.time = t;
    s.truth.position = p0 + v0 * t;
    s.truth.velocity = v0;
    Eigen::Matrix<double, 9, 1> x;
    x << s.truth.position, s.truth.velocity, Vec3::Zero();
    Eigen::Matrix<double, 9, 9> L = Eigen::Matrix<double, 9, 9>::Zero();
    for (int i = 0; i < 9; ++i) {
      x(i) += (i < 3 ? 3.0 : i < 6 ? 1.0 : 0.2) * rng.normal();
      for (int j = 0; j <= i; ++j) L(i, j) = (i == j ? 2.0 : 0.3) * rng.normal();
    }
    Estimate& e = s.estimate;
    e.time = t;
    e.updated = true;
    e.initialised = true;
    set_estimate_state<9>(e, x, L * L.transpose(), enu_index);
    e.innovation = Vec3(rng.normal(), rng.normal(), rng.normal());
    e.nis = e.innovation.squaredNorm();
  }
  return steps;
}

// Writes `runs` runs of `steps` through a fresh sink.csv of `reg` into `dir`; returns the rows.
double write_file(const host::PluginRegistry& reg, const std::string& params, const std::vector<Step>& steps, int runs,
                  const std::string& dir) {
  host::OutputDirectoryScope out(dir);
  auto worker = make(reg, "sink.csv", params);
  auto aggregate = make(reg, "sink.csv", params);
  const std::vector<InputInfo> inputs = {{"kf", "filter.ekf", mask(ItemKind::Estimate), {}},
                                         {"truth", "sim.trajectory", mask(ItemKind::Truth), {}}};
  worker->set_inputs(inputs);
  aggregate->set_inputs(inputs);
  for (int run = 0; run < runs; ++run) {
    RunContext ctx;
    ctx.run = static_cast<std::uint64_t>(run);
    worker->start_run(ctx);
    for (const Step& s : steps) {
      worker->on_truth(s.truth, 1);
      worker->on_estimate(s.estimate, 0);
    }
    auto result = worker->end_run();
    aggregate->merge(*result);
  }
  Summary summary;
  FinishContext fin;
  fin.node = "log";
  fin.output_dir = dir;
  fin.runs = static_cast<std::uint64_t>(runs);
  aggregate->finish(summary, fin);
  return static_cast<double>(runs) * static_cast<double>(steps.size());
}

std::string file_text(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

// Every cell of `csv` that is a number, as printf("%.*g", precision) writes it; the rest as it is.
std::string rounded(const std::string& csv, int precision) {
  std::string out;
  out.reserve(csv.size());
  std::size_t start = 0;
  while (start < csv.size()) {
    std::size_t end = csv.find_first_of(",\n", start);
    if (end == std::string::npos) end = csv.size();
    double v = 0;
    const auto r = std::from_chars(csv.data() + start, csv.data() + end, v);
    if (end > start && r.ec == std::errc() && r.ptr == csv.data() + end)
      number_text::append_general(out, v, precision);
    else
      out.append(csv, start, end - start);
    if (end < csv.size()) out.push_back(csv[end]);
    start = end + 1;
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 200, rounds = 5;
  std::string plugin_dir = TRACKFLOW_BENCH_PLUGIN_DIR, old_dir;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--plugins")) plugin_dir = argv[i + 1];
    if (!std::strcmp(argv[i], "--old-plugins")) old_dir = argv[i + 1];
    if (!std::strcmp(argv[i], "--runs")) runs = std::max(1, std::atoi(argv[i + 1]));
    if (!std::strcmp(argv[i], "--rounds")) rounds = std::max(1, std::atoi(argv[i + 1]));
  }
  host::PluginRegistry reg, old_reg;
  reg.load_directories({plugin_dir});
  if (!old_dir.empty()) old_reg.load_directories({old_dir});
  const std::vector<Step> steps = make_run();
  const auto tmp = std::filesystem::temp_directory_path() / ("trackflow-bench-csv-" + std::to_string(::getpid()));
  const std::string new_dir = (tmp / "new").string(), old_out = (tmp / "old").string();

  std::printf("sink.csv, %d runs x %zu rows (estimate + truth of a 9-state filter) per round, best of %d rounds, 1 thread\n",
              runs, steps.size(), rounds);
  std::printf("%-44s %14s %14s %12s\n", "", "rows/CPU-s", "rows/wall-s", "us/row (CPU)");
  int status = 0;
  for (const char* params : {"{ path: log.csv }", "{ path: log.csv, precision: 10 }", "{ path: log.csv, full_covariance: true }"}) {
    Rate now, before;
    for (int round = 0; round < rounds; ++round) {
      double rows = 0;
      now.add(rows, time_it([&] { rows = write_file(reg, params, steps, runs, new_dir); }));
      if (!old_dir.empty()) before.add(rows, time_it([&] { rows = write_file(old_reg, params, steps, runs, old_out); }));
    }
    const char* layout = std::strstr(params, "full_covariance") ? "full_covariance (42 numbers a row)"
                         : std::strstr(params, "precision")     ? "precision: 10 (21 numbers a row)"
                                                                : "default columns (21 numbers a row)";
    std::printf("%-44s %14.0f %14.0f %12.3f\n", (std::string("this build, ") + layout).c_str(), now.cpu, now.wall,
                1e6 / now.cpu);
    if (!old_dir.empty()) {
      std::printf("%-44s %14.0f %14.0f %12.3f\n", "  --old-plugins build", before.cpu, before.wall, 1e6 / before.cpu);
      const std::string mine = file_text(new_dir + "/log.csv"), theirs = file_text(old_out + "/log.csv");
      const bool same = mine == theirs;
      const bool same_rounded = same || rounded(mine, 10) == theirs;
      std::printf("  speed-up %.2fx (CPU); files %s (%zu and %zu bytes)\n", now.cpu / before.cpu,
                  same           ? "byte-identical"
                  : same_rounded ? "differ, equal with this build's numbers rounded to %.10g"
                                 : "DIFFER",
                  mine.size(), theirs.size());
      if (!same_rounded) status = 1;
    }
  }
  std::error_code ec;
  std::filesystem::remove_all(tmp, ec);
  return status;
}
