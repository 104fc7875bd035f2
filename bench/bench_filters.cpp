// Purpose: benchmark: per-step cost of the spherical-measurement filters (filter.ekf, filter.ukf, filter.ekf_spherical, filter.imm with three 9-state EKF modes) on one pre-generated launch track.
//
// Usage: trackflow-bench-filters [--reps N] [--rounds R] [--plugins DIR]. Single thread. sim.trajectory (KSLV-I
// profile, 40 Hz, 540 s) and sim.radar (Table-4 noise with range rate, radar 100 km from the pad)
// generate one measurement sequence; each filter then runs over it through its plugin (virtual
// call, Estimate formed and read by one consumer), N passes per round, the filters taking turns
// for R rounds; each keeps its best round, by CPU time (this process on its core) and by wall
// time. Prints steps/s, us/step, the cost relative to filter.ekf, and the position RMSE against
// the truth as a check that each filter is tracking. A filter type that is not built is reported
// and skipped.
#include "bench_common.hpp"

#include <trackflow/host/config.hpp>
#include <trackflow/host/filter_control.hpp>
#include <trackflow/host/plugins.hpp>
#include <trackflow/host/validate.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

using namespace trackflow;
using trackflow::bench::Consumer;
using trackflow::bench::Rate;
using trackflow::bench::time_it;

namespace {

struct Recorder : Component {
  std::vector<Truth> truths;
  std::vector<Measurement> measurements;
  std::vector<Estimate> estimates;
  void on_truth(const Truth& t, int) override { truths.push_back(t); }
  void on_measurement(const Measurement& m, int) override { measurements.push_back(m); }
  void on_estimate(const Estimate& e, int) override { estimates.push_back(e); }
};

std::shared_ptr<Component> make(const host::PluginRegistry& reg, const std::string& type, const std::string& yaml) {
  const auto* t = reg.find(type);
  if (!t) return nullptr;
  host::Value v = host::load_yaml_string(yaml, "bench");
  return reg.create(*t, host::validate_params(t->decl.params, v, type, v.loc));
}

bool declares(const host::PluginRegistry& reg, const std::string& type, const std::string& param) {
  for (const auto& p : reg.find(type)->decl.params)
    if (p.name == param) return true;
  return false;
}

struct Track {
  std::vector<Truth> truth;
  std::vector<Measurement> measurements;
};

Track launch_track(const host::PluginRegistry& reg) {
  auto traj = make(reg, "sim.trajectory",
                   "{ profile: kslv1, rate: 40 Hz, pad_position: [-60 km, -80 km, 0 m], launch_azimuth: 170 deg }");
  auto radar = make(reg, "sim.radar", "{ noise_model: table4, range_rate: true, sigma_range_rate: 0.1 m/s }");
  if (!traj || !radar) {
    std::fprintf(stderr, "sim.trajectory and sim.radar must be built\n");
    std::exit(1);
  }
  Recorder rec;
  const Link to_radar[2] = {{radar.get(), 0, mask(ItemKind::Truth)}, {&rec, 0, mask(ItemKind::Truth)}};
  const Link to_rec[1] = {{&rec, 0, mask(ItemKind::Measurement)}};
  traj->out.connect(to_radar, 2);
  radar->out.connect(to_rec, 1);
  radar->set_inputs({{"truth", "sim.trajectory", mask(ItemKind::Truth)}});
  Diagnostics d;
  traj->start_run({0, 11, &d});
  radar->start_run({0, 12, &d});
  auto& gen = dynamic_cast<Generator&>(*traj);
  while (std::isfinite(gen.next_time())) gen.emit_next();
  return {std::move(rec.truths), std::move(rec.measurements)};
}

struct Row {
  std::string type;
  std::shared_ptr<Component> filter;  // null: not built
  Rate rate;
  double position_rmse = 0;
  std::shared_ptr<Consumer> consumer = std::make_shared<Consumer>();
  Link link{};
};

Row prepare(const host::PluginRegistry& reg, const std::string& type, const std::string& params, const Track& track) {
  Row row{type, make(reg, type, params)};
  if (!row.filter) return row;
  // A filter's own annotations (filter.imm's mode probabilities) get their slots as in the engine.
  if (auto* f = dynamic_cast<Filter*>(row.filter.get())) host::FilterControl::reserve_own_annotations(*f, static_cast<int>(f->annotation_names().size()));
  // Accuracy pass with the outputs recorded; the timed passes have no consumer.
  Recorder rec;
  const Link link{&rec, 0, mask(ItemKind::Estimate)};
  Diagnostics d;
  row.filter->out.connect(&link, 1);
  row.filter->start_run({0, 1, &d});
  for (const auto& m : track.measurements) row.filter->on_measurement(m, 0);
  row.link = {row.consumer.get(), 0, 0xFF};
  row.filter->out.connect(&row.link, 1);
  double sq = 0;
  int n = 0;
  for (size_t i = 0; i < rec.estimates.size() && i < track.truth.size(); ++i)
    if (rec.estimates[i].initialised) {
      sq += (rec.estimates[i].enu.head<3>() - track.truth[i].position).squaredNorm();
      ++n;
    }
  row.position_rmse = n ? std::sqrt(sq / n) : std::numeric_limits<double>::quiet_NaN();
  return row;
}

void passes(Component& f, const Track& track, int reps) {
  Diagnostics d;
  for (int rep = 0; rep < reps; ++rep) {
    f.start_run({static_cast<std::uint64_t>(rep), 1, &d});
    for (const auto& m : track.measurements) f.on_measurement(m, 0);
  }
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 5, rounds = 7;
  std::string plugin_dir = TRACKFLOW_BENCH_PLUGIN_DIR;  // --plugins: another build's, for before/after
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--plugins")) plugin_dir = argv[i + 1];
    if (!std::strcmp(argv[i], "--reps")) reps = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--rounds")) rounds = std::atoi(argv[i + 1]);
  }
  host::PluginRegistry reg;
  reg.load_directories({plugin_dir});
  const Track track = launch_track(reg);
  if (track.measurements.size() != track.truth.size()) {
    std::fprintf(stderr, "expected one measurement per truth sample\n");
    return 1;
  }

  const std::string cartesian = "{ motion: constant_acceleration, q_jerk: 1 m2/s5, range_rate: use }";
  std::string spherical = "{ range_rate: use";
  if (reg.find("filter.ekf_spherical"))
    for (const char* q : {"q_r", "q_h", "q_v"})
      if (declares(reg, "filter.ekf_spherical", q)) spherical += std::string(", ") + q + ": 1 m2/s5";
  spherical += " }";
  std::vector<Row> rows;
  rows.push_back(prepare(reg, "filter.ekf", cartesian, track));
  rows.push_back(prepare(reg, "filter.ukf", cartesian, track));
  rows.push_back(prepare(reg, "filter.ekf_spherical", spherical, track));
  // Issue 14: an IMM of three 9-state EKF modes, at most 4x one filter.ekf step.
  const std::string imm =
      "{ range_rate: use, modes: [{ name: ca_low, motion: constant_acceleration, q_jerk: 1 m2/s5 }, { name: ca_high, "
      "motion: constant_acceleration, q_jerk: 100 m2/s5 }, { motion: singer, singer_alpha: 0.5 1/s, singer_sigma: 10 "
      "m/s2 }], transition: [0.98, 0.01, 0.01, 0.01, 0.98, 0.01, 0.01, 0.01, 0.98] }";
  rows.push_back(prepare(reg, "filter.imm", imm, track));
  // The filters take turns over several rounds and each keeps its best round, so a busy
  // machine (other processes on the core) affects them alike and the ratios stay meaningful.
  const double steps = static_cast<double>(reps) * track.measurements.size();
  for (int round = 0; round < rounds; ++round)
    for (auto& r : rows)
      if (r.filter) r.rate.add(steps, time_it([&] { passes(*r.filter, track, reps); }));

  std::printf("KSLV-I launch track, 40 Hz, %zu measurements [r, az, el, rdot]; best of %d rounds of %d passes, "
              "1 thread\n",
              track.measurements.size(), rounds, reps);
  std::printf("%-22s %12s %8s %8s %12s %8s %8s %16s\n", "filter", "steps/CPU-s", "us", "cost/ekf", "steps/wall-s",
              "us", "cost/ekf", "position RMSE m");
  const Rate ekf = rows[0].rate;
  for (const auto& r : rows) {
    if (!r.filter) {
      std::printf("%-22s (not built)\n", r.type.c_str());
      continue;
    }
    std::printf("%-22s %12.0f %8.3f %8.2f %12.0f %8.3f %8.2f %16.2f\n", r.type.c_str(), r.rate.cpu, 1e6 / r.rate.cpu,
                ekf.cpu / r.rate.cpu, r.rate.wall, 1e6 / r.rate.wall, ekf.wall / r.rate.wall, r.position_rmse);
  }
  std::printf("(filter.ekf and filter.ukf: %s; filter.ekf_spherical: %s; filter.imm: %s)\n", cartesian.c_str(),
              spherical.c_str(), imm.c_str());
  return 0;
}
