// Purpose: YAML loading into a located value tree and parsing of the pipeline's top-level structure.
#include <trackflow/host/config.hpp>
#include <trackflow/names.hpp>
#include <trackflow/host/suggest.hpp>

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unordered_map>

namespace trackflow::host {
namespace {

SourceLoc loc_of(const YAML::Mark& m, const std::string& file) {
  if (m.line < 0) return {file, 0, 0};
  return {file, m.line + 1, m.column + 1};
}

// Whether the quoted scalar opening at byte `pos` of `text` is closed. yaml-cpp 0.7 takes an
// unclosed quote as a scalar running to the end of the file (`type: "filter.kalman` became the type
// "filter.kalman input: cm - id: ...", reported as an unknown type). YAML 1.2 §7.3.1 (a '\\'
// escape inside "...") and §7.3.2 ('' inside '...').
bool quote_closed(const std::string& text, std::size_t pos) {
  const char q = text[pos];
  for (std::size_t i = pos + 1; i < text.size(); ++i) {
    if (q == '"' && text[i] == '\\') {
      ++i;
    } else if (text[i] == q) {
      if (q == '\'' && i + 1 < text.size() && text[i + 1] == '\'') {
        ++i;
        continue;
      }
      return true;
    }
  }
  return false;
}

// YAML aliases make the node graph a DAG (or, with an alias inside its own anchor, a cycle) that
// convert() expands into a tree: a budget on the values made and on the depth keeps a small
// hostile file ("billion laughs", `&a [*a]`) from exhausting memory or the stack.
struct Expansion {
  const std::string& file;
  const std::string& text;  // the parsed text, to check quoted scalars against
  std::size_t values = 0;
  std::vector<YAML::Node> path;  // ancestors of the node being converted, to name a recursive alias
};

Value convert(const YAML::Node& n, Expansion& x) {
  Value v;
  v.loc = loc_of(n.Mark(), x.file);
  if (++x.values > kMaxYamlValues)
    throw ConfigError("the YAML expands to more than " + std::to_string(kMaxYamlValues) +
                          " values (aliases repeated many times?); a pipeline is far smaller",
                      v.loc);
  if (n.IsMap() || n.IsSequence()) {
    for (const auto& a : x.path)
      if (a.is(n))
        throw ConfigError("an alias refers to a node that contains it (a recursive alias): it would never end", v.loc);
    if (x.path.size() >= kMaxYamlDepth)
      throw ConfigError("the YAML nests deeper than " + std::to_string(kMaxYamlDepth) + " levels", v.loc);
    x.path.push_back(n);
  }
  switch (n.Type()) {
    case YAML::NodeType::Null:
    case YAML::NodeType::Undefined:
      v.kind = Value::Kind::Null;
      break;
    case YAML::NodeType::Scalar: {
      v.kind = Value::Kind::Scalar;
      v.scalar = n.Scalar();
      const auto pos = static_cast<std::size_t>(n.Mark().pos);
      if (n.Mark().pos >= 0 && pos < x.text.size() && (x.text[pos] == '"' || x.text[pos] == '\'') &&
          !quote_closed(x.text, pos))
        throw ConfigError(std::string("YAML syntax error: the quote ") + x.text[pos] + " opened here is never closed",
                          v.loc);
      break;
    }
    case YAML::NodeType::Sequence:
      v.kind = Value::Kind::List;
      for (const auto& item : n) v.items.push_back(convert(item, x));
      break;
    case YAML::NodeType::Map:
      v.kind = Value::Kind::Map;
      for (const auto& kv : n) {
        const SourceLoc kl = loc_of(kv.first.Mark(), x.file);
        if (!kv.first.IsScalar()) throw ConfigError("a map key must be a plain name, not a list or a map", kl);
        const std::string key = kv.first.Scalar();
        if (v.find(key))
          throw ConfigError("duplicate key '" + quote_token(key) + "' (first at " + v.key_loc(key).str() + ")", kl);
        v.entries.emplace_back(key, convert(kv.second, x));
        v.key_locs.push_back(kl);
      }
      break;
  }
  if (n.IsMap() || n.IsSequence()) x.path.pop_back();
  return v;
}

// Parses without building anything; remembers where the last document started.
struct SecondDocument : YAML::EventHandler {
  YAML::Mark start;
  void OnDocumentStart(const YAML::Mark& m) override { start = m; }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

Value parse_text(const std::string& text, const std::string& name) {
  if (text.size() > kMaxYamlBytes)
    throw ConfigError("'" + name + "' is larger than " + std::to_string(kMaxYamlBytes / 1024) +
                      " KiB; a pipeline file is far smaller");
  YAML::Node doc;
  try {
    doc = YAML::Load(text);
    // A second document would otherwise be ignored without a word. (Not YAML::LoadAll: in
    // yaml-cpp 0.7 it loops forever on some malformed input, e.g. "[|".)
    std::istringstream in(text);
    YAML::Parser parser(in);
    SecondDocument probe;
    if (parser.HandleNextDocument(probe)) {
      const YAML::Mark first = probe.start;
      if (parser.HandleNextDocument(probe)) {
        // A parser that stays where it was has not understood the first document.
        if (probe.start.pos <= first.pos)
          throw ConfigError("YAML syntax error: this cannot be read as YAML", loc_of(probe.start, name));
        throw ConfigError("a second YAML document ('---') in one file; a pipeline is one document",
                          loc_of(probe.start, name));
      }
    }
  } catch (const YAML::Exception& e) {
    throw ConfigError("YAML syntax error: " + e.msg, loc_of(e.mark, name));
  }
  Expansion x{name, text};
  try {
    return convert(doc, x);
  } catch (const YAML::Exception& e) {
    throw ConfigError("YAML error: " + e.msg, loc_of(e.mark, name));
  }
}

const std::string& scalar(const Value& v, const std::string& what) {
  if (!v.is_scalar()) throw ConfigError(what + " must be a single value, got " + v.describe(), v.loc);
  return v.scalar;
}

// A whole number in the full 64-bit range (seeds are 64-bit): digits only, no sign, no exponent.
std::uint64_t to_count(const Value& v, const std::string& what) {
  const std::string& s = scalar(v, what);
  std::uint64_t n = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), n);
  if (!s.empty() && std::isdigit(static_cast<unsigned char>(s[0])) && ec == std::errc() && ptr == s.data() + s.size())
    return n;
  throw ConfigError(what + " must be a whole number from 0 to 18446744073709551615, got '" + quote_token(s) + "'", v.loc);
}

void reject_unknown_keys(const Value& map, const std::vector<std::string>& known, const std::string& where,
                         const std::string& node = {}) {
  for (size_t i = 0; i < map.entries.size(); ++i) {
    const auto& key = map.entries[i].first;
    if (std::find(known.begin(), known.end(), key) == known.end())
      throw ConfigError("unknown key '" + quote_token(key) + "' in " + where + did_you_mean(key, known) +
                            "; allowed: " + join(known),
                        map.key_locs[i], node);
  }
}

std::vector<std::string> string_list(const Value& v, const std::string& what, std::vector<SourceLoc>* locs = nullptr) {
  std::vector<std::string> out;
  if (v.is_scalar()) {
    out.push_back(v.scalar);
    if (locs) locs->push_back(v.loc);
  } else if (v.kind == Value::Kind::List) {
    for (const auto& item : v.items) {
      out.push_back(scalar(item, what + " entry"));
      if (locs) locs->push_back(item.loc);
    }
  } else {
    throw ConfigError(what + " must be a name or a list of names, got " + v.describe(), v.loc);
  }
  return out;
}

NodeConfig parse_node(const Value& v) {
  if (v.kind != Value::Kind::Map) throw ConfigError("each entry of 'nodes' must be a map with id and type", v.loc);
  NodeConfig n;
  n.loc = v.loc;
  const Value* id = v.find("id");
  if (!id) throw ConfigError("node has no 'id'", v.loc);
  n.id = scalar(*id, "id");
  // Ids become file names, JSON keys and CSV columns (names.hpp: the rule shared with other labels).
  if (!is_plain_name(n.id))
    throw ConfigError("node id '" + quote_token(n.id) + "' must be " + kPlainNameRule +
                          " (no '.', '=', space or other characters)",
                      id->loc);
  reject_unknown_keys(v, {"id", "type", "input", "inputs", "attach_to", "params", "doc"}, "node", n.id);
  const Value* type = v.find("type");
  if (!type) throw ConfigError("node has no 'type'", v.loc, n.id);
  n.type = scalar(*type, "type");
  n.type_loc = type->loc;
  const Value* input = v.find("input");
  const Value* inputs = v.find("inputs");
  if (input && inputs) throw ConfigError("give either 'input' or 'inputs', not both", inputs->loc, n.id);
  if (input) n.inputs = string_list(*input, "input", &n.input_locs);
  if (inputs) n.inputs = string_list(*inputs, "inputs", &n.input_locs);
  if (const Value* a = v.find("attach_to")) {
    n.attach_to = scalar(*a, "attach_to");
    n.attach_loc = a->loc;
  }
  if (const Value* p = v.find("params")) {
    if (p->kind != Value::Kind::Map && p->kind != Value::Kind::Null)
      throw ConfigError("'params' must be a map of name: value, got " + p->describe(), p->loc, n.id);
    n.params = *p;
  } else {
    n.params.kind = Value::Kind::Null;
    n.params.loc = v.loc;
  }
  return n;
}

// A plain finite number, the whole text ("25abc", "nan", "1e999" are refused).
double expect_number(const Value& v, const std::string& key, const std::string& op) {
  const std::string& t = scalar(v, "expect '" + key + "': '" + op + "'");
  const char* first = t.data() + (!t.empty() && t[0] == '+' ? 1 : 0);
  double x = 0;
  const auto [ptr, ec] = std::from_chars(first, t.data() + t.size(), x);
  if (ec != std::errc() || ptr != t.data() + t.size() || !std::isfinite(x))
    throw ConfigError("expect '" + key + "': '" + op + "' needs a finite number, got '" + quote_token(t) + "'", v.loc);
  return x;
}

// "<node id>.<metric>" of less_than, greater_than and ratio_to.
std::pair<std::string, std::string> metric_ref(const Value& v, const std::string& key, const std::string& op) {
  const std::string ref = scalar(v, op);
  const auto d = ref.find('.');
  if (d == std::string::npos || d == 0 || d + 1 == ref.size())
    throw ConfigError("expect '" + key + "': '" + op + "' needs <node id>.<metric>, got '" + quote_token(ref) + "'",
                      v.loc);
  return {ref.substr(0, d), ref.substr(d + 1)};
}

// One entry of `expect:` is one check per operator it names, all of them checked: { min: 1,
// max: 2 } is two checks, and nothing in the map is ignored. With ratio_to, min and max bound
// metric / reference and nothing else may be combined with it.
std::vector<ExpectConfig> parse_expect(const std::string& key, const SourceLoc& key_loc, const Value& v) {
  ExpectConfig base;
  base.loc = key_loc;
  const auto dot = key.find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == key.size())
    throw ConfigError("expect key '" + quote_token(key) + "' must be <node id>.<metric>", key_loc);
  base.node = key.substr(0, dot);
  base.metric = key.substr(dot + 1);
  if (v.kind != Value::Kind::Map || v.entries.empty())
    throw ConfigError("expect '" + key + "' must be a map such as { max: 25 } or { within_band: 0.95 }, or a list of them", v.loc);
  static const std::vector<std::string> ops = {"min",       "max",       "within_band",  "outside_band", "equals",
                                               "tolerance", "less_than", "greater_than", "ratio_to"};
  reject_unknown_keys(v, ops, "expect '" + key + "'");
  const Value* ratio = v.find("ratio_to");
  if (ratio) {
    std::tie(base.ref_node, base.ref_metric) = metric_ref(*ratio, key, "ratio_to");
    if (!v.find("min") && !v.find("max"))
      throw ConfigError("expect '" + key + "': 'ratio_to' needs 'min' and/or 'max' bounds for the ratio", ratio->loc);
    for (const char* other : {"equals", "tolerance", "within_band", "outside_band", "less_than", "greater_than"})
      if (v.find(other))
        throw ConfigError("expect '" + key + "': '" + other + "' cannot be combined with 'ratio_to' (which bounds the "
                          "ratio with min and max); write it as a separate entry",
                          v.key_loc(other));
  }
  const Value* tolerance = v.find("tolerance");
  if (tolerance && !v.find("equals"))
    throw ConfigError("expect '" + key + "': 'tolerance' applies only to 'equals'", v.key_loc("tolerance"));
  std::vector<ExpectConfig> out;
  // A fixed order (min before max, as always), whatever the order in the file.
  for (const char* op : {"min", "max", "equals", "within_band", "outside_band", "less_than", "greater_than"}) {
    const Value* val = v.find(op);
    if (!val) continue;
    ExpectConfig e = base;
    const std::string o = op;
    if (o == "less_than" || o == "greater_than") {
      e.op = o;
      std::tie(e.ref_node, e.ref_metric) = metric_ref(*val, key, o);
    } else {
      e.op = ratio && (o == "min" || o == "max") ? "ratio_" + o : o;
      e.value = expect_number(*val, key, o);
      if ((o == "within_band" || o == "outside_band") && !(e.value > 0 && e.value < 1))
        throw ConfigError("expect '" + key + "': '" + o + "' is a confidence between 0 and 1 (e.g. 0.95), got '" +
                              quote_token(val->scalar) + "'",
                          val->loc);
      if (o == "equals" && tolerance) {
        e.tolerance = expect_number(*tolerance, key, "tolerance");
        if (e.tolerance < 0)
          throw ConfigError("expect '" + key + "': 'tolerance' must not be negative", tolerance->loc);
      }
    }
    out.push_back(std::move(e));
  }
  return out;
}

// `sites: { name: { latitude: .., longitude: .., height: .. }, ... }` -> a list of records, each
// with its `name` first (a Records parameter's shape); the fields are validated by the components
// that declare `sites`, against their own field declarations.
Value parse_sites(const Value& v) {
  if (v.kind != Value::Kind::Map || v.entries.empty())
    throw ConfigError("'sites' must be a map of name: { latitude, longitude, height }", v.loc);
  Value list;
  list.kind = Value::Kind::List;
  list.loc = v.loc;
  for (size_t i = 0; i < v.entries.size(); ++i) {
    const auto& [name, site] = v.entries[i];
    if (name.empty() || name.find_first_of(". =") != std::string::npos)
      throw ConfigError("site name '" + name + "' must be non-empty and contain no '.', '=' or space", v.key_locs[i]);
    if (site.kind != Value::Kind::Map)
      throw ConfigError("site '" + name + "' must be a map such as { latitude: 34.43 deg, longitude: 127.53 deg, "
                        "height: 0 m }, got " + site.describe(), site.loc);
    if (site.find("name"))
      throw ConfigError("site '" + name + "': the key is its name; remove 'name'", site.key_loc("name"));
    Value record = site;
    Value n;
    n.kind = Value::Kind::Scalar;
    n.scalar = name;
    n.loc = v.key_locs[i];
    record.entries.insert(record.entries.begin(), {"name", n});
    record.key_locs.insert(record.key_locs.begin(), v.key_locs[i]);
    list.items.push_back(std::move(record));
  }
  return list;
}

}  // namespace

Value::Value() = default;
Value::Value(const Value&) = default;
Value::Value(Value&&) noexcept = default;
Value& Value::operator=(const Value&) = default;
Value& Value::operator=(Value&&) noexcept = default;
Value::~Value() = default;

const Value* Value::find(const std::string& key) const {
  for (const auto& [k, v] : entries)
    if (k == key) return &v;
  return nullptr;
}
Value* Value::find(const std::string& key) {
  for (auto& [k, v] : entries)
    if (k == key) return &v;
  return nullptr;
}
SourceLoc Value::key_loc(const std::string& key) const {
  for (size_t i = 0; i < entries.size(); ++i)
    if (entries[i].first == key) return key_locs[i];
  return loc;
}
std::string Value::describe() const {
  switch (kind) {
    case Kind::Null: return "nothing";
    case Kind::Scalar: return "'" + quote_token(scalar) + "'";
    case Kind::List: return "a list";
    case Kind::Map: return "a map";
  }
  return "?";
}

Value load_yaml_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw ConfigError("'" + path + "' is a folder, not a pipeline file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError("cannot open pipeline file '" + path + "'");
  // Read at most one byte more than allowed: /dev/zero or a huge file stop here, not in memory.
  std::string text(kMaxYamlBytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) throw ConfigError("cannot read pipeline file '" + path + "'");
  text.resize(static_cast<std::size_t>(in.gcount()));
  return parse_text(text, path);
}

Value load_yaml_string(const std::string& text, const std::string& name) { return parse_text(text, name); }

namespace {

// One step of an override's parameter path: a name and the list indices after it
// ("segments[1]" -> segments, {1}).
struct OverrideStep {
  std::string name;
  std::vector<std::size_t> indices;
};

std::vector<OverrideStep> parse_override_path(const std::string& path, const std::string& what) {
  std::vector<OverrideStep> steps;
  std::size_t at = 0;
  const auto bad = [&](const std::string& why) {
    return ConfigError(what + ": " + why + " (a path is name, name.name or name[index].name, e.g. truth.segments[1].turn_rate)");
  };
  for (;;) {
    OverrideStep step;
    while (at < path.size() && path[at] != '.' && path[at] != '[') step.name += path[at++];
    if (step.name.empty()) throw bad("empty parameter name");
    while (at < path.size() && path[at] == '[') {
      const auto close = path.find(']', at);
      if (close == std::string::npos) throw bad("'[' without ']'");
      const std::string digits = path.substr(at + 1, close - at - 1);
      if (digits.empty() || digits.size() > 6 || digits.find_first_not_of("0123456789") != std::string::npos)
        throw bad("'[" + quote_token(digits) + "]' is not a list index (0, 1, 2, ...)");
      step.indices.push_back(static_cast<std::size_t>(std::stoul(digits)));
      at = close + 1;
    }
    steps.push_back(std::move(step));
    if (at == path.size()) return steps;
    if (path[at] != '.') throw bad("unexpected '" + quote_token(path.substr(at, 1)) + "'");
    ++at;
  }
}

}  // namespace

Override parse_override(const std::string& text) {
  const auto eq = text.find('=');
  const auto dot = text.find('.');
  if (eq == std::string::npos || dot == std::string::npos || dot > eq || dot == 0 || dot + 1 == eq)
    throw ConfigError("--set '" + quote_token(text) + "' must look like node.param=value");
  return {text.substr(0, dot), text.substr(dot + 1, eq - dot - 1), text.substr(eq + 1)};
}

PipelineConfig parse_pipeline(const Value& root, const std::string& file, const std::vector<Override>& overrides) {
  PipelineConfig cfg;
  cfg.file = file;
  if (root.kind != Value::Kind::Map)
    throw ConfigError("a pipeline file is a map with 'pipeline', 'nodes' and optionally 'expect'", root.loc);
  reject_unknown_keys(root, {"pipeline", "sites", "nodes", "expect", "plugin_paths"}, "the top level");
  const std::filesystem::path base = std::filesystem::path(file).parent_path();
  auto add_paths = [&](const Value& v) {
    if (cfg.plugin_paths_loc.file.empty()) cfg.plugin_paths_loc = v.loc;
    for (const auto& p : string_list(v, "plugin_paths")) {
      std::filesystem::path pp(p);
      cfg.plugin_paths.push_back((pp.is_relative() ? base / pp : pp).string());
    }
  };
  if (const Value* p = root.find("pipeline")) {
    if (p->kind != Value::Kind::Map) throw ConfigError("'pipeline' must be a map", p->loc);
    reject_unknown_keys(
        *p, {"name", "description", "seed", "runs", "on_bad_row", "plugin_paths", "file_format", "frame_origin"},
        "'pipeline'");
    if (const Value* v = p->find("name")) {
      cfg.name = scalar(*v, "name");
      // The name is the default output folder out/<name>: it must stay one folder name.
      const bool safe = !cfg.name.empty() && cfg.name.size() <= 100 && cfg.name.front() != '.' &&
                        std::none_of(cfg.name.begin(), cfg.name.end(), [](char c) {
                          return c == '/' || c == '\\' || static_cast<unsigned char>(c) < 0x20 || c == 0x7f;
                        });
      if (!safe)
        throw ConfigError("name '" + quote_token(cfg.name) +
                              "' must be 1 to 100 characters without '/', '\\' or control characters and must not start "
                              "with '.' (it names the output folder out/<name>)",
                          v->loc);
    }
    if (const Value* v = p->find("description")) cfg.description = scalar(*v, "description");
    if (const Value* v = p->find("seed")) cfg.seed = to_count(*v, "seed");
    if (const Value* v = p->find("runs")) {
      cfg.runs = to_count(*v, "runs");
      if (cfg.runs == 0) throw ConfigError("runs must be at least 1", v->loc);
    }
    if (const Value* v = p->find("on_bad_row")) {
      cfg.on_bad_row = scalar(*v, "on_bad_row");
      if (cfg.on_bad_row != "error" && cfg.on_bad_row != "skip")
        throw ConfigError("on_bad_row must be 'error' or 'skip', got '" + quote_token(cfg.on_bad_row) + "'", v->loc);
    }
    if (const Value* v = p->find("plugin_paths")) add_paths(*v);
    if (const Value* v = p->find("frame_origin")) {
      scalar(*v, "frame_origin");
      cfg.frame_origin = *v;
    }
    if (const Value* v = p->find("file_format")) {
      if (scalar(*v, "file_format") != "1")
        throw ConfigError("file_format " + quote_token(v->scalar) + " is not supported by this trackflow (supports 1)", v->loc);
    }
  } else {
    throw ConfigError("missing 'pipeline:' section (name, seed, runs)", root.loc);
  }
  if (cfg.name.empty()) {
    cfg.name = std::filesystem::path(file).stem().string();
    for (char& c : cfg.name)
      if (c == '\\' || static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '_';
    if (cfg.name.empty() || cfg.name.front() == '.') cfg.name = "pipeline" + cfg.name;
  }
  if (const Value* v = root.find("sites")) {
    cfg.sites = parse_sites(*v);
    // Sites are positions in the ENU frame only once the frame is anchored at one of them.
    if (!cfg.frame_origin.is_scalar())
      throw ConfigError("'sites' needs 'frame_origin: <site>' in the pipeline: section (the site the ENU frame is "
                        "anchored at)",
                        v->loc);
  }
  if (cfg.frame_origin.is_scalar()) {
    std::vector<std::string> names;
    for (const auto& site : cfg.sites.items) names.push_back(site.entries.front().second.scalar);
    if (names.empty())
      throw ConfigError("frame_origin '" + quote_token(cfg.frame_origin.scalar) +
                            "' names a site, but the pipeline has no 'sites:' section",
                        cfg.frame_origin.loc);
    if (std::find(names.begin(), names.end(), cfg.frame_origin.scalar) == names.end())
      throw ConfigError("frame_origin '" + quote_token(cfg.frame_origin.scalar) + "' is not a site" +
                            did_you_mean(cfg.frame_origin.scalar, names) + "; sites: " + join(names),
                        cfg.frame_origin.loc);
  }
  if (const Value* v = root.find("plugin_paths")) add_paths(*v);

  const Value* nodes = root.find("nodes");
  if (!nodes || nodes->kind != Value::Kind::List || nodes->items.empty())
    throw ConfigError("'nodes' must be a non-empty list", nodes ? nodes->loc : root.loc);
  if (nodes->items.size() > kMaxNodes)
    throw ConfigError("'nodes' lists " + std::to_string(nodes->items.size()) + " nodes; at most " +
                          std::to_string(kMaxNodes) + " are supported",
                      nodes->loc);
  std::unordered_map<std::string, std::size_t> index;  // id -> position: linear in the node count
  for (const auto& n : nodes->items) {
    NodeConfig node = parse_node(n);
    const auto [it, fresh] = index.emplace(node.id, cfg.nodes.size());
    if (!fresh)
      throw ConfigError("duplicate node id '" + node.id + "' (first defined at " + cfg.nodes[it->second].loc.str() + ")",
                        node.loc, node.id);
    cfg.nodes.push_back(std::move(node));
  }

  for (const auto& o : overrides) {
    const auto found = index.find(o.node);
    if (found == index.end()) {
      std::vector<std::string> ids;
      for (const auto& n : cfg.nodes) ids.push_back(n.id);
      throw ConfigError("--set " + quote_token(o.node) + "." + quote_token(o.param) + ": no node '" + quote_token(o.node) +
                        "'" + did_you_mean(o.node, ids) + "; nodes: " + join_some(ids));
    }
    auto it = cfg.nodes.begin() + static_cast<std::ptrdiff_t>(found->second);
    Value val = load_yaml_string(o.value, "--set " + o.node + "." + o.param);
    if (it->params.kind != Value::Kind::Map) {
      it->params.kind = Value::Kind::Map;
    }
    // A dotted parameter reaches into a component-valued one: --set mtt.estimator.q=1 sets q in
    // the map under 'estimator'; an index reaches into a list: --set truth.segments[1].turn_rate=
    // '3 deg/s' sets a field of the second record, --set radar.position[2]=10 sets one element.
    // Every level but the last must already be in the file: an override changes what is there or
    // adds a parameter to a map, it never invents a list element.
    const std::string what = "--set " + quote_token(o.node) + "." + quote_token(o.param);
    const auto steps = parse_override_path(o.param, what);
    Value* target = &it->params;
    std::string reached = "node '" + quote_token(o.node) + "'";
    for (std::size_t k = 0; k < steps.size(); ++k) {
      const OverrideStep& step = steps[k];
      const bool last = k + 1 == steps.size();
      if (target->kind != Value::Kind::Map)
        throw ConfigError(what + ": " + reached + " is not a map of parameters (a dotted name reaches into a component or a record, e.g. --set mtt.estimator.q=1)",
                          target->loc, o.node);
      Value* inner = target->find(step.name);
      if (last && step.indices.empty()) {
        if (inner) {
          *inner = std::move(val);
        } else {
          target->entries.emplace_back(step.name, std::move(val));
          target->key_locs.push_back({"--set " + o.node + "." + o.param, 0, 0});
        }
        break;
      }
      if (!inner) {
        std::vector<std::string> keys;
        for (const auto& e : target->entries) keys.push_back(e.first);
        throw ConfigError(what + ": " + reached + " sets no '" + quote_token(step.name) + "' to reach into" +
                              did_you_mean(step.name, keys) + "; it sets: " + join_some(keys),
                          k == 0 ? it->loc : target->loc, o.node);
      }
      reached = "'" + quote_token(step.name) + "'";
      for (std::size_t index : step.indices) {
        if (inner->kind != Value::Kind::List)
          throw ConfigError(what + ": " + reached + " is " + inner->describe() + ", not a list to index", inner->loc, o.node);
        if (index >= inner->items.size())
          throw ConfigError(what + ": " + reached +
                                (inner->items.empty() ? std::string(" is an empty list")
                                 : " has " + std::to_string(inner->items.size()) + " element" +
                                       (inner->items.size() == 1 ? std::string(" (index 0)")
                                                                 : "s (indices 0 to " + std::to_string(inner->items.size() - 1) + ")")) +
                                ", so no [" + std::to_string(index) + "]",
                            inner->loc, o.node);
        inner = &inner->items[index];
        reached += "[" + std::to_string(index) + "]";
      }
      if (last) {
        *inner = std::move(val);
        break;
      }
      target = inner;
    }
  }

  if (const Value* ex = root.find("expect")) {
    if (ex->kind != Value::Kind::Map) throw ConfigError("'expect' must be a map of <node>.<metric>: {check}", ex->loc);
    for (size_t i = 0; i < ex->entries.size(); ++i) {
      const auto& [key, entry] = ex->entries[i];
      // A list of check maps puts several checks on one metric, e.g. an absolute bound and a
      // comparison: [{ max: 5 }, { less_than: baseline.position_rmse }].
      if (entry.kind == Value::Kind::List) {
        if (entry.items.empty()) throw ConfigError("expect '" + quote_token(key) + "': an empty list of checks", entry.loc);
        for (const Value& item : entry.items)
          for (auto& e : parse_expect(key, ex->key_locs[i], item)) cfg.expects.push_back(std::move(e));
      } else {
        for (auto& e : parse_expect(key, ex->key_locs[i], entry)) cfg.expects.push_back(std::move(e));
      }
    }
  }
  return cfg;
}

}  // namespace trackflow::host
