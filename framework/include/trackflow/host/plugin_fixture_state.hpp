// Purpose: what the SDK's test fixture holds (the plugin registry), for in-tree tests that inspect the host's view of the loaded plugins.
#pragma once

#include <trackflow/host/plugins.hpp>
#include <trackflow/testing/plugin_fixture.hpp>

namespace trackflow::testing {

struct PluginFixture::State {
  host::PluginRegistry registry;
};

}  // namespace trackflow::testing
