// Purpose: writes the per-step series nodes publish (Summary::series) as CSV files with units in the header.
#pragma once

#include <trackflow/host/engine.hpp>

#include <string>
#include <vector>

namespace trackflow::report {

// Header "time_s,position_rmse_m,...", one row per step, empty cells for missing values.
void write_series_csv(const std::string& path, const Series& s);

// The file name of a node's series: "<node>.<series>.csv" with ':' turned into '-'
// ("score.ensemble.csv", "report_track.estimate-kf.csv").
std::string series_file_name(const std::string& node, const Series& s);

// Writes every series of every node into `dir` (created on demand); returns the paths.
std::vector<std::string> write_all_series(const std::string& dir, const host::Outcome& out);

}  // namespace trackflow::report
