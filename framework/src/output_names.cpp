// Purpose: the collision checks of output_names.hpp: every file of one run named by one output only.
#include <trackflow/host/output_names.hpp>

#include <trackflow/error.hpp>
#include <trackflow/host/suggest.hpp>
#include <trackflow/safe_output.hpp>

#include <filesystem>
#include <optional>
#include <vector>

namespace trackflow::host {
namespace fs = std::filesystem;

namespace {

const GraphNode* node_of(const Graph& g, const std::string& id) {
  for (const auto& n : g.nodes)
    if (n.config.id == id) return &n;
  return nullptr;
}

[[noreturn]] void refuse(const Graph& g, const std::string& node, const std::string& text) {
  const GraphNode* n = node_of(g, node);
  throw ConfigError(text, n ? n->config.loc : SourceLoc{}, n ? node : std::string());
}

// An absolute path with the symlinks of its existing folders resolved, for comparing.
std::string resolved(const fs::path& p) {
  std::error_code ec;
  fs::path a = fs::absolute(p, ec);
  if (ec) a = p;
  fs::path w = fs::weakly_canonical(a, ec);
  return (ec ? a.lexically_normal() : w).string();
}

// The node whose series files `name` (a file name at the top of --out) may be: series files
// are <node id>.<series>.csv and node ids hold no '.'.
std::optional<std::string> series_owner(const Graph& g, const std::string& name) {
  const size_t dot = name.find('.');
  if (dot == std::string::npos || name.size() < 4 || name.compare(name.size() - 4, 4, ".csv") != 0 ||
      name.find('.', dot + 1) == std::string::npos)
    return std::nullopt;
  const std::string id = name.substr(0, dot);
  if (!node_of(g, id)) return std::nullopt;
  return id;
}

}  // namespace

void check_declared_outputs(const Graph& g) {
  std::vector<std::string> names;
  for (const auto& d : g.outputs) names.push_back(fs::path(d.file).lexically_normal().string());
  for (size_t i = 0; i < g.outputs.size(); ++i)
    for (size_t j = 0; j < i; ++j) {
      if (names[i] != names[j] || g.outputs[i].node == g.outputs[j].node) continue;
      refuse(g, g.outputs[i].node,
             "nodes '" + g.outputs[j].node + "' and '" + g.outputs[i].node + "' both write '" +
                 quote_token(names[i], 300) + "' under --out; give one of them another 'path'");
    }
}

void check_run_outputs(const Graph& g, const RunOutputs& o) {
  const fs::path out = o.out_dir.empty() ? fs::path(".") : fs::path(o.out_dir);
  const std::string out_resolved = resolved(out);
  struct Named {
    std::string what, path;
  };
  std::vector<Named> cli;
  if (!o.report.empty()) cli.push_back({"the report", resolved(o.report)});
  if (!o.metrics_json.empty()) cli.push_back({"--metrics-json", resolved(o.metrics_json)});
  if (cli.size() == 2 && cli[0].path == cli[1].path)
    throw ConfigError("--report and --metrics-json both name '" + quote_token(o.report, 300) + "'; give them different files");
  for (const auto& d : g.outputs) {
    const fs::path rel = fs::path(d.file).lexically_normal();
    const std::string file = (fs::path(out_resolved) / rel).lexically_normal().string();
    const std::string shown = (out / rel).string();
    // A symlinked folder on the way (out/<name>/sub -> ..) is refused now, not after run 0
    // (SafeOutputFile refuses it again when the file is opened).
    if (!rel.has_root_path() && rel.parent_path().has_filename() && *rel.begin() != "..")
      if (std::string why = linked_folder_problem(out.string(), rel.parent_path().string()); !why.empty())
        refuse(g, d.node, "cannot write '" + quote_token(shown, 300) + "': " + why);
    for (const auto& c : cli)
      if (c.path == file)
        refuse(g, d.node, "its file '" + quote_token(shown, 300) + "' is also the file of " + c.what +
                              "; give one of them another name");
    if (!o.series || fs::path(file).parent_path() != fs::path(out_resolved)) continue;
    if (auto owner = series_owner(g, rel.filename().string()))
      refuse(g, d.node, "its file '" + quote_token(shown, 300) + "' is a name of the series files of node '" + *owner +
                            "' (--series writes <node>.<series>.csv into --out); give it another 'path'");
  }
  // The report or --metrics-json at the top of --out under a series file's name.
  if (o.series)
    for (const auto& c : cli)
      if (fs::path(c.path).parent_path() == fs::path(out_resolved))
        if (auto owner = series_owner(g, fs::path(c.path).filename().string()))
          throw ConfigError(c.what + " '" + quote_token(c.path, 300) + "' is a name of the series files of node '" + *owner +
                            "' (--series writes <node>.<series>.csv into --out); choose another file");
}

}  // namespace trackflow::host
