// Purpose: the SDK test fixture's implementation in the host: plugins loaded by the real loader, parameters validated as in a pipeline.
#include <trackflow/host/config.hpp>
#include <trackflow/host/filter_control.hpp>
#include <trackflow/host/plugin_fixture_state.hpp>
#include <trackflow/host/validate.hpp>

#include <filesystem>

namespace trackflow::testing {

PluginFixture::PluginFixture(const std::vector<std::string>& files_or_dirs) : state_(std::make_unique<State>()) {
  host::PluginRegistry& registry = state_->registry;
  std::vector<std::string> dirs;
  for (const auto& p : files_or_dirs) {
    if (std::filesystem::is_directory(p))
      dirs.push_back(p);
    else
      registry.load_file(p);
  }
  if (!dirs.empty()) registry.load_directories(dirs);
  if (!registry.problems().empty()) throw std::runtime_error("plugin not loaded: " + registry.problems()[0].str());
}

PluginFixture::~PluginFixture() = default;

Params PluginFixture::params_for(const std::string& type, const std::string& yaml_params,
                                 const std::string& node_id) const {
  const host::RegisteredType* t = state_->registry.find(type);
  if (!t) throw std::runtime_error("no plugin declares type '" + type + "'");
  const host::Value v = host::load_yaml_string(yaml_params, "test params");
  host::ComponentTypes types;
  for (const auto& r : state_->registry.types()) types.push_back(&r.decl);
  return host::validate_params(t->decl.params, v, node_id, v.loc, types);
}

std::shared_ptr<Component> PluginFixture::make(const std::string& type, const std::string& yaml_params,
                                               const std::string& node_id) const {
  const host::PluginRegistry& registry = state_->registry;
  std::shared_ptr<Component> c = registry.create(*registry.find(type), params_for(type, yaml_params, node_id));
  // A filter's own annotations get their slots as in the engine (graph.cpp).
  if (auto* f = dynamic_cast<Filter*>(c.get()))
    if (!host::FilterControl::reserve_own_annotations(*f, static_cast<int>(f->annotation_names().size())))
      throw std::runtime_error("too many annotations on a " + type);
  return c;
}

std::shared_ptr<Estimator> PluginFixture::make_estimator(const std::string& type, const std::string& yaml_params,
                                                        const std::string& node_id) const {
  const host::PluginRegistry& registry = state_->registry;
  return registry.create_estimator(*registry.find(type), params_for(type, yaml_params, node_id));
}

void attach(Adapter& adapter, Filter& filter) {
  const std::string why = noise_mismatch(adapter.needs(), filter.noise(), filter.has_covariance_access());
  if (!why.empty()) throw std::runtime_error("cannot attach: " + why);
  if (!host::FilterControl::attach(filter, adapter, static_cast<int>(adapter.annotation_names().size())))
    throw std::runtime_error("cannot attach: too many adapters or annotations");
  host::FilterControl::save_configured_noise(filter);
}

void save_configured_noise(Filter& filter) { host::FilterControl::save_configured_noise(filter); }

void start_run(Component& c, std::uint64_t run, std::uint64_t seed, Diagnostics* diag) {
  if (auto* f = dynamic_cast<Filter*>(&c)) host::FilterControl::reset_adapted_state(*f);
  c.start_run({run, seed, diag});
}

}  // namespace trackflow::testing
