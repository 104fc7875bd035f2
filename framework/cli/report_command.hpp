// Purpose: what `trackflow run --series/--report` and `trackflow report` add to a run: the track and scene recorder nodes and the report files.
#pragma once

#include <trackflow/host/config.hpp>
#include <trackflow/host/engine.hpp>
#include <trackflow/host/plugins.hpp>
#include <trackflow/host/report.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace trackflow::cli {

// Appends a sink.track node recording run `run` of every node that produces items; returns
// its id (unique in the pipeline). Nothing else in the pipeline changes: node seeds derive
// from their own ids, and the recorder is the last consumer of every stream.
std::string add_track_recorder(host::PipelineConfig& cfg, const host::PluginRegistry& reg, std::uint64_t run);

// For a pipeline with a tracker (a node producing track sets): appends a sink.scene node recording
// run `run` of every node that produces truth, scans or track sets, for the report's picture;
// returns its id, "" for a pipeline without a tracker. As harmless as the track recorder.
std::string add_scene_recorder(host::PipelineConfig& cfg, const host::PluginRegistry& reg, std::uint64_t run);

struct ReportRequest {
  std::string series_dir;  // write every node's series as CSV here ("" no)
  std::string html;        // write the HTML report here ("" no)
  std::string html_out;    // non-empty: `html` is the default <--out>/report.html, written beneath this folder
  std::string track_node;  // the recorder added by add_track_recorder ("" none)
  std::string scene_node;  // the recorder added by add_scene_recorder ("" none)
  std::uint64_t track_run = 0;
  std::string command;     // the command line, shown in the report
};

// Writes what `req` asks for; returns the paths written (printed by the caller).
std::vector<std::string> write_report_outputs(const ReportRequest& req, const host::Graph& g, const host::Outcome& out,
                                              const std::vector<host::ExpectResult>& expects, unsigned threads);

// argv joined with shell-style quoting where needed, for the report's header.
std::string command_line(int argc, char** argv);

}  // namespace trackflow::cli
