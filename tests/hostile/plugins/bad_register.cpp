// Purpose: test-only plugin whose registration throws something that is not a std::exception.
#include <trackflow/plugin.hpp>

namespace {

void register_components(trackflow::Registrar&) { throw 42; }

}  // namespace

TRACKFLOW_PLUGIN("test.bad_register", register_components)
