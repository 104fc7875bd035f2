// Purpose: test-only helpers the sim.trajectory tests share: run a configuration and collect its truths, and the ConfigError message a configuration raises.
#pragma once

#include "plugin_fixture.hpp"

#include <trackflow/error.hpp>
#include <trackflow/items.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace trackflow::test {

// The truths sim.trajectory configured by `yaml` publishes over one run (seed and run index as
// the engine would pass them).
inline std::vector<Truth> fly(const std::string& yaml, std::uint64_t seed = 1, std::uint64_t run = 0) {
  auto gen = make("sim.trajectory", yaml);
  Collector out;
  out.attach_to(*gen);
  drain(*gen, seed, run);
  return out.truths;
}

// The message of the ConfigError that building `yaml` throws ("" if none).
inline std::string config_error(const std::string& yaml) {
  try {
    (void)make("sim.trajectory", yaml);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return {};
}

}  // namespace trackflow::test
