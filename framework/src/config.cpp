// Purpose: YAML loading into a located value tree and parsing of the pipeline's top-level structure.
#include <trackflow/host/config.hpp>
#include <trackflow/host/suggest.hpp>

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace trackflow::host {
namespace {

SourceLoc loc_of(const YAML::Mark& m, const std::string& file) {
  if (m.line < 0) return {file, 0, 0};
  return {file, m.line + 1, m.column + 1};
}

Value convert(const YAML::Node& n, const std::string& file) {
  Value v;
  v.loc = loc_of(n.Mark(), file);
  switch (n.Type()) {
    case YAML::NodeType::Null:
    case YAML::NodeType::Undefined:
      v.kind = Value::Kind::Null;
      break;
    case YAML::NodeType::Scalar:
      v.kind = Value::Kind::Scalar;
      v.scalar = n.Scalar();
      break;
    case YAML::NodeType::Sequence:
      v.kind = Value::Kind::List;
      for (const auto& item : n) v.items.push_back(convert(item, file));
      break;
    case YAML::NodeType::Map:
      v.kind = Value::Kind::Map;
      for (const auto& kv : n) {
        const std::string key = kv.first.Scalar();
        const SourceLoc kl = loc_of(kv.first.Mark(), file);
        if (v.find(key))
          throw ConfigError("duplicate key '" + key + "' (first at " + v.key_loc(key).str() + ")", kl);
        v.entries.emplace_back(key, convert(kv.second, file));
        v.key_locs.push_back(kl);
      }
      break;
  }
  return v;
}

Value parse_text(const std::string& text, const std::string& name) {
  try {
    return convert(YAML::Load(text), name);
  } catch (const YAML::Exception& e) {
    throw ConfigError("YAML syntax error: " + e.msg, loc_of(e.mark, name));
  }
}

const std::string& scalar(const Value& v, const std::string& what) {
  if (!v.is_scalar()) throw ConfigError(what + " must be a single value, got " + v.describe(), v.loc);
  return v.scalar;
}

std::uint64_t to_count(const Value& v, const std::string& what) {
  const std::string& s = scalar(v, what);
  try {
    size_t used = 0;
    const long long n = std::stoll(s, &used);
    if (used == s.size() && n >= 0) return static_cast<std::uint64_t>(n);
  } catch (const std::exception&) {
  }
  throw ConfigError(what + " must be a non-negative whole number, got '" + s + "'", v.loc);
}

void reject_unknown_keys(const Value& map, const std::vector<std::string>& known, const std::string& where,
                         const std::string& node = {}) {
  for (size_t i = 0; i < map.entries.size(); ++i) {
    const auto& key = map.entries[i].first;
    if (std::find(known.begin(), known.end(), key) == known.end())
      throw ConfigError("unknown key '" + key + "' in " + where + did_you_mean(key, known) +
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
  if (n.id.empty() || n.id.find_first_of(". =") != std::string::npos)
    throw ConfigError("node id '" + n.id + "' must be non-empty and contain no '.', '=' or space", id->loc);
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

ExpectConfig parse_expect(const std::string& key, const SourceLoc& key_loc, const Value& v) {
  ExpectConfig e;
  e.loc = key_loc;
  const auto dot = key.find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == key.size())
    throw ConfigError("expect key '" + key + "' must be <node id>.<metric>", key_loc);
  e.node = key.substr(0, dot);
  e.metric = key.substr(dot + 1);
  if (v.kind != Value::Kind::Map || v.entries.empty())
    throw ConfigError("expect '" + key + "' must be a map such as { max: 25 } or { within_band: 0.95 }, or a list of them", v.loc);
  static const std::vector<std::string> ops = {"min",       "max",       "within_band",  "outside_band", "equals",
                                               "tolerance", "less_than", "greater_than", "ratio_to"};
  reject_unknown_keys(v, ops, "expect '" + key + "'");
  // One check per entry would need a list; the usual {min, max} pair is split by the caller.
  // With ratio_to, min/max bound metric / reference.
  if (const Value* r = v.find("ratio_to")) {
    const std::string ref = scalar(*r, "ratio_to");
    const auto d = ref.find('.');
    if (d == std::string::npos || d == 0 || d + 1 == ref.size())
      throw ConfigError("expect '" + key + "': 'ratio_to' needs <node id>.<metric>, got '" + ref + "'", r->loc);
    if (!v.find("min") && !v.find("max"))
      throw ConfigError("expect '" + key + "': 'ratio_to' needs 'min' and/or 'max' bounds for the ratio", r->loc);
    e.ref_node = ref.substr(0, d);
    e.ref_metric = ref.substr(d + 1);
  }
  for (size_t i = 0; i < v.entries.size(); ++i) {
    const auto& [op, val] = v.entries[i];
    if (op == "tolerance" || op == "ratio_to") continue;
    if (op == "less_than" || op == "greater_than") {
      const std::string ref = scalar(val, op);
      const auto d = ref.find('.');
      if (d == std::string::npos || d == 0 || d + 1 == ref.size())
        throw ConfigError("expect '" + key + "': '" + op + "' needs <node id>.<metric>, got '" + ref + "'", val.loc);
      e.op = op;
      e.ref_node = ref.substr(0, d);
      e.ref_metric = ref.substr(d + 1);
      continue;
    }
    try {
      e.op = e.ref_node.empty() || (op != "min" && op != "max") ? op : "ratio_" + op;
      e.value = std::stod(scalar(val, op));
    } catch (const ConfigError&) {
      throw;
    } catch (const std::exception&) {
      throw ConfigError("expect '" + key + "': '" + op + "' needs a number, got '" + val.scalar + "'", val.loc);
    }
  }
  if (const Value* t = v.find("tolerance")) e.tolerance = std::stod(scalar(*t, "tolerance"));
  return e;
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
    case Kind::Scalar: return "'" + scalar + "'";
    case Kind::List: return "a list";
    case Kind::Map: return "a map";
  }
  return "?";
}

Value load_yaml_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError("cannot open pipeline file '" + path + "'");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_text(ss.str(), path);
}

Value load_yaml_string(const std::string& text, const std::string& name) { return parse_text(text, name); }

Override parse_override(const std::string& text) {
  const auto eq = text.find('=');
  const auto dot = text.find('.');
  if (eq == std::string::npos || dot == std::string::npos || dot > eq || dot == 0 || dot + 1 == eq)
    throw ConfigError("--set '" + text + "' must look like node.param=value");
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
    if (const Value* v = p->find("name")) cfg.name = scalar(*v, "name");
    if (const Value* v = p->find("description")) cfg.description = scalar(*v, "description");
    if (const Value* v = p->find("seed")) cfg.seed = to_count(*v, "seed");
    if (const Value* v = p->find("runs")) {
      cfg.runs = to_count(*v, "runs");
      if (cfg.runs == 0) throw ConfigError("runs must be at least 1", v->loc);
    }
    if (const Value* v = p->find("on_bad_row")) {
      cfg.on_bad_row = scalar(*v, "on_bad_row");
      if (cfg.on_bad_row != "error" && cfg.on_bad_row != "skip")
        throw ConfigError("on_bad_row must be 'error' or 'skip', got '" + cfg.on_bad_row + "'", v->loc);
    }
    if (const Value* v = p->find("plugin_paths")) add_paths(*v);
    if (const Value* v = p->find("frame_origin")) {
      scalar(*v, "frame_origin");
      cfg.frame_origin = *v;
    }
    if (const Value* v = p->find("file_format")) {
      if (scalar(*v, "file_format") != "1")
        throw ConfigError("file_format " + v->scalar + " is not supported by this trackflow (supports 1)", v->loc);
    }
  } else {
    throw ConfigError("missing 'pipeline:' section (name, seed, runs)", root.loc);
  }
  if (cfg.name.empty()) cfg.name = std::filesystem::path(file).stem().string();
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
      throw ConfigError("frame_origin '" + cfg.frame_origin.scalar +
                            "' names a site, but the pipeline has no 'sites:' section",
                        cfg.frame_origin.loc);
    if (std::find(names.begin(), names.end(), cfg.frame_origin.scalar) == names.end())
      throw ConfigError("frame_origin '" + cfg.frame_origin.scalar + "' is not a site" +
                            did_you_mean(cfg.frame_origin.scalar, names) + "; sites: " + join(names),
                        cfg.frame_origin.loc);
  }
  if (const Value* v = root.find("plugin_paths")) add_paths(*v);

  const Value* nodes = root.find("nodes");
  if (!nodes || nodes->kind != Value::Kind::List || nodes->items.empty())
    throw ConfigError("'nodes' must be a non-empty list", nodes ? nodes->loc : root.loc);
  for (const auto& n : nodes->items) {
    NodeConfig node = parse_node(n);
    for (const auto& other : cfg.nodes)
      if (other.id == node.id)
        throw ConfigError("duplicate node id '" + node.id + "' (first defined at " + other.loc.str() + ")", node.loc,
                          node.id);
    cfg.nodes.push_back(std::move(node));
  }

  for (const auto& o : overrides) {
    auto it = std::find_if(cfg.nodes.begin(), cfg.nodes.end(), [&](const NodeConfig& n) { return n.id == o.node; });
    if (it == cfg.nodes.end()) {
      std::vector<std::string> ids;
      for (const auto& n : cfg.nodes) ids.push_back(n.id);
      throw ConfigError("--set " + o.node + "." + o.param + ": no node '" + o.node + "'" + did_you_mean(o.node, ids) +
                        "; nodes: " + join(ids));
    }
    Value val = load_yaml_string(o.value, "--set " + o.node + "." + o.param);
    if (it->params.kind != Value::Kind::Map) {
      it->params.kind = Value::Kind::Map;
    }
    if (Value* existing = it->params.find(o.param)) {
      *existing = std::move(val);
    } else {
      it->params.entries.emplace_back(o.param, std::move(val));
      it->params.key_locs.push_back({"--set " + o.node + "." + o.param, 0, 0});
    }
  }

  if (const Value* ex = root.find("expect")) {
    if (ex->kind != Value::Kind::Map) throw ConfigError("'expect' must be a map of <node>.<metric>: {check}", ex->loc);
    for (size_t i = 0; i < ex->entries.size(); ++i) {
      const auto& [key, entry] = ex->entries[i];
      // A list of check maps puts several checks on one metric, e.g. an absolute bound and a
      // comparison: [{ max: 5 }, { less_than: baseline.position_rmse }].
      std::vector<const Value*> checks;
      if (entry.kind == Value::Kind::List) {
        if (entry.items.empty())
          throw ConfigError("expect '" + key + "': an empty list of checks", entry.loc);
        for (const Value& item : entry.items) checks.push_back(&item);
      } else {
        checks.push_back(&entry);
      }
      for (const Value* check : checks) {
        const Value& val = *check;
        // { min: a, max: b, less_than: x.y } is one check per comparison, each checked (tolerance
        // goes with equals, ratio_to with min and max).
        int comparisons = 0;
        if (val.kind == Value::Kind::Map)
          for (const auto& [op, unused] : val.entries) comparisons += op != "tolerance" && op != "ratio_to";
        if (comparisons <= 1) {
          cfg.expects.push_back(parse_expect(key, ex->key_locs[i], val));
          continue;
        }
        for (const auto& [op, opval] : val.entries) {
          if (op == "tolerance" || op == "ratio_to") continue;
          Value one;
          one.kind = Value::Kind::Map;
          one.loc = val.loc;
          one.entries.emplace_back(op, opval);
          one.key_locs.push_back(val.key_loc(op));
          const char* companion = op == "equals" ? "tolerance" : (op == "min" || op == "max") ? "ratio_to" : nullptr;
          if (const Value* c = companion ? val.find(companion) : nullptr) {
            one.entries.emplace_back(companion, *c);
            one.key_locs.push_back(val.key_loc(companion));
          }
          cfg.expects.push_back(parse_expect(key, ex->key_locs[i], one));
        }
      }
    }
  }
  return cfg;
}

}  // namespace trackflow::host
