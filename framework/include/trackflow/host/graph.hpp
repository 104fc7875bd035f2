// Purpose: turns a parsed pipeline into a checked graph: types resolved, parameters validated, wiring typed, no cycles.
#pragma once

#include <trackflow/host/config.hpp>
#include <trackflow/host/plugins.hpp>
#include <trackflow/output_path.hpp>

#include <memory>
#include <string>
#include <vector>

namespace trackflow::host {

struct GraphNode {
  NodeConfig config;
  const RegisteredType* type = nullptr;
  Params params;
  std::vector<int> inputs;   // indices of upstream nodes, in `inputs:` order (= port numbers)
  std::vector<ItemMask> input_kinds;  // what each input delivers: upstream produces ∩ this accepts
  int attach_to = -1;        // adapters: index of the filter
};

struct Graph {
  PipelineConfig config;
  std::vector<GraphNode> nodes;
  std::vector<int> order;    // topological: every node after its inputs
  std::vector<DeclaredOutput> outputs;  // the files the nodes declared at construction (output_path.hpp)
  // Valid but seldom meant ("file:line:col: node 'n': parameter 'p' = ... is valid but
  // implausible: ..."): a declaration's plausible range and the plugins' Params::warn, each once.
  std::vector<std::string> warnings;
};

// Collects nothing silently: the first problem is thrown as a ConfigError naming file:line:col
// and the node id. Also instantiates each component once so plugin-side checks run now.
Graph build_graph(PipelineConfig cfg, const PluginRegistry& registry);

// "unknown type 'x' (did you mean 'y'?). Available: ... Searched: ..." plus plugin load problems.
std::string unknown_type_message(const std::string& type, const PluginRegistry& registry);

// One instantiated copy of the graph (one per worker thread).
struct GraphInstance {
  std::vector<std::shared_ptr<Component>> components;  // by node index
  std::vector<std::vector<Link>> links;                 // by node index
  std::vector<int> roots;                               // generator nodes
  std::vector<int> time_grouping;                       // nodes with groups_by_time, upstream first
};
GraphInstance instantiate(const Graph& g, const PluginRegistry& registry);

}  // namespace trackflow::host
