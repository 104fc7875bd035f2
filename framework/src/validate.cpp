// Purpose: validation of node parameters against their declarations (type, unit dimension, range).
#include <trackflow/host/suggest.hpp>
#include <trackflow/host/validate.hpp>
#include <trackflow/number_text.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

namespace trackflow::host {
namespace {

// Shortest round-trip digits, but a whole number below 1e15 in full ("100000", not "1e+05").
std::string fmt_si(double v) {
  if (v == std::floor(v) && std::fabs(v) < 1e15) return number_text::fixed(v, 0);
  return number_text::shortest(v);
}

// A declared range as an analyst reads it: "> 0 and <= 1", ">= -11000 m and <= 100000 m",
// "> 0 and <= 30 deg" (issue 26: the old "between 4.94066e-324 and 1 1" printed
// ParamSpec::positive()'s smallest double and the dimension "1" of a plain number). Bounds in the
// declaration's SI unit with shortest round-trip digits; a plain angle in degrees (6 digits), the
// unit analysts give angles in (30 deg, not 0.5235987755982988 rad).
std::string range_text(const ParamSpec& s) {
  const bool degrees = s.dimension == dim::angle;
  const std::string unit = degrees ? " deg" : s.dimension.dimensionless() ? "" : " " + s.dimension.str();
  auto value = [&](double v) {
    return (degrees ? number_text::general(v * 180.0 / std::numbers::pi, 6) : fmt_si(v)) + unit;
  };
  std::string lo, hi;
  if (s.min > 0 && s.min < 1e-300)
    lo = "> 0";  // positive(): denorm_min; zero needs no unit
  else if (std::isfinite(s.min))
    lo = ">= " + value(s.min);
  if (std::isfinite(s.max)) hi = "<= " + value(s.max);
  if (lo.empty()) return hi;
  return hi.empty() ? lo : lo + " and " + hi;
}

// A bare number for a quantity with an angle in its dimension (an angle, an angular rate) is
// refused (issue 26): SI would read `sigma_azimuth: 2` as 2 rad (115 deg) and `turn_rate: 3` as
// 3 rad/s (61 g at 200 m/s), both valid and both almost certainly meant in degrees. A length, a
// time, or a density per angle (clutter per m*rad^2), given bare is what the SI reading says: those
// are computed, not read off a data sheet in degrees. Zero needs no unit.
std::string bare_angle_problem(const ParamSpec& s, const std::string& text, double si) {
  const std::string si_unit = s.dimension.str();
  std::string deg_unit = si_unit;
  for (size_t at = deg_unit.find("rad"); at != std::string::npos; at = deg_unit.find("rad", at + 3))
    deg_unit.replace(at, 3, "deg");
  const double deg = si * std::pow(180.0 / std::numbers::pi, s.dimension.angle);
  const std::string number = quote_token(text);
  std::string ways = "'" + number + " " + deg_unit + "'";
  if (s.dimension == dim::angle) ways += ", '" + number + " mrad'";
  ways += " or '" + number + " " + si_unit + "'";
  return "parameter '" + s.name + "' is " + (s.dimension == dim::angle ? "an angle" : "a quantity in " + si_unit) +
         ": write its unit (" + ways + "); a bare " + number + " would be read as " + number + " " + si_unit + " = " +
         number_text::general(deg, 6) + " " + deg_unit;
}

// Set while a declaration's default is parsed: a default is the plugin author's SI number, neither
// an analyst's bare angle to refuse nor an analyst's value to call implausible.
thread_local bool parsing_default = false;

double parse_real(const ParamSpec& s, const Value& v, const std::string& node) {
  if (!v.is_scalar())
    throw ConfigError("parameter '" + s.name + "' expects a " + describe_type(s) + ", got " + v.describe(), v.loc,
                      node);
  Quantity q;
  try {
    q = parse_quantity(v.scalar);
  } catch (const std::exception& e) {
    throw ConfigError("parameter '" + s.name + "': " + e.what(), v.loc, node);
  }
  if (!q.had_unit && q.value != 0 && s.dimension.angle > 0 && !parsing_default)
    throw ConfigError(bare_angle_problem(s, v.scalar, q.value), v.loc, node);
  if (q.had_unit && q.dimension != s.dimension)
    throw ConfigError("parameter '" + s.name + "' has unit dimension " + s.dimension.str() + ", but '" + quote_token(v.scalar) +
                          "' is " + q.dimension.str(),
                      v.loc, node);
  if (q.value < s.min || q.value > s.max)
    throw ConfigError("parameter '" + s.name + "' must be " + range_text(s) + ", got '" + quote_token(v.scalar) + "'",
                      v.loc, node);
  if (std::abs(q.value) > s.plausible_max_abs && !parsing_default)
    detail::note_setup_warning(ConfigError("parameter '" + s.name + "' = '" + quote_token(v.scalar) +
                                               "' is valid but implausible: " + s.implausible_hint,
                                           v.loc, node)
                                   .message());
  return q.value;
}

bool accepts(const ParamSpec& s, const ComponentDecl& d) {
  const bool kind_ok = s.kinds.empty() || std::find(s.kinds.begin(), s.kinds.end(), d.kind) != s.kinds.end();
  return kind_ok && d.type.rfind(s.type_prefix, 0) == 0;
}

// What a Component parameter accepts, for describe and messages: "filter", "filter, type filter.*".
std::string accepted_text(const ParamSpec& s) {
  std::vector<std::string> parts;
  std::vector<std::string> k;
  for (ComponentKind kind : s.kinds) k.push_back(to_string(kind));
  if (!k.empty()) parts.push_back(join(k, "/"));
  if (!s.type_prefix.empty()) parts.push_back("type " + s.type_prefix + "*");
  return parts.empty() ? "any type" : join(parts, ", ");
}

// One `{type: <name>, <params>...}` map: the type must be a loaded one that the spec accepts; the
// other keys are that type's params, validated by validate_params itself, so a nested key's error
// has the nested key's own file:line:col as any top-level one.
NestedComponent parse_component(const ParamSpec& s, const Value& v, const std::string& node,
                                const ComponentTypes& types) {
  if (v.kind != Value::Kind::Map)
    throw ConfigError("parameter '" + s.name + "' expects a map {type: <" + accepted_text(s) + ">, <its parameters>}, got " +
                          v.describe(),
                      v.loc, node);
  const Value* type = v.find("type");
  if (!type) throw ConfigError("parameter '" + s.name + "': the component map has no 'type'", v.loc, node);
  if (!type->is_scalar())
    throw ConfigError("parameter '" + s.name + "': 'type' must be a type name, got " + type->describe(), type->loc, node);
  std::vector<std::string> names;
  const ComponentDecl* decl = nullptr;
  for (const ComponentDecl* d : types) {
    if (!accepts(s, *d)) continue;
    names.push_back(d->type);
    if (d->type == type->scalar) decl = d;
  }
  if (!decl) {
    const bool exists = std::any_of(types.begin(), types.end(), [&](const ComponentDecl* d) { return d->type == type->scalar; });
    throw ConfigError("parameter '" + s.name + "': " +
                          (exists ? "type '" + quote_token(type->scalar) + "' is not accepted here"
                                  : "unknown type '" + quote_token(type->scalar) + "'" + did_you_mean(type->scalar, names)) +
                          "; accepted (" + accepted_text(s) + "): " + (names.empty() ? std::string("none loaded") : join(names)),
                      type->loc, node);
  }
  Value rest = v;
  for (size_t i = 0; i < rest.entries.size(); ++i)
    if (rest.entries[i].first == "type") {
      rest.entries.erase(rest.entries.begin() + static_cast<std::ptrdiff_t>(i));
      rest.key_locs.erase(rest.key_locs.begin() + static_cast<std::ptrdiff_t>(i));
      break;
    }
  NestedComponent out{decl->type, validate_params(decl->params, rest, node, v.loc, types), type->loc, {}};
  out.estimator_factory = decl->create_estimator;
  out.part_factory = decl->create_part;
  out.component_factory = decl->create;
  out.accepts_frames = decl->accepts_frames;
  return out;
}

ParamValue parse_value(const ParamSpec& s, const Value& v, const std::string& node, const ComponentTypes& types) {
  ParamValue out;
  out.type = s.type;
  out.where = v.loc;
  auto type_error = [&]() {
    return ConfigError("parameter '" + s.name + "' expects a " + describe_type(s) + ", got " + v.describe(), v.loc,
                       node);
  };
  switch (s.type) {
    case ParamType::Real:
      out.real = parse_real(s, v, node);
      break;
    case ParamType::Integer: {
      if (!v.is_scalar()) throw type_error();
      try {
        size_t used = 0;
        out.integer = std::stoll(v.scalar, &used);
        if (used != v.scalar.size()) throw type_error();
      } catch (const std::logic_error&) {
        throw type_error();
      }
      if (out.integer < s.min || out.integer > s.max) throw ConfigError("parameter '" + s.name + "' out of range", v.loc, node);
      break;
    }
    case ParamType::Boolean:
      if (!v.is_scalar()) throw type_error();
      if (v.scalar == "true" || v.scalar == "yes" || v.scalar == "on")
        out.boolean = true;
      else if (v.scalar == "false" || v.scalar == "no" || v.scalar == "off")
        out.boolean = false;
      else
        throw type_error();
      break;
    case ParamType::String:
      if (!v.is_scalar()) throw type_error();
      out.text = v.scalar;
      break;
    case ParamType::Choice: {
      if (!v.is_scalar()) throw type_error();
      const auto it = std::find(s.choices.begin(), s.choices.end(), v.scalar);
      if (it == s.choices.end())
        throw ConfigError("parameter '" + s.name + "' must be one of " + join(s.choices, ", ") + "; got '" + quote_token(v.scalar) +
                              "'" + did_you_mean(v.scalar, s.choices),
                          v.loc, node);
      const size_t i = static_cast<size_t>(it - s.choices.begin());
      out.choice = i < s.choice_values.size() ? s.choice_values[i] : static_cast<int>(i);
      out.text = v.scalar;
      break;
    }
    case ParamType::RealList: {
      if (v.kind != Value::Kind::List) throw type_error();
      if (s.list_size >= 0 && static_cast<int>(v.items.size()) != s.list_size)
        throw ConfigError("parameter '" + s.name + "' expects " + std::to_string(s.list_size) + " values, got " +
                              std::to_string(v.items.size()),
                          v.loc, node);
      ParamSpec elem = s;
      elem.type = ParamType::Real;
      for (const auto& item : v.items) out.reals.push_back(parse_real(elem, item, node));
      break;
    }
    case ParamType::Records: {
      if (v.kind != Value::Kind::List) throw type_error();
      for (const auto& item : v.items) {
        if (item.kind != Value::Kind::Map)
          throw ConfigError("each entry of '" + s.name + "' must be a map, got " + item.describe(), item.loc, node);
        if (s.components_too && item.find("type"))
          out.components.push_back(parse_component(s, item, node, types));
        else
          out.records.push_back(validate_params(s.fields, item, node, item.loc, types));
      }
      if (!out.records.empty() && !out.components.empty())
        throw ConfigError("parameter '" + s.name + "': give every entry as a record or every entry as a component {type: " +
                              accepted_text(s) + ", <its parameters>}, not both",
                          v.loc, node);
      break;
    }
    case ParamType::Component:
      out.components.push_back(parse_component(s, v, node, types));
      break;
    case ParamType::ComponentList: {
      if (v.kind != Value::Kind::List) throw type_error();
      for (const auto& item : v.items) out.components.push_back(parse_component(s, item, node, types));
      break;
    }
  }
  return out;
}

}  // namespace

std::string describe_type(const ParamSpec& s) {
  switch (s.type) {
    case ParamType::Real: return "real [" + s.dimension.str() + "]";
    case ParamType::RealList:
      return (s.list_size >= 0 ? "list of " + std::to_string(s.list_size) : std::string("list of")) + " reals [" +
             s.dimension.str() + "]";
    case ParamType::Choice: return "choice {" + join(s.choices, "|") + "}";
    case ParamType::Component: return "component {type: " + accepted_text(s) + "}";
    case ParamType::ComponentList: return "list of components {type: " + accepted_text(s) + "}";
    case ParamType::Records:
      return s.components_too ? "list of records or of components {type: " + accepted_text(s) + "}" : "list of records";
    default: return to_string(s.type);
  }
}

Params validate_params(const std::vector<ParamSpec>& specs, const Value& given, const std::string& node,
                       const SourceLoc& node_loc, const ComponentTypes& types) {
  Params p(node, given.kind == Value::Kind::Null ? node_loc : given.loc);
  std::vector<std::string> names;
  for (const auto& s : specs) names.push_back(s.name);
  for (size_t i = 0; i < given.entries.size(); ++i) {
    const auto& key = given.entries[i].first;
    if (std::find(names.begin(), names.end(), key) == names.end())
      throw ConfigError("unknown parameter '" + quote_token(key) + "'" + did_you_mean(key, names) +
                            (names.empty() ? "; this type takes no parameters" : "; known: " + join(names)),
                        given.key_locs[i], node);
  }
  for (const auto& s : specs) {
    if (const Value* v = given.find(s.name)) {
      p.set(s.name, parse_value(s, *v, node, types));
    } else if (!s.default_text.empty()) {
      Value dv = load_yaml_string(s.default_text, "default of " + s.name);
      parsing_default = true;
      ParamValue pv;
      try {
        pv = parse_value(s, dv, node, types);
      } catch (...) {
        parsing_default = false;
        throw;
      }
      parsing_default = false;
      pv.from_default = true;
      p.set(s.name, std::move(pv));
    } else if (s.required) {
      throw ConfigError("missing required parameter '" + s.name + "' (" + describe_type(s) + ": " + s.doc + ")",
                        given.kind == Value::Kind::Null ? node_loc : given.loc, node);
    }
  }
  return p;
}

}  // namespace trackflow::host
