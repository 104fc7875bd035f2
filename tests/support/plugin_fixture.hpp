// Purpose: test helpers: load the build's plugins, create a component from YAML params, capture its outputs.
#pragma once

#include <trackflow/host/config.hpp>
#include <trackflow/host/plugins.hpp>
#include <trackflow/host/validate.hpp>

#include <memory>
#include <string>
#include <vector>

namespace trackflow::test {

// The registry of every plugin built in this tree (loaded once per test process).
const host::PluginRegistry& registry();

// Creates `type` with parameters written as YAML, validated exactly as in a pipeline.
std::shared_ptr<Component> make(const std::string& type, const std::string& yaml_params = "{}",
                                 const std::string& node_id = "node");
Params params_for(const std::string& type, const std::string& yaml_params, const std::string& node_id = "node");

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

// Runs a generator to exhaustion for one run with the given seed.
void drain(Component& generator, std::uint64_t seed = 1, std::uint64_t run = 0, Diagnostics* diag = nullptr);

}  // namespace trackflow::test
