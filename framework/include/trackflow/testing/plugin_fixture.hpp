// Purpose: unit-test fixture installed with the SDK: load plugins through the real loader, create components from YAML params, attach adapters as the engine does, capture outputs.
#pragma once

#include <trackflow/component.hpp>
#include <trackflow/host/config.hpp>
#include <trackflow/host/plugins.hpp>
#include <trackflow/host/validate.hpp>

#include <cmath>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace trackflow::testing {

// The plugins of the given files or folders (tfplugin_*.so), loaded by the same code as
// `trackflow run`; a problem loading any of them throws, naming the file and the stage.
class PluginFixture {
 public:
  explicit PluginFixture(const std::vector<std::string>& files_or_dirs) {
    std::vector<std::string> dirs;
    for (const auto& p : files_or_dirs) {
      if (std::filesystem::is_directory(p))
        dirs.push_back(p);
      else
        registry_.load_file(p);
    }
    if (!dirs.empty()) registry_.load_directories(dirs);
    if (!registry_.problems().empty()) throw std::runtime_error("plugin not loaded: " + registry_.problems()[0].str());
  }

  const host::PluginRegistry& registry() const { return registry_; }

  // Parameters written as YAML ("{ q: 1 m2/s3 }"), validated exactly as in a pipeline.
  Params params_for(const std::string& type, const std::string& yaml_params = "{}",
                    const std::string& node_id = "node") const {
    const host::RegisteredType* t = registry_.find(type);
    if (!t) throw std::runtime_error("no plugin declares type '" + type + "'");
    const host::Value v = host::load_yaml_string(yaml_params, "test params");
    return host::validate_params(t->decl.params, v, node_id, v.loc);
  }

  std::shared_ptr<Component> make(const std::string& type, const std::string& yaml_params = "{}",
                                  const std::string& node_id = "node") const {
    std::shared_ptr<Component> c = registry_.create(*registry_.find(type), params_for(type, yaml_params, node_id));
    // A filter's own annotations get their slots as in the engine (graph.cpp).
    if (auto* f = dynamic_cast<Filter*>(c.get()))
      if (!f->reserve_own_annotations(static_cast<int>(f->annotation_names().size())))
        throw std::runtime_error("too many annotations on a " + type);
    return c;
  }

 private:
  host::PluginRegistry registry_;
};

// Attaches `adapter` to `filter` the way the engine does: the typed contract is checked (the
// reason is thrown, as validate would report it), then the filter's configured noise is saved.
inline void attach(Adapter& adapter, Filter& filter) {
  const std::string why = noise_mismatch(adapter.needs(), filter.noise(), filter.has_covariance_access());
  if (!why.empty()) throw std::runtime_error("cannot attach: " + why);
  if (!filter.attach(&adapter, static_cast<int>(adapter.annotation_names().size())))
    throw std::runtime_error("cannot attach: too many adapters or annotations");
  filter.save_configured_noise();
}

// What the engine does at the start of a run: adapted noise restored, then start_run.
inline void start_run(Component& c, std::uint64_t run = 0, std::uint64_t seed = 1, Diagnostics* diag = nullptr) {
  if (auto* f = dynamic_cast<Filter*>(&c)) f->reset_adapted_state();
  c.start_run({run, seed, diag});
}

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
