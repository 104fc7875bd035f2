// Purpose: test helpers (see plugin_fixture.hpp).
#include "plugin_fixture.hpp"

#include <cmath>
#include <stdexcept>

namespace trackflow::test {

const host::PluginRegistry& registry() {
  static const host::PluginRegistry reg = [] {
    host::PluginRegistry r;
    r.load_directories({TRACKFLOW_TEST_PLUGIN_DIR});
    return r;
  }();
  return reg;
}

Params params_for(const std::string& type, const std::string& yaml_params, const std::string& node_id) {
  const auto* t = registry().find(type);
  if (!t) throw std::runtime_error("test: plugin type not built: " + type);
  host::Value v = host::load_yaml_string(yaml_params, "test params");
  return host::validate_params(t->decl.params, v, node_id, v.loc);
}

std::shared_ptr<Component> make(const std::string& type, const std::string& yaml_params, const std::string& node_id) {
  return registry().create(*registry().find(type), params_for(type, yaml_params, node_id));
}

void drain(Component& c, std::uint64_t seed, std::uint64_t run, Diagnostics* diag) {
  Diagnostics local;
  c.start_run({run, seed, diag ? diag : &local});
  auto& g = dynamic_cast<Generator&>(c);
  while (std::isfinite(g.next_time())) g.emit_next();
}

}  // namespace trackflow::test
