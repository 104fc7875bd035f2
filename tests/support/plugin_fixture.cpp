// Purpose: binds the SDK's test fixture to this build's plugin folder (see plugin_fixture.hpp).
#include "plugin_fixture.hpp"

namespace trackflow::test {

const testing::PluginFixture& fixture() {
  static const testing::PluginFixture f({TRACKFLOW_TEST_PLUGIN_DIR});
  return f;
}

}  // namespace trackflow::test
