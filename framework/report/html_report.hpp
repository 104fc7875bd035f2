// Purpose: the self-contained HTML report of a run or a sweep: pipeline graph, summary, expect table and Vega-Lite plots, inlined for offline viewing.
#pragma once

#include <trackflow/host/engine.hpp>
#include <trackflow/host/report.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace trackflow::report {

struct RunReport {
  const host::Graph* graph = nullptr;  // as run (with the track and scene recorders, if any)
  const host::Outcome* outcome = nullptr;
  const std::vector<host::ExpectResult>* expects = nullptr;
  unsigned threads = 1;
  std::string command;                 // how the report was made, shown in its header
  std::string track_node;              // id of the sink.track node whose run is drawn ("" none)
  std::uint64_t track_run = 0;         // also the run of the scene drawn
  std::string scene_node;              // id of the sink.scene node whose run is drawn ("" none)
  std::vector<std::string> files;      // files written next to it (series CSV)
};

// One HTML document; the chart library is inlined, the data are inline JSON: no network.
std::string render_run_report(const RunReport& r);

struct SweepAxisView {
  std::string name;                 // node.param
  std::string unit;                 // SI unit of the numeric values ("" none)
  std::vector<std::string> text;    // per grid point, as written
  std::vector<double> value;        // per grid point in SI; NaN when not a number (a list, a choice)
};
struct SweepMetricView {
  std::string name;  // node.metric
  std::string unit;
  std::vector<double> value;  // per grid point
};
struct SweepReport {
  const host::Graph* graph = nullptr;  // of the first grid point
  std::uint64_t runs = 0;
  std::string command;
  std::vector<SweepAxisView> axes;
  std::vector<SweepMetricView> metrics;
  std::vector<std::string> files;
  bool zipped = false;  // --zip: the axes move together (point i takes the i-th value of each)
};

std::string render_sweep_report(const SweepReport& r);

// Writes `text` to `path` (folders created) through a temporary renamed into place
// (safe_output.hpp: a command-line path); ConfigError naming the path on failure.
void write_text_file(const std::string& path, const std::string& text);

}  // namespace trackflow::report
