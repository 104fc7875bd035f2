// Purpose: a component's parameter declaration (name, type, unit, default, doc) and the validated values it receives.
#pragma once

#include <boost/config.hpp>

#include <trackflow/error.hpp>
#include <trackflow/items.hpp>
#include <trackflow/units.hpp>

#include <functional>
#include <initializer_list>
#include <memory>
#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace trackflow {

// Declared in registry.hpp (which includes this header); a scoped enum's opaque declaration is complete.
enum class ComponentKind;

enum class ParamType {
  Real,      // a quantity with a dimension: "10 m", "3 mrad", 0.5
  Integer,
  Boolean,
  String,
  Choice,    // one of a fixed list of words
  RealList,  // [1, 2, 3] or [1 km, 2 km]; each element has the declared dimension
  Records,   // a list of maps, each validated against `fields` (e.g. trajectory segments)
  Component,      // one nested component: {type: filter.ekf, <that type's params>...}
  ComponentList,  // a list of such maps
};
const char* to_string(ParamType t);

// One declared parameter. Validation, `trackflow describe` and the docs are derived from it.
struct ParamSpec {
  std::string name;
  ParamType type = ParamType::Real;
  Dimension dimension;            // Real and RealList only
  std::string doc;                // one line
  bool required = false;
  std::string default_text;       // as an analyst would write it ("10 m"); empty: no default
  std::vector<std::string> choices;
  std::vector<int> choice_values;  // Choice: the enum value of each word (see choice<E>)
  std::vector<ParamSpec> fields;  // Records only
  // Records only: an entry with a `type:` key is a nested component (of `kinds` and `type_prefix`,
  // validated against that type's declaration) instead of a record; entries are all of one form.
  bool components_too = false;
  double min = -std::numeric_limits<double>::infinity();  // SI, inclusive
  double max = std::numeric_limits<double>::infinity();
  int list_size = -1;             // RealList: exact length when >= 0
  // Component and ComponentList: the types a nested map may name. Empty kinds: any kind; empty
  // prefix: any name. Its params are validated against that type's own declaration.
  std::vector<ComponentKind> kinds;
  std::string type_prefix;
  // Real and RealList: a value whose magnitude is above plausible_max_abs (SI) is valid but
  // seldom meant; validate and run warn, naming the parameter's line, with implausible_hint
  // saying what is most often meant (issue 26: an angle sigma of 2 rad is degrees written as rad).
  double plausible_max_abs = std::numeric_limits<double>::infinity();
  std::string implausible_hint;

  // Fluent construction, e.g.
  //   ParamSpec::real("sigma_range", dim::length, "range noise σ").def("10 m").at_least(0)
  static ParamSpec real(std::string name, Dimension d, std::string doc);
  static ParamSpec integer(std::string name, std::string doc);
  static ParamSpec boolean(std::string name, std::string doc);
  static ParamSpec string(std::string name, std::string doc);
  // A choice yields an enum declared beside its words, e.g.
  //   enum class Init { TwoPoint, Explicit };
  //   ParamSpec::choice<Init>("init", {{Init::TwoPoint, "two_point"}, {Init::Explicit, "explicit"}}, "...")
  // and the plugin reads it as p.choice<Init>("init"): no string comparison, no silent fallback.
  template <class E>
  static ParamSpec choice(std::string name, std::initializer_list<std::pair<E, const char*>> options, std::string doc) {
    std::vector<std::string> words;
    std::vector<int> values;
    for (const auto& [value, word] : options) {
      words.emplace_back(word);
      values.push_back(static_cast<int>(value));
    }
    ParamSpec s = choice_words(std::move(name), std::move(words), std::move(doc));
    s.choice_values = std::move(values);
    return s;
  }
  static ParamSpec real_list(std::string name, Dimension d, std::string doc, int size = -1);
  // A choice read only as its word (choice_word); prefer the typed form above.
  static ParamSpec choice_words(std::string name, std::vector<std::string> choices, std::string doc);
  static ParamSpec records(std::string name, std::vector<ParamSpec> fields, std::string doc);
  // A nested component of one of `kinds`, e.g. ParamSpec::component("motion_filter", {ComponentKind::Filter}, "...");
  // the plugin reads it as p.component(name) and may ask the host to create it.
  static ParamSpec component(std::string name, std::vector<ComponentKind> kinds, std::string doc);
  static ParamSpec component_list(std::string name, std::vector<ComponentKind> kinds, std::string doc);
  // A Records list whose entries may instead all be nested components of `kinds`
  // (p.records(name) then holds none and p.components(name) each entry).
  ParamSpec or_components(std::vector<ComponentKind> k) && {
    kinds = std::move(k);
    components_too = true;
    return std::move(*this);
  }
  // Only types whose name starts with `prefix` ("filter.").
  ParamSpec with_prefix(std::string prefix) && { type_prefix = std::move(prefix); return std::move(*this); }
  ParamSpec def(std::string text) && { default_text = std::move(text); return std::move(*this); }
  ParamSpec req() && { required = true; return std::move(*this); }
  ParamSpec at_least(double v) && { min = v; return std::move(*this); }
  ParamSpec at_most(double v) && { max = v; return std::move(*this); }
  ParamSpec positive() && { min = std::numeric_limits<double>::denorm_min(); return std::move(*this); }
  // A warning above `max_abs` (SI), e.g. .plausible_up_to(0.3, "an angle sigma above 0.3 rad (17 deg)
  // is most often degrees written as radians").
  ParamSpec plausible_up_to(double max_abs, std::string hint) && {
    plausible_max_abs = max_abs;
    implausible_hint = std::move(hint);
    return std::move(*this);
  }
};

class Params;
struct NestedComponent;
class Estimator;
class TrackerPart;
class Component;

struct ParamValue {
  ParamType type = ParamType::Real;
  double real = 0.0;
  long long integer = 0;
  int choice = 0;  // Choice: the enum value declared for the word
  bool boolean = false;
  std::string text;
  std::vector<double> reals;
  std::vector<Params> records;
  std::vector<NestedComponent> components;  // Component: exactly one; ComponentList: each entry
  SourceLoc where;
  bool from_default = false;

  // Defined in params.cpp, where Params is complete: inline ones would need Params complete
  // here, which it cannot be (Params holds ParamValues), and clang refuses that cycle.
  ParamValue();
  ParamValue(const ParamValue&);
  ParamValue(ParamValue&&) noexcept;
  ParamValue& operator=(const ParamValue&);
  ParamValue& operator=(ParamValue&&) noexcept;
  ~ParamValue();
};

// Validated parameters of one node (or of one record inside a Records parameter).
// Getters throw ConfigError naming the node if a name was not declared with that type.
class Params {
 public:
  Params() = default;
  Params(std::string node, SourceLoc where) : node_(std::move(node)), where_(std::move(where)) {}

  double real(std::string_view name) const;
  long long integer(std::string_view name) const;
  bool boolean(std::string_view name) const;
  const std::string& text(std::string_view name) const;  // String only
  template <class E>
  E choice(std::string_view name) const { return static_cast<E>(get(name, ParamType::Choice).choice); }
  const std::string& choice_word(std::string_view name) const;  // the word as written, for messages
  const std::vector<double>& reals(std::string_view name) const;
  Vec3 vec3(std::string_view name) const;                // RealList of size 3
  const std::vector<Params>& records(std::string_view name) const;
  const NestedComponent& component(std::string_view name) const;               // Component only
  // ComponentList, or the component entries of a Records list declared or_components (empty when
  // its entries are records).
  const std::vector<NestedComponent>& components(std::string_view name) const;
  double real_or(std::string_view name, double fallback) const { return has(name) ? real(name) : fallback; }

  bool has(std::string_view name) const;    // a value exists (given or defaulted)
  bool given(std::string_view name) const;  // the analyst wrote it
  SourceLoc where(std::string_view name) const;
  const SourceLoc& where() const { return where_; }
  const std::string& node() const { return node_; }
  // A ConfigError pointing at the parameter's line in the analyst's file.
  ConfigError error(std::string_view name, const std::string& message) const;
  // A warning pointing at the parameter's line: the value is valid but seldom meant (a turn of
  // 40 g). `validate` and `run` print it; the pipeline still runs. For checks a declaration's
  // plausible_up_to cannot state (they need several parameters); call it from the factory.
  void warn(std::string_view name, const std::string& message) const;

  // Engine side.
  void set(std::string name, ParamValue v) { values_.emplace_back(std::move(name), std::move(v)); }
  const std::vector<std::pair<std::string, ParamValue>>& values() const { return values_; }

 private:
  const ParamValue& get(std::string_view name, ParamType expected) const;
  std::string node_;
  SourceLoc where_;
  std::vector<std::pair<std::string, ParamValue>> values_;
};

// A validated nested component: the type named by its `type:` key and its other keys, validated
// against that type's declaration (units converted to SI as for any node).
struct NestedComponent {
  std::string type;
  Params params;
  SourceLoc type_where;  // the `type:` value, for messages about the type itself
  // The nested type's per-track estimator factory (its ComponentDecl::create_estimator), set by
  // the host at validation; empty when the type declares none. Its code lives in that type's
  // plugin, which the host keeps loaded while the pipeline that named it exists.
  std::function<std::unique_ptr<Estimator>(const Params&)> estimator_factory;
  // The nested type's tracker-part factory (ComponentDecl::create_part), likewise; make_part
  // (tracker.hpp) creates the part.
  std::function<std::unique_ptr<TrackerPart>(const Params&)> part_factory;
  // The nested type's own component factory (ComponentDecl::create), for a component composed of
  // components that are not parts or estimators (tracker.multi's per-track adapters,
  // track_adapters.hpp), and the measurement frames it declares it accepts (ComponentDecl::accepts_frames).
  std::function<std::unique_ptr<Component>(const Params&)> component_factory;
  FrameMask accepts_frames = kAnyFrame;

  // The nested type's estimator from `params`, for a component composed of estimators (filter.imm's
  // modes). Throws ConfigError at the `type:` value when the type declares no estimator.
  std::unique_ptr<Estimator> create_estimator() const;
};

namespace detail {
// The host's side of Params::warn. While a collector is installed on this thread (the host builds
// a graph), warnings are appended to it as "file:line:col: node 'n': parameter 'p': message", each
// once; with none installed (a run constructing the same components again) they are dropped, as
// they were reported when the graph was built. Returns the previous collector.
BOOST_SYMBOL_VISIBLE std::vector<std::string>* install_setup_warnings(std::vector<std::string>* collector);
BOOST_SYMBOL_VISIBLE void note_setup_warning(const std::string& text);
}  // namespace detail

}  // namespace trackflow
