// Purpose: benchmark: tracker.multi (assoc.gnn + init.m_of_n + delete.misses, a CV filter.kalman per track; filter.ekf on spherical plots) scans per second on Stone Soup's k-d-tree tutorial scenario, a 1000-target case in Cartesian and in spherical scans, heap allocations per scan, and sink.gospa steps per second.
//
// Usage: trackflow-bench-tracker [--runs N] [--rounds R] [--plugins DIR] [--case kdtree|adapted|jpda|jpda_lbp|tomht|scale|spherical|gospa|all]
//                                [--targets N]
// Single thread, CPU time of the process (and wall time). The scans of every run are made first by
// sim.scenario (not timed) and stored; each round then feeds them to a fresh tracker.multi, run by
// run, and counts scans per second. The tracker's published track sets go to a consumer that reads
// every track's position, as a sink would.
//
// Allocation: this executable replaces the global operator new with a counting one. From the second
// run on (the tracker keeps its storage across runs, as each engine worker keeps its nodes), after
// the run's first `warm-up` scans (the population grows to its peak: the initial targets are
// confirmed in the first scans, then only die off), every allocation during on_scan is counted
// (the claim: none).
//
// Cases (issue 21):
//   kdtree  Stone Soup's k-d-tree tutorial scenario: 100 initial targets, Poisson births 0.3 and death
//           probability 0.05 per step, 50 clutter detections per scan over 1 km x 1 km, P_D 0.9,
//           R = 0.25 I m2, scans every 5 s, 30 scans a run (about 55 targets alive on average, ~100
//           detections per scan; docs/performance.md gives the peer's figures on this machine).
//   adapted the kdtree case with adapt.innovation_r on every track (tracker.multi `adapters:`).
//   jpda    the kdtree case under assoc.jpda (exact per cluster up to 10 000 joint events, else loopy
//           belief propagation) with score deletion (a JPDA track rarely misses: some clutter is in its gate).
//   jpda_lbp  the same with belief propagation on every cluster (max_events: 1), as Stone Soup's JPDAwithLBP.
//   tomht   the kdtree case under tracker.tomht (pipelines/kdtree_mht.yaml: N = 3, <= 100 hypotheses).
//   scale   1000 targets that live throughout and 1000 clutter detections per scan over 3 km x 3 km.
//   spherical  the scale case's targets seen by sim.scan_radar at the centre of the region (30 m below
//           it): [range, azimuth, elevation] plots, sigmas 0.5 m and 0.3 mrad, P_D 0.9, 1000 clutter
//           plots per scan over 0-2.2 km, all azimuths, -2 to 80 deg; a CV filter.ekf per track. The
//           targets surround the radar, so gates cross the azimuth seam and the nearest ones have
//           azimuth gates wider than the circle (the spherical pre-gate's edge cases). --targets N: N
//           targets and N clutter plots at the same densities (region and reach scaled by sqrt(N/1000)).
//   gospa   sink.gospa over 50 000 steps with 50 truths and 50 tracks each (a track 0.5 m off each
//           truth, 10 % of them 100 m off: missed + false).
#include "bench_common.hpp"

#include <trackflow/scan.hpp>
#include <trackflow/tracks.hpp>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <new>
#include <vector>

// ---- counting allocator ----------------------------------------------------------------------
namespace {
std::atomic<bool> g_counting{false};
std::atomic<std::uint64_t> g_allocations{0};
}  // namespace

void* operator new(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void* operator new(std::size_t n, std::align_val_t a) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  const std::size_t al = static_cast<std::size_t>(a);
  if (void* p = std::aligned_alloc(al, (n + al - 1) / al * al)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n, std::align_val_t a) { return operator new(n, a); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

using namespace trackflow;
using namespace trackflow::bench;

namespace {

// One scan, owning its detections (a Scan views its emitter's storage only during delivery).
struct StoredScan {
  Scan scan;
  std::vector<Detection> detections;
};

struct Recorder final : Component {
  std::vector<StoredScan>* scans = nullptr;
  std::vector<Truth>* truths = nullptr;
  void on_scan(const Scan& s, int) override {
    scans->push_back({s, {s.detections.begin(), s.detections.end()}});
  }
  void on_truth(const Truth& t, int) override {
    if (truths) truths->push_back(t);
  }
};

// Reads every published track's position, as a metrics sink would.
struct TrackConsumer final : Component {
  double sum = 0.0;
  std::uint64_t confirmed = 0, sets = 0;
  void on_tracks(const TrackSet& set, int) override {
    ++sets;
    for (const TrackEstimate& t : set.tracks) {
      sum += t.estimate.enu(0) + t.estimate.enu(1);
      confirmed += t.status == TrackStatus::Confirmed ? 1 : 0;
    }
  }
};

// `radar_yaml` empty: sim.scenario's own (Cartesian) scans; else its truths go through a
// sim.scan_radar of these parameters and its scans are the ones stored.
std::vector<std::vector<StoredScan>> make_scans(const host::PluginRegistry& reg, const std::string& scenario_yaml,
                                                const std::string& radar_yaml, int runs, double* mean_detections,
                                                double* mean_alive) {
  std::vector<std::vector<StoredScan>> all(static_cast<std::size_t>(runs));
  auto gen_c = make(reg, "sim.scenario", scenario_yaml);
  auto* gen = dynamic_cast<Generator*>(gen_c.get());
  std::shared_ptr<Component> radar = radar_yaml.empty() ? nullptr : make(reg, "sim.scan_radar", radar_yaml);
  Recorder rec;
  std::vector<Truth> truths;
  rec.truths = &truths;
  // Outputs keep a pointer to their links: these live as long as the runs.
  const Link direct[1] = {{&rec, 0, 0xFF}};
  const Link via_radar[2] = {{radar.get(), 0, mask(ItemKind::Truth)}, {&rec, 0, mask(ItemKind::Truth)}};
  const Link radar_links[1] = {{&rec, 0, mask(ItemKind::Scan)}};
  if (radar) {
    gen->out.connect(via_radar, 2);
    radar->out.connect(radar_links, 1);
  } else {
    gen->out.connect(direct, 1);
  }
  double detections = 0, scans = 0;
  for (int r = 0; r < runs; ++r) {
    rec.scans = &all[static_cast<std::size_t>(r)];
    RunContext ctx;
    ctx.run = static_cast<std::uint64_t>(r);
    ctx.seed = 0x9e3779b97f4a7c15ull * static_cast<std::uint64_t>(r + 1);
    gen->start_run(ctx);
    if (radar) {
      RunContext radar_ctx = ctx;
      radar_ctx.seed ^= 0x5851f42d4c957f2dull;  // its own random stream
      radar->start_run(radar_ctx);
    }
    while (std::isfinite(gen->next_time())) {
      const double t = gen->next_time();
      gen->emit_next();
      // The instant is complete when the source's next item is later (what the engine does).
      if (radar && gen->next_time() != t) radar->on_time_complete(t);
    }
    gen->end_run();
    if (radar) radar->end_run();
    for (const StoredScan& s : all[static_cast<std::size_t>(r)]) {
      detections += static_cast<double>(s.detections.size());
      scans += 1;
    }
  }
  // Point each stored scan's span at its own storage.
  for (auto& run : all)
    for (StoredScan& s : run) s.scan.detections = std::span<const Detection>(s.detections);
  *mean_detections = detections / scans;
  *mean_alive = static_cast<double>(truths.size()) / scans;
  return all;
}

struct TrackerResult {
  Rate rate;
  std::uint64_t steady_allocations = 0, steady_scans = 0, late_allocations = 0, late_scans = 0;
  double confirmed_per_scan = 0.0;
};

TrackerResult bench_tracker(const host::PluginRegistry& reg, const std::string& tracker_yaml,
                            const std::vector<std::vector<StoredScan>>& runs, int rounds, int warm_up,
                            const char* tracker_type = "tracker.multi") {
  TrackerResult res;
  double scans = 0;
  for (const auto& r : runs) scans += static_cast<double>(r.size());
  for (int round = 0; round < rounds; ++round) {
    auto tracker = make(reg, tracker_type, tracker_yaml);
    TrackConsumer consumer;
    const Link links[1] = {{&consumer, 0, 0xFF}};
    tracker->out.connect(links, 1);
    Diagnostics diag;
    std::uint64_t steady_allocations = 0, steady_scans = 0, late_allocations = 0, late_scans = 0;
    const Clocks c = time_it([&] {
      for (std::size_t r = 0; r < runs.size(); ++r) {
        RunContext ctx;
        ctx.run = r;
        ctx.diagnostics = &diag;
        tracker->start_run(ctx);
        int k = 0;
        for (const StoredScan& s : runs[r]) {
          // Steady: past the run's first scans, and not in the first run (the engine's workers
          // keep their nodes across runs, as this loop keeps its tracker).
          const bool steady = r > 0 && k >= warm_up;
          ++k;
          const std::uint64_t before = g_allocations.load(std::memory_order_relaxed);
          g_counting.store(steady, std::memory_order_relaxed);
          tracker->on_scan(s.scan, 0);
          g_counting.store(false, std::memory_order_relaxed);
          if (steady) {
            const std::uint64_t a = g_allocations.load(std::memory_order_relaxed) - before;
            steady_allocations += a;
            ++steady_scans;
            if (2 * r >= runs.size()) {
              late_allocations += a;
              ++late_scans;
            }
          }
        }
        tracker->end_run();
      }
    });
    res.rate.add(scans, c);
    res.steady_allocations = steady_allocations;
    res.steady_scans = steady_scans;
    res.late_allocations = late_allocations;
    res.late_scans = late_scans;
    res.confirmed_per_scan = static_cast<double>(consumer.confirmed) / scans;
  }
  return res;
}

const char* kTracker =
    "{ estimator: { type: filter.kalman, motion: constant_velocity, q: 0.005 m2/s3 },"
    "  associator: { type: assoc.gnn, gate_probability: 0.99 },"
    "  initiator: { type: init.m_of_n, m: 3, n: 4, max_speed: 10 m/s },"
    "  deleter: { type: delete.misses, max_misses: 3 } }";

// The same tracker on spherical plots: the EKF linearises the [range, azimuth, elevation] measurement.
const char* kSphericalTracker =
    "{ estimator: { type: filter.ekf, motion: constant_velocity, q: 0.005 m2/s3 },"
    "  associator: { type: assoc.gnn, gate_probability: 0.99 },"
    "  initiator: { type: init.m_of_n, m: 3, n: 4, max_speed: 10 m/s },"
    "  deleter: { type: delete.misses, max_misses: 3 } }";

// The same tracker with adapt.innovation_r on every track (tracker.multi `adapters:`): each track
// slot keeps its own adapter instance, so the claim of no allocation per scan holds with it too.
const char* kAdaptedTracker =
    "{ estimator: { type: filter.kalman, motion: constant_velocity, q: 0.005 m2/s3 },"
    "  adapters: [ { type: adapt.innovation_r, window: 20, warmup: 5 } ],"
    "  associator: { type: assoc.gnn, gate_probability: 0.99 },"
    "  initiator: { type: init.m_of_n, m: 3, n: 4, max_speed: 10 m/s },"
    "  deleter: { type: delete.misses, max_misses: 3 } }";

// The kdtree tracker under JPDA (assoc.jpda: each cluster exact up to max_events joint events, loopy
// belief propagation above) and the combined update per track (issue 22). `lbp` forces belief
// propagation on every cluster (max_events: 1): the case of Stone Soup's JPDAwithLBP.
const char* kJpdaTracker =
    "{ estimator: { type: filter.kalman, motion: constant_velocity, q: 0.005 m2/s3 },"
    "  associator: { type: assoc.jpda, gate_probability: 0.99 },"
    "  initiator: { type: init.m_of_n, m: 3, n: 4, max_speed: 10 m/s },"
    "  deleter: { type: delete.score, score_drop: 6.5, max_position_sd: 10 m } }";
const char* kJpdaLbpTracker =
    "{ estimator: { type: filter.kalman, motion: constant_velocity, q: 0.005 m2/s3 },"
    "  associator: { type: assoc.jpda, gate_probability: 0.99, max_events: 1 },"
    "  initiator: { type: init.m_of_n, m: 3, n: 4, max_speed: 10 m/s },"
    "  deleter: { type: delete.score, score_drop: 6.5, max_position_sd: 10 m } }";

// The track-oriented MHT of pipelines/kdtree_mht.yaml (tracker.tomht, N = 3, at most 100 global
// hypotheses; issue 22).
const char* kMhtTracker =
    "{ estimator: { type: filter.kalman, motion: constant_velocity, q: 0.005 m2/s3 },"
    "  gate_probability: 0.99, max_speed: 4 m/s, n_scan: 3, max_hypotheses: 100,"
    "  false_track_probability: 1e-3, start_score: 2 }";

void run_tracker_case(const host::PluginRegistry& reg, const char* name, const std::string& scenario, int runs,
                      int rounds, int warm_up, const char* tracker = kTracker, const std::string& radar = "",
                      const char* tracker_type = "tracker.multi") {
  double dets = 0, alive = 0;
  const auto scans = make_scans(reg, scenario, radar, runs, &dets, &alive);
  const TrackerResult r = bench_tracker(reg, tracker, scans, rounds, warm_up, tracker_type);
  std::printf("%-8s %4d runs x %3zu scans, %6.1f targets alive, %7.1f detections/scan, %6.1f confirmed tracks/scan\n", name,
              runs, scans.front().size(), alive, dets, r.confirmed_per_scan);
  std::printf("         %12.0f scans/CPU-s %12.0f scans/wall-s %10.1f us/scan (CPU)\n", r.rate.cpu, r.rate.wall,
              1e6 / r.rate.cpu);
  std::printf("         heap allocations in on_scan, runs 2-%d from scan %d on: %llu in %llu scans\n", runs, warm_up + 1,
              static_cast<unsigned long long>(r.steady_allocations), static_cast<unsigned long long>(r.steady_scans));
  std::printf("         (growth of storage to a new largest scan; in the second half of the runs: %llu in %llu scans)\n",
              static_cast<unsigned long long>(r.late_allocations), static_cast<unsigned long long>(r.late_scans));
}

void run_gospa_case(const host::PluginRegistry& reg, int rounds) {
  const int steps = 50000, n = 50;
  std::vector<Truth> truths(static_cast<std::size_t>(n));
  std::vector<TrackEstimate> tracks(static_cast<std::size_t>(n));
  const std::vector<InputInfo> inputs = {{"tracker", "tracker.multi", mask(ItemKind::Tracks), {}},
                                         {"scenario", "sim.scenario", mask(ItemKind::Truth), {}}};
  Rate rate;
  double checksum = 0;
  for (int round = 0; round < rounds; ++round) {
    auto sink = make(reg, "sink.gospa", "{ cutoff: 10 m }");
    sink->set_inputs(inputs);
    const Clocks c = time_it([&] {
      RunContext ctx;
      sink->start_run(ctx);
      for (int k = 0; k < steps; ++k) {
        const double t = k;
        for (int i = 0; i < n; ++i) {
          Truth& tr = truths[static_cast<std::size_t>(i)];
          tr.time = t;
          tr.target = static_cast<std::uint32_t>(i);
          tr.position = Vec3(37.0 * i + 0.01 * k, 11.0 * (i % 7), 0.0);
          TrackEstimate& te = tracks[static_cast<std::size_t>(i)];
          te.id = static_cast<std::uint64_t>(i + 1);
          te.status = TrackStatus::Confirmed;
          te.estimate.initialised = true;
          te.estimate.enu.setZero();
          const double off = (i + k) % 10 == 0 ? 100.0 : 0.5;
          te.estimate.enu.head<3>() = tr.position + Vec3(off, 0.0, 0.0);
          sink->on_truth(tr, 1);
        }
        sink->on_tracks(TrackSet{t, tracks}, 0);
      }
      auto r = sink->end_run();
      sink->merge(*r);
      Summary s;
      sink->finish(s, {});
      if (const Metric* m = s.find("gospa")) checksum += m->value;
    });
    rate.add(steps, c);
  }
  std::printf("gospa    %d steps, %d truths and %d tracks each (GOSPA checksum %.6f)\n", steps, n, n, checksum / rounds);
  std::printf("         %12.0f steps/CPU-s %12.0f steps/wall-s %10.3f s for 50 000 steps (CPU)\n", rate.cpu, rate.wall,
              steps / rate.cpu);
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 100, rounds = 3, spherical_targets = 1000;
  std::string plugin_dir = TRACKFLOW_BENCH_PLUGIN_DIR, which = "all";
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--plugins")) plugin_dir = argv[i + 1];
    else if (!std::strcmp(argv[i], "--runs")) runs = std::max(1, std::atoi(argv[i + 1]));
    else if (!std::strcmp(argv[i], "--rounds")) rounds = std::max(1, std::atoi(argv[i + 1]));
    else if (!std::strcmp(argv[i], "--case")) which = argv[i + 1];
    else if (!std::strcmp(argv[i], "--targets")) spherical_targets = std::max(1, std::atoi(argv[i + 1]));
    else {
      std::fprintf(stderr, "unknown option %s; usage: trackflow-bench-tracker [--runs N] [--rounds R] [--plugins DIR] "
                   "[--case kdtree|adapted|jpda|jpda_lbp|tomht|scale|spherical|gospa|all] [--targets N (spherical)]\n", argv[i]);
      return 2;
    }
  }
  host::PluginRegistry reg;
  reg.load_directories({plugin_dir});
  std::printf("tracker.multi (filter.kalman CV, spherical: filter.ekf CV + assoc.gnn + init.m_of_n + delete.misses), 1 thread, "
              "best of %d rounds\n",
              rounds);
  const char* kdtree_scenario =
      "{ period: 5 s, duration: 145 s, planar: true, region_lo: [-500 m, -500 m], region_hi: [500 m, 500 m],"
      "  initial_targets: 100, birth_rate: 0.3, survival_probability: 0.95,"
      "  birth_velocity_sigma: [1 m/s, 1 m/s, 0 m/s], process_noise_q: 0.005 m2/s3,"
      "  detection_probability: 0.9, measurement_sigma: 0.5 m, clutter_rate: 50 }";
  if (which == "all" || which == "kdtree") run_tracker_case(reg, "kdtree", kdtree_scenario, runs, rounds, 4);
  // The kdtree case with per-track adapt.innovation_r (tracker.multi `adapters:`).
  if (which == "all" || which == "adapted")
    run_tracker_case(reg, "adapted", kdtree_scenario, runs, rounds, 4, kAdaptedTracker);
  if (which == "all" || which == "jpda") run_tracker_case(reg, "jpda", kdtree_scenario, runs, rounds, 4, kJpdaTracker);
  if (which == "all" || which == "jpda_lbp")
    run_tracker_case(reg, "jpda_lbp", kdtree_scenario, runs, rounds, 4, kJpdaLbpTracker);
  if (which == "all" || which == "tomht")
    run_tracker_case(reg, "tomht", kdtree_scenario, runs, rounds, 4, kMhtTracker, "", "tracker.tomht");
  if (which == "all" || which == "scale")
    run_tracker_case(reg, "scale",
                     "{ period: 5 s, duration: 145 s, planar: true, region_lo: [-1500 m, -1500 m], region_hi: [1500 m, 1500 m],"
                     "  initial_targets: 1000, birth_velocity_sigma: [1 m/s, 1 m/s, 0 m/s], process_noise_q: 0.005 m2/s3,"
                     "  detection_probability: 0.9, measurement_sigma: 0.5 m, clutter_rate: 1000 }",
                     std::max(2, runs / 10), rounds, 6);
  if (which == "all" || which == "spherical") {
    // --targets N: N targets and N clutter plots, the region's side and the radar's reach scaled by
    // sqrt(N / 1000) so that the densities stay those of 1000 (how the cost grows with the scene).
    const double k = std::sqrt(spherical_targets / 1000.0);
    char scenario[512], radar[512];
    std::snprintf(scenario, sizeof scenario,
                  "{ period: 5 s, duration: 145 s, planar: true, region_lo: [-%.9g m, -%.9g m], region_hi: [%.9g m, %.9g m],"
                  "  initial_targets: %d, birth_velocity_sigma: [1 m/s, 1 m/s, 0 m/s], process_noise_q: 0.005 m2/s3,"
                  "  detection_probability: 1, measurement_sigma: 0.5 m }",
                  1500 * k, 1500 * k, 1500 * k, 1500 * k, spherical_targets);
    std::snprintf(radar, sizeof radar,
                  "{ position: [0 m, 0 m, -30 m], sigma_range: 0.5 m, sigma_azimuth: 0.3 mrad, sigma_elevation: 0.3 mrad,"
                  "  detection_probability: 0.9, range_max: %.9g m, elevation_min: -2 deg, elevation_max: 80 deg,"
                  "  clutter_rate: %d }",
                  2200 * k, spherical_targets);
    run_tracker_case(reg, "spherical", scenario, std::max(2, runs / 10), rounds, 6, kSphericalTracker, radar);
  }
  if (which == "all" || which == "gospa") run_gospa_case(reg, rounds);
  return 0;
}
