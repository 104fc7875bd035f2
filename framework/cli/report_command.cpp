// Purpose: the track and scene recorder nodes, the series CSV files and the HTML report of `run --series/--report` and `report`.
#include "report_command.hpp"

#include "html_report.hpp"
#include "series_csv.hpp"

#include <trackflow/safe_output.hpp>

#include <filesystem>

namespace trackflow::cli {

namespace {

// A recorder node of `type` with id `base` (or base_2, base_3, ... when taken), recording run `run`.
host::NodeConfig recorder_node(const host::PipelineConfig& cfg, const std::string& base, const std::string& type,
                               std::uint64_t run) {
  std::string id = base;
  auto taken = [&](const std::string& s) {
    for (const auto& n : cfg.nodes)
      if (n.id == s) return true;
    return false;
  };
  for (int k = 2; taken(id); ++k) id = base + "_" + std::to_string(k);
  host::NodeConfig n;
  n.id = id;
  n.type = type;
  n.params.kind = host::Value::Kind::Map;
  host::Value v;
  v.kind = host::Value::Kind::Scalar;
  v.scalar = std::to_string(run);
  n.params.entries.push_back({"run", v});
  n.params.key_locs.push_back({});
  return n;
}

// Wires into `n` every node (no adapter) producing something `recorder` takes.
void wire_producers(host::NodeConfig& n, const host::PipelineConfig& cfg, const host::PluginRegistry& reg,
                    const host::RegisteredType& recorder) {
  for (const auto& other : cfg.nodes) {
    const auto* t = reg.find(other.type);
    if (!t || (t->decl.produces & recorder.decl.accepts) == 0 || t->decl.kind == ComponentKind::Adapter) continue;
    n.inputs.push_back(other.id);
    n.input_locs.push_back(other.loc);
  }
}

// Whether any of `n`'s inputs produces one of `kinds`.
bool fed_with(const host::NodeConfig& n, const host::PipelineConfig& cfg, const host::PluginRegistry& reg, ItemMask kinds) {
  for (const auto& id : n.inputs)
    for (const auto& other : cfg.nodes)
      if (other.id == id)
        if (const auto* t = reg.find(other.type))
          if (t->decl.produces & kinds) return true;
  return false;
}

}  // namespace

std::string add_track_recorder(host::PipelineConfig& cfg, const host::PluginRegistry& reg, std::uint64_t run) {
  const auto* recorder = reg.find("sink.track");
  if (!recorder) return {};
  host::NodeConfig n = recorder_node(cfg, "report_track", "sink.track", run);
  // Only what the recorder takes (truth, measurements, estimates): a tracker's track sets are
  // not one track, and wiring them in would be refused.
  wire_producers(n, cfg, reg, *recorder);
  // Truth alone (a multi-target scenario feeding trackers) is no track to draw: its targets would
  // be joined into one line.
  if (n.inputs.empty() || !fed_with(n, cfg, reg, mask(ItemKind::Estimate) | mask(ItemKind::Measurement))) return {};
  std::string id = n.id;
  cfg.nodes.push_back(std::move(n));
  return id;
}

std::string add_scene_recorder(host::PipelineConfig& cfg, const host::PluginRegistry& reg, std::uint64_t run) {
  const auto* recorder = reg.find("sink.scene");
  if (!recorder) return {};
  host::NodeConfig n = recorder_node(cfg, "report_scene", "sink.scene", run);
  wire_producers(n, cfg, reg, *recorder);
  // Without a tracker there is no multi-target picture (a single-target pipeline has its track plot).
  if (!fed_with(n, cfg, reg, mask(ItemKind::Tracks))) return {};
  std::string id = n.id;
  cfg.nodes.push_back(std::move(n));
  return id;
}

std::vector<std::string> write_report_outputs(const ReportRequest& req, const host::Graph& g, const host::Outcome& out,
                                              const std::vector<host::ExpectResult>& expects, unsigned threads) {
  std::vector<std::string> files;
  if (!req.series_dir.empty()) files = report::write_all_series(req.series_dir, out);
  if (!req.html.empty()) {
    report::RunReport r;
    r.graph = &g;
    r.outcome = &out;
    r.expects = &expects;
    r.threads = threads;
    r.command = req.command;
    r.track_node = req.track_node;
    r.scene_node = req.scene_node;
    r.track_run = req.track_run;
    r.files = files;
    // The default name beneath --out is written as a sink's file is (no symlink followed there).
    if (!req.html_out.empty()) write_file_beneath(req.html_out, "report.html", report::render_run_report(r));
    else report::write_text_file(req.html, report::render_run_report(r));
    files.push_back(req.html);
  }
  return files;
}

std::string command_line(int argc, char** argv) {
  std::string s = "trackflow";
  for (int i = 0; i < argc; ++i) {
    std::string a = argv[i];
    if (a.find_first_of(" \"'$") != std::string::npos) a = "'" + a + "'";
    s += " " + a;
  }
  return s;
}

}  // namespace trackflow::cli
