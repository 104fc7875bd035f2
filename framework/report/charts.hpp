// Purpose: Vega-Lite specifications of the report's plots (lines, bands, tracks, the pipeline graph), with the mark counts the browser test checks.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace trackflow::report {

using json = nlohmann::json;

// One plotted series; points with a non-finite x or y are left out.
struct Line {
  std::string label;
  std::vector<double> x, y;
};

// A finished plot: its Vega-Lite spec and what the browser must have drawn from it (one SVG
// path per line and per area, one symbol per point), so a test can tell an empty plot.
struct Chart {
  std::string title;
  std::string caption;  // one line under the plot
  json spec;
  int lines = 0;
  long line_points = 0;
  int areas = 0;
  long symbols = 0;
  std::vector<std::pair<std::string, std::string>> attributes;  // more data-* attributes of its element
};

// Series longer than this are thinned to every k-th point (the CSV keeps them all).
inline constexpr size_t kMaxPointsPerLine = 1500;

// y against x, one coloured line per series; y on a log scale when `log_y` and all values are positive.
Chart line_chart(const std::string& title, const std::string& x_title, const std::string& y_title,
                 const std::vector<Line>& lines, bool log_y = false);

// Values against time (one line per filter, on one scale) inside their shared two-sided band,
// shaded grey (ANEES, ANIS).
Chart band_chart(const std::string& title, const std::string& y_title, const std::vector<Line>& values,
                 const Line& band_lo, const Line& band_hi, const std::string& band_label);

// A path in a plane (ground track x-y, or altitude against time): `paths` drawn as lines in
// time order, `points` as small symbols (measurements); equal axis scales when `equal_axes`.
Chart track_chart(const std::string& title, const std::string& x_title, const std::string& y_title,
                  const std::vector<Line>& paths, const std::vector<Line>& points, bool equal_axes);

// The multi-target picture of one run in the x-y plane, at equal scales: each truth a black
// dashed line, each track a line in its own colour (track_colour of its id; its tentative
// positions pale), and the scan detections as dots, clutter grey and target-originated dark.
// Detections are drawn all (the recorder caps them), lines thinned as line_chart's.
struct TrackPath {
  std::uint64_t id = 0;
  Line confirmed;  // confirmed and coasting positions, in time order
  Line tentative;
};
struct SceneView {
  std::vector<Line> truths;  // one per target
  std::vector<TrackPath> tracks;
  Line clutter, target_detections;
};
Chart scene_chart(const std::string& title, const SceneView& v);

// A track's colour from a fixed palette of 10 by its id, the same in every report.
const char* track_colour(std::uint64_t id);

// The pipeline drawn as boxes and arrows; nodes as {id, type, kind, column, row}, edges as
// index pairs (dashed: an adapter's attachment).
struct GraphNodeView {
  std::string id, type, kind;
  int column = 0, row = 0;
};
struct GraphEdgeView {
  int from = 0, to = 0;
  bool attachment = false;
};
Chart graph_chart(const std::vector<GraphNodeView>& nodes, const std::vector<GraphEdgeView>& edges);

// The axis of a log scale: labels at 1, 2 and 5 times a power of ten only (the default labels
// every minor tick, and they overlap).
json log_axis();
// Rounds to 6 significant digits so the page stays small (the CSV files keep full precision).
double round6(double v);

}  // namespace trackflow::report
