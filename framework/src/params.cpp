// Purpose: parameter declarations' builders and the typed getters of validated parameters.
#include <trackflow/estimator.hpp>
#include <trackflow/params.hpp>

#include <algorithm>
#include <utility>

namespace trackflow {

const char* to_string(ParamType t) {
  switch (t) {
    case ParamType::Real: return "real";
    case ParamType::Integer: return "integer";
    case ParamType::Boolean: return "boolean";
    case ParamType::String: return "string";
    case ParamType::Choice: return "choice";
    case ParamType::RealList: return "list of reals";
    case ParamType::Records: return "list of records";
    case ParamType::Component: return "component";
    case ParamType::ComponentList: return "list of components";
  }
  return "?";
}

namespace {
ParamSpec make(std::string name, ParamType t, std::string doc) {
  ParamSpec s;
  s.name = std::move(name);
  s.type = t;
  s.doc = std::move(doc);
  return s;
}
}  // namespace

ParamSpec ParamSpec::real(std::string name, Dimension d, std::string doc) {
  auto s = make(std::move(name), ParamType::Real, std::move(doc));
  s.dimension = d;
  return s;
}
ParamSpec ParamSpec::integer(std::string name, std::string doc) {
  return make(std::move(name), ParamType::Integer, std::move(doc));
}
ParamSpec ParamSpec::boolean(std::string name, std::string doc) {
  return make(std::move(name), ParamType::Boolean, std::move(doc));
}
ParamSpec ParamSpec::string(std::string name, std::string doc) {
  return make(std::move(name), ParamType::String, std::move(doc));
}
ParamSpec ParamSpec::choice_words(std::string name, std::vector<std::string> choices, std::string doc) {
  auto s = make(std::move(name), ParamType::Choice, std::move(doc));
  for (size_t i = 0; i < choices.size(); ++i) s.choice_values.push_back(static_cast<int>(i));
  s.choices = std::move(choices);
  return s;
}
ParamSpec ParamSpec::real_list(std::string name, Dimension d, std::string doc, int size) {
  auto s = make(std::move(name), ParamType::RealList, std::move(doc));
  s.dimension = d;
  s.list_size = size;
  return s;
}
ParamSpec ParamSpec::records(std::string name, std::vector<ParamSpec> fields, std::string doc) {
  auto s = make(std::move(name), ParamType::Records, std::move(doc));
  s.fields = std::move(fields);
  return s;
}

ParamSpec ParamSpec::component(std::string name, std::vector<ComponentKind> kinds, std::string doc) {
  auto s = make(std::move(name), ParamType::Component, std::move(doc));
  s.kinds = std::move(kinds);
  return s;
}
ParamSpec ParamSpec::component_list(std::string name, std::vector<ComponentKind> kinds, std::string doc) {
  auto s = make(std::move(name), ParamType::ComponentList, std::move(doc));
  s.kinds = std::move(kinds);
  return s;
}

ParamValue::ParamValue() = default;
ParamValue::ParamValue(const ParamValue&) = default;
ParamValue::ParamValue(ParamValue&&) noexcept = default;
ParamValue& ParamValue::operator=(const ParamValue&) = default;
ParamValue& ParamValue::operator=(ParamValue&&) noexcept = default;
ParamValue::~ParamValue() = default;

const ParamValue& Params::get(std::string_view name, ParamType expected) const {
  for (const auto& [n, v] : values_) {
    if (n != name) continue;
    if (v.type != expected)
      throw ConfigError("parameter '" + std::string(name) + "' is a " + to_string(v.type) +
                            ", read as a " + to_string(expected) + " (plugin bug)",
                        v.where, node_);
    return v;
  }
  throw ConfigError("parameter '" + std::string(name) + "' has no value (not declared, or optional and not given)",
                    where_, node_);
}

double Params::real(std::string_view n) const { return get(n, ParamType::Real).real; }
long long Params::integer(std::string_view n) const { return get(n, ParamType::Integer).integer; }
bool Params::boolean(std::string_view n) const { return get(n, ParamType::Boolean).boolean; }
const std::string& Params::text(std::string_view n) const { return get(n, ParamType::String).text; }
const std::string& Params::choice_word(std::string_view n) const { return get(n, ParamType::Choice).text; }
const std::vector<double>& Params::reals(std::string_view n) const { return get(n, ParamType::RealList).reals; }
const std::vector<Params>& Params::records(std::string_view n) const { return get(n, ParamType::Records).records; }

const NestedComponent& Params::component(std::string_view n) const {
  return get(n, ParamType::Component).components.front();  // validation makes exactly one
}
const std::vector<NestedComponent>& Params::components(std::string_view n) const {
  for (const auto& [name, v] : values_)
    if (name == n && v.type == ParamType::Records) return v.components;  // a Records list or_components
  return get(n, ParamType::ComponentList).components;
}

std::unique_ptr<Estimator> NestedComponent::create_estimator() const {
  if (!estimator_factory)
    throw ConfigError("type '" + type + "' declares no per-track estimator, so it cannot be composed here", type_where,
                      params.node());
  std::unique_ptr<Estimator> e = estimator_factory(params);
  if (!e) throw ConfigError("estimator factory of '" + type + "' returned nothing", type_where, params.node());
  return e;
}

Vec3 Params::vec3(std::string_view n) const {
  const auto& r = reals(n);
  if (r.size() != 3) throw error(n, "expects 3 values, got " + std::to_string(r.size()));
  return {r[0], r[1], r[2]};
}

bool Params::has(std::string_view name) const {
  for (const auto& [n, v] : values_)
    if (n == name) return true;
  return false;
}
bool Params::given(std::string_view name) const {
  for (const auto& [n, v] : values_)
    if (n == name) return !v.from_default;
  return false;
}
SourceLoc Params::where(std::string_view name) const {
  for (const auto& [n, v] : values_)
    if (n == name && !v.from_default) return v.where;
  return where_;
}
ConfigError Params::error(std::string_view name, const std::string& message) const {
  return ConfigError("parameter '" + std::string(name) + "': " + message, where(name), node_);
}
void Params::warn(std::string_view name, const std::string& message) const {
  detail::note_setup_warning(error(name, message).message());
}

namespace detail {
namespace {
thread_local std::vector<std::string>* setup_warnings = nullptr;
}  // namespace
std::vector<std::string>* install_setup_warnings(std::vector<std::string>* collector) {
  return std::exchange(setup_warnings, collector);
}
void note_setup_warning(const std::string& text) {
  if (!setup_warnings) return;
  if (std::find(setup_warnings->begin(), setup_warnings->end(), text) == setup_warnings->end())
    setup_warnings->push_back(text);
}
}  // namespace detail

}  // namespace trackflow
