// Purpose: in-tree test helpers: the SDK's installed fixture (trackflow/testing/plugin_fixture.hpp) and its registry, bound to this build's plugin folder.
#pragma once

#include <trackflow/host/plugin_fixture_state.hpp>
#include <trackflow/testing/plugin_fixture.hpp>
#include <trackflow/tracker.hpp>

#include <memory>
#include <string>

namespace trackflow::test {

using testing::Collector;
using testing::drain;
using testing::attach;
using testing::save_configured_noise;
using testing::start_run;

// The fixture of every plugin built in this tree (loaded once per test process).
const testing::PluginFixture& fixture();
inline const host::PluginRegistry& registry() { return fixture().state().registry; }

// Creates `type` with parameters written as YAML, validated exactly as in a pipeline.
inline std::shared_ptr<Component> make(const std::string& type, const std::string& yaml_params = "{}",
                                       const std::string& node_id = "node") {
  return fixture().make(type, yaml_params, node_id);
}
inline Params params_for(const std::string& type, const std::string& yaml_params, const std::string& node_id = "node") {
  return fixture().params_for(type, yaml_params, node_id);
}

// A tracker part (an associator, initiator or deleter) of `type` made from YAML parameters, as a
// tracker makes the part it names; null when `type` makes a part of another kind.
template <class Part>
std::unique_ptr<Part> make_part(const std::string& type, const std::string& yaml_params) {
  const Params p = params_for(type, yaml_params);
  std::unique_ptr<TrackerPart> part = registry().find(type)->decl.create_part(p);
  return std::unique_ptr<Part>(dynamic_cast<Part*>(part.release()));
}

}  // namespace trackflow::test
