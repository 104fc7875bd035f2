// Purpose: what the benchmarks share: per-thread CPU time next to wall time, alternating best-of-rounds timing, a consumer that reads every published estimate, plugin creation from YAML text.
#pragma once

#include <trackflow/component.hpp>
#include <trackflow/host/config.hpp>
#include <trackflow/host/plugins.hpp>
#include <trackflow/host/validate.hpp>

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

namespace trackflow::bench {

// The two clocks of one timed section. CPU time is the process's (CLOCK_PROCESS_CPUTIME_ID; the
// engine's single worker thread included, the main thread only waits for it): on a machine
// shared with other jobs it counts only the time the benchmark ran on a core, so it measures one
// core's throughput; wall time also counts waiting for the core. Both are printed.
struct Clocks {
  double cpu = 0.0, wall = 0.0;
};

inline double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

template <class F>
Clocks time_it(F&& f) {
  const double c0 = cpu_seconds();
  const auto w0 = std::chrono::steady_clock::now();
  f();
  Clocks c;
  c.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  c.cpu = cpu_seconds() - c0;
  return c;
}

// Best (highest) rate of each clock over rounds: the least disturbed round.
struct Rate {
  double cpu = 0.0, wall = 0.0;  // items per second
  void add(double items, const Clocks& c) {
    if (c.cpu > 0.0) cpu = std::max(cpu, items / c.cpu);
    if (c.wall > 0.0) wall = std::max(wall, items / c.wall);
  }
};

// Reads what a sink reads from every estimate (state, ENU block and its covariance), so a filter
// always forms its whole Estimate; keeps a checksum so nothing is optimised away.
struct Consumer final : Component {
  double sum = 0.0;
  void on_estimate(const Estimate& e, int) override {
    if (e.initialised) sum += e.state(0) + e.enu(3) + e.enu_covariance(0, 0) + e.covariance(0, 0);
  }
};

inline std::shared_ptr<Component> make(const host::PluginRegistry& reg, const std::string& type,
                                       const std::string& yaml, bool required = true) {
  const auto* t = reg.find(type);
  if (!t) {
    if (!required) return nullptr;
    std::fprintf(stderr, "plugin type %s not found\n", type.c_str());
    std::exit(2);
  }
  host::Value v = host::load_yaml_string(yaml, "bench");
  host::ComponentTypes types;  // what component-valued parameters (a tracker's estimator, ...) may name
  for (const auto& rt : reg.types()) types.push_back(&rt.decl);
  return reg.create(*t, host::validate_params(t->decl.params, v, type, v.loc, types));
}

}  // namespace trackflow::bench
