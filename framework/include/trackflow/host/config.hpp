// Purpose: the analyst's pipeline file as a located value tree and its parsed top-level structure.
#pragma once

#include <trackflow/error.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace trackflow::host {

// YAML reduced to what trackflow needs, every node remembering where it was written.
struct Value {
  enum class Kind { Null, Scalar, List, Map };
  Kind kind = Kind::Null;
  std::string scalar;
  std::vector<Value> items;
  std::vector<std::pair<std::string, Value>> entries;  // map, in file order
  std::vector<SourceLoc> key_locs;                      // location of each map key
  SourceLoc loc;

  const Value* find(const std::string& key) const;
  Value* find(const std::string& key);
  SourceLoc key_loc(const std::string& key) const;
  bool is_scalar() const { return kind == Kind::Scalar; }
  std::string describe() const;  // "a map", "a list", "'abc'"

  // Out of line (config.cpp): inline ones would instantiate std::pair<std::string, Value>
  // while Value is incomplete, which clang refuses.
  Value();
  Value(const Value&);
  Value(Value&&) noexcept;
  Value& operator=(const Value&);
  Value& operator=(Value&&) noexcept;
  ~Value();
};

// Limits on what a pipeline file may ask of the loader, so a hostile or broken file ends in a
// clear error rather than exhausting memory or the stack (docs/pipeline-yaml.md, "Limits").
inline constexpr std::size_t kMaxYamlBytes = 2u << 20;   // 2 MiB of YAML text
inline constexpr std::size_t kMaxYamlValues = 250'000;   // values after alias expansion
inline constexpr std::size_t kMaxYamlDepth = 64;         // nesting of lists and maps
inline constexpr std::size_t kMaxNodes = 10'000;         // nodes in one pipeline

Value load_yaml_file(const std::string& path);
Value load_yaml_string(const std::string& text, const std::string& name);

struct NodeConfig {
  std::string id;
  std::string type;
  std::vector<std::string> inputs;
  std::vector<SourceLoc> input_locs;
  std::string attach_to;  // adapters: the filter they retune
  SourceLoc attach_loc;
  Value params;           // Map or Null
  SourceLoc loc;          // the node's "- id:" line
  SourceLoc type_loc;
};

struct ExpectConfig {
  std::string node;
  std::string metric;
  // min, max, within_band, outside_band, equals (with tolerance): against `value`;
  // less_than, greater_than: against another metric `ref_node`.`ref_metric`.
  std::string op;
  double value = 0;
  double tolerance = 0;
  std::string ref_node, ref_metric;
  SourceLoc loc;
};

struct PipelineConfig {
  std::string file;  // path as given
  std::string name;
  std::string description;
  std::uint64_t seed = 1;
  std::uint64_t runs = 1;
  std::string on_bad_row = "error";
  std::vector<std::string> plugin_paths;  // resolved relative to the file
  SourceLoc plugin_paths_loc;             // where the file asks for them (refused unless trusted)
  std::vector<NodeConfig> nodes;
  std::vector<ExpectConfig> expects;
  // Top-level `sites:` (name -> {latitude, longitude, height}) as a list of records, each with its
  // `name`; given to every node that declares a `sites` parameter (and does not set its own).
  Value sites;
  // `pipeline.frame_origin`: the site the pipeline's ENU frame is anchored at; given to every
  // node that declares a `frame_origin` parameter. Empty: none.
  Value frame_origin;
};

// A `--set node.param=value` override, applied to the tree before validation.
struct Override {
  std::string node, param, value;
};
Override parse_override(const std::string& text);

// Reads the structure (not the parameters: those are validated against each component's
// declaration later). Throws ConfigError with file:line:col.
PipelineConfig parse_pipeline(const Value& root, const std::string& file,
                              const std::vector<Override>& overrides = {});

}  // namespace trackflow::host
