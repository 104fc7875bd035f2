// Purpose: unit-test fixture installed with the SDK: load plugins through the real loader, create components from YAML params, attach adapters as the engine does, capture outputs.
#pragma once

#include <trackflow/component.hpp>
#include <trackflow/error.hpp>
#include <trackflow/estimator.hpp>
#include <trackflow/params.hpp>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace trackflow::testing {

// The plugins of the given files or folders (tfplugin_*.so), loaded by the same code as
// `trackflow run`; a problem loading any of them throws, naming the file and the stage.
// Implemented in the host library (link trackflow::host): this header needs only the SDK.
class PluginFixture {
 public:
  explicit PluginFixture(const std::vector<std::string>& files_or_dirs);
  ~PluginFixture();
  PluginFixture(const PluginFixture&) = delete;
  PluginFixture& operator=(const PluginFixture&) = delete;

  // Parameters written as YAML ("{ q: 1 m2/s3 }"), validated exactly as in a pipeline.
  Params params_for(const std::string& type, const std::string& yaml_params = "{}",
                    const std::string& node_id = "node") const;

  // A component of `type` created by its plugin from those parameters; a filter's own annotations
  // get their slots as in the engine.
  std::shared_ptr<Component> make(const std::string& type, const std::string& yaml_params = "{}",
                                  const std::string& node_id = "node") const;

  // The per-track estimator of a filter type (ComponentDecl::create_estimator) from those
  // parameters, as a tracker gets it.
  std::shared_ptr<Estimator> make_estimator(const std::string& type, const std::string& yaml_params = "{}",
                                            const std::string& node_id = "node") const;

  // The loaded registry, for in-tree tests of the host (its definition is a host header, not installed).
  struct State;
  const State& state() const { return *state_; }

 private:
  std::unique_ptr<State> state_;
};

// Attaches `adapter` to `filter` the way the engine does: the typed contract is checked (the
// reason is thrown, as validate would report it), then the filter's configured noise is saved.
void attach(Adapter& adapter, Filter& filter);

// What the engine does once a filter is built (attach does it too): its process noise, as
// configured, is saved to be put back at the start of every run.
void save_configured_noise(Filter& filter);

// What the engine does at the start of a run: adapted noise restored, then start_run.
void start_run(Component& c, std::uint64_t run = 0, std::uint64_t seed = 1, Diagnostics* diag = nullptr);

// Records what a component emits.
class Collector : public Component {
 public:
  void on_truth(const Truth& t, int) override { truths.push_back(t); }
  void on_measurement(const Measurement& m, int) override { measurements.push_back(m); }
  void on_estimate(const Estimate& e, int) override { estimates.push_back(e); }
  // Wires `c`'s output into this collector.
  void attach_to(Component& c) {
    link_ = {this, 0, 0xFF};
    c.out.connect(&link_, 1);
  }
  std::vector<Truth> truths;
  std::vector<Measurement> measurements;
  std::vector<Estimate> estimates;

 private:
  Link link_;
};

// Runs a generator (a source) to exhaustion for one run with the given seed.
inline void drain(Component& generator, std::uint64_t seed = 1, std::uint64_t run = 0, Diagnostics* diag = nullptr) {
  Diagnostics local;
  generator.start_run({run, seed, diag ? diag : &local});
  auto& g = dynamic_cast<Generator&>(generator);
  while (std::isfinite(g.next_time())) g.emit_next();
}

}  // namespace trackflow::testing
