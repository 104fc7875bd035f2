// Purpose: two outputs of one run naming one file are refused before anything runs: sinks' declared files, the report, series files, --metrics-json.
#pragma once

#include <trackflow/host/graph.hpp>

#include <string>

namespace trackflow::host {

// Two nodes declaring one file beneath --out (declare_output_file in output_path.hpp; their
// names compared lexically normalised: "a/../t.csv" is "t.csv"): a ConfigError naming both
// nodes and the file. build_graph calls it, so `validate` refuses it (issue 27).
void check_declared_outputs(const Graph& g);

// What a run writes besides the sinks' files.
struct RunOutputs {
  std::string out_dir;       // --out (or its default)
  bool series = false;       // --series: <node>.<series>.csv in out_dir for every node with series
  std::string report;        // the HTML report ("" none; the default is <out_dir>/report.html)
  std::string metrics_json;  // --metrics-json ("" none)
};

// A sink's file equal to the report, to --metrics-json, or to a series file name
// (<node id>.<anything>.csv at the top of --out, for a node of this pipeline: series names are
// known only after the runs, the node id before them), and the report equal to --metrics-json:
// a ConfigError naming both and the file; also a sink's path through a symlinked folder
// beneath --out (linked_folder_problem, safe_output.hpp). Paths are compared after resolving the symlinks of
// the folders that exist (a sink's folders beneath --out are never followed, safe_output.hpp).
void check_run_outputs(const Graph& g, const RunOutputs& o);

}  // namespace trackflow::host
