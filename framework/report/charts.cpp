// Purpose: Vega-Lite specs of the report's plots, built as JSON values.
#include "charts.hpp"

#include <trackflow/number_text.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <string>

namespace trackflow::report {
namespace {

constexpr int kWidth = 860, kHeight = 260;

// Labels of a log axis at 1, 2 and 5 times a power of ten only.
constexpr const char* kLogLabels =
    "indexof([1, 2, 5], round(datum.value / pow(10, floor(log(datum.value) / LN10)))) >= 0 ? datum.label : ''";

size_t stride_for(size_t n, size_t max_points = kMaxPointsPerLine) {
  return n <= max_points ? 1 : (n + max_points - 1) / max_points;
}

json base_spec(const std::string& title) {
  return {{"$schema", "https://vega.github.io/schema/vega-lite/v6.json"},
          {"title", title},
          {"width", kWidth},
          {"height", kHeight},
          {"config", {{"font", "sans-serif"}, {"legend", {{"orient", "top"}, {"labelLimit", 320}}}}}};
}

// Appends the finite points of `line` to `values` as {x, y, s[, o]}, thinned to at most
// `max_points`; returns how many.
long append_points(json& values, const Line& line, const std::vector<double>* order = nullptr,
                   size_t max_points = kMaxPointsPerLine) {
  long n = 0;
  const size_t step = stride_for(line.x.size(), max_points);
  for (size_t i = 0; i < line.x.size() && i < line.y.size(); i += step) {
    if (!std::isfinite(line.x[i]) || !std::isfinite(line.y[i])) continue;
    json p = {{"x", round6(line.x[i])}, {"y", round6(line.y[i])}, {"s", line.label}};
    if (order && i < order->size()) p["o"] = (*order)[i];
    values.push_back(std::move(p));
    ++n;
  }
  return n;
}

json labels(const std::vector<Line>& lines) {
  json d = json::array();
  for (const auto& l : lines) d.push_back(l.label);
  return d;
}

bool all_positive(const std::vector<Line>& lines) {
  bool any = false;
  for (const auto& l : lines)
    for (double v : l.y)
      if (std::isfinite(v)) {
        if (v <= 0) return false;
        any = true;
      }
  return any;
}

// The x and y scales of a picture in a plane, and its height. With `equal_axes`: the same metres
// per pixel on both axes, so the geometry is not distorted -- unless the points are much longer
// than wide (a straight approach would be a flat line), when each axis gets its own scale; the
// caption says which.
struct PlaneScales {
  json x = {{"zero", false}}, y = {{"zero", false}};
  int height = kHeight;
  std::string caption;
};

PlaneScales plane_scales(const std::vector<const Line*>& lines, bool equal_axes) {
  PlaneScales s;
  if (!equal_axes) return s;
  const int width = kWidth;
  s.height = 420;
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const Line* l : lines)
    for (size_t i = 0; i < l->x.size() && i < l->y.size(); ++i)
      if (std::isfinite(l->x[i]) && std::isfinite(l->y[i])) {
        x0 = std::min(x0, l->x[i]);
        x1 = std::max(x1, l->x[i]);
        y0 = std::min(y0, l->y[i]);
        y1 = std::max(y1, l->y[i]);
      }
  const double sx = std::max(x1 - x0, 1.0), sy = std::max(y1 - y0, 1.0);
  if (std::isfinite(x0) && std::isfinite(y0) && std::max(sx / sy, sy / sx) > 8.0) {
    s.caption = "axes scaled independently (the track is " + std::to_string(static_cast<long>(std::max(sx, sy))) +
                " m long and " + std::to_string(static_cast<long>(std::min(sx, sy))) + " m wide)";
    s.height = kHeight + 60;
  } else if (std::isfinite(x0) && std::isfinite(y0)) {
    s.caption = "equal scales on both axes";
    const double per_px = std::max(sx / width, sy / s.height) * 1.05;
    const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
    s.x["domain"] = {round6(cx - per_px * width / 2), round6(cx + per_px * width / 2)};
    s.y["domain"] = {round6(cy - per_px * s.height / 2), round6(cy + per_px * s.height / 2)};
  }
  return s;
}

}  // namespace

json log_axis() { return {{"labelExpr", kLogLabels}}; }

double round6(double v) {
  if (!std::isfinite(v) || v == 0.0) return v;
  // Shorter than 16 characters: the string stays in its own small buffer, no allocation.
  const std::string text = number_text::general(v, 6);
  double rounded = v;
  std::from_chars(text.data(), text.data() + text.size(), rounded);  // correctly rounded, as strtod
  return rounded;
}

Chart line_chart(const std::string& title, const std::string& x_title, const std::string& y_title,
                 const std::vector<Line>& lines, bool log_y) {
  Chart c;
  c.title = title;
  json values = json::array();
  for (const auto& l : lines) {
    const long n = append_points(values, l);
    if (n > 0) {
      ++c.lines;
      c.line_points += n;
    }
  }
  const bool log = log_y && all_positive(lines);
  c.spec = base_spec(title);
  c.spec["data"] = {{"values", values}};
  c.spec["mark"] = {{"type", "line"}, {"strokeWidth", 1.4}, {"clip", true}};
  c.spec["params"] = json::array({{{"name", "zoom"}, {"select", "interval"}, {"bind", "scales"}}});
  c.spec["encoding"] = {
      {"x", {{"field", "x"}, {"type", "quantitative"}, {"title", x_title}}},
      {"y", {{"field", "y"}, {"type", "quantitative"}, {"title", y_title}, {"scale", {{"type", log ? "log" : "linear"}, {"zero", false}}},
             {"axis", log ? log_axis() : json::object()}}},
      {"color", {{"field", "s"}, {"type", "nominal"}, {"title", nullptr}, {"scale", {{"domain", labels(lines)}}}}}};
  return c;
}

Chart band_chart(const std::string& title, const std::string& y_title, const std::vector<Line>& values_in,
                 const Line& band_lo, const Line& band_hi, const std::string& band_label) {
  Chart c;
  c.title = title;
  json band = json::array();
  const size_t step = stride_for(band_lo.x.size());
  for (size_t i = 0; i < band_lo.x.size() && i < band_hi.y.size(); i += step) {
    if (!std::isfinite(band_lo.x[i]) || !std::isfinite(band_lo.y[i]) || !std::isfinite(band_hi.y[i])) continue;
    band.push_back({{"x", round6(band_lo.x[i])}, {"lo", round6(band_lo.y[i])}, {"hi", round6(band_hi.y[i])}});
  }
  json values = json::array();
  for (const auto& v : values_in) {
    const long n = append_points(values, v);
    if (n > 0) {
      ++c.lines;
      c.line_points += n;
    }
  }
  c.areas = band.empty() ? 0 : 1;
  // A log scale when a value leaves the band by far (an inconsistent filter), so both show.
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  for (const auto& v : values) {
    lo = std::min(lo, v["y"].get<double>());
    hi = std::max(hi, v["y"].get<double>());
  }
  for (const auto& b : band) {
    lo = std::min(lo, b["lo"].get<double>());
    hi = std::max(hi, b["hi"].get<double>());
  }
  const bool log = lo > 0.0 && hi / lo > 20.0;
  json yscale = {{"type", log ? "log" : "linear"}, {"zero", false}};
  json yaxis = json::object();
  // A log axis labels only 1-2-5 steps: the default labels every minor tick and they overlap.
  if (log) yaxis = log_axis();
  c.spec = base_spec(title);
  c.spec["layer"] = json::array(
      // The band in grey: the filters' lines take the palette's colours, the first of them blue.
      {{{"data", {{"values", band}}},
        {"mark", {{"type", "area"}, {"opacity", 0.35}, {"color", "#bbbbbb"}, {"clip", true}}},
        {"encoding",
         {{"x", {{"field", "x"}, {"type", "quantitative"}, {"title", "time [s]"}}},
          {"y", {{"field", "lo"}, {"type", "quantitative"}, {"title", y_title}, {"scale", yscale}, {"axis", yaxis}}},
          {"y2", {{"field", "hi"}}}}}},
       {{"data", {{"values", values}}},
        {"mark", {{"type", "line"}, {"strokeWidth", 1.4}, {"clip", true}}},
        {"params", json::array({{{"name", "zoom"}, {"select", "interval"}, {"bind", "scales"}}})},
        {"encoding",
         {{"x", {{"field", "x"}, {"type", "quantitative"}}},
          {"y", {{"field", "y"}, {"type", "quantitative"}, {"scale", yscale}}},
          {"color", {{"field", "s"}, {"type", "nominal"}, {"title", nullptr}, {"scale", {{"domain", labels(values_in)}}}}}}}}});
  c.caption = "grey: " + band_label;
  return c;
}

Chart track_chart(const std::string& title, const std::string& x_title, const std::string& y_title,
                  const std::vector<Line>& paths, const std::vector<Line>& points, bool equal_axes) {
  Chart c;
  c.title = title;
  json line_values = json::array(), point_values = json::array();
  for (const auto& l : paths) {
    // Draw in time order even when x is not monotonic (a ground track): "o" is the sample index.
    std::vector<double> order(l.x.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<double>(i);
    const long n = append_points(line_values, l, &order);
    if (n > 0) {
      ++c.lines;
      c.line_points += n;
    }
  }
  for (const auto& p : points) c.symbols += append_points(point_values, p);
  std::vector<Line> all = points;
  all.insert(all.end(), paths.begin(), paths.end());
  std::vector<const Line*> drawn;
  for (const auto& l : all) drawn.push_back(&l);
  const PlaneScales scales = plane_scales(drawn, equal_axes);
  const json& xscale = scales.x;
  const json& yscale = scales.y;
  const int width = kWidth, height = scales.height;
  c.caption = scales.caption;
  json domain = labels(all);
  // Truth in black, measurements in light colours (visible, yet behind the lines), estimates in
  // strong ones.
  const char* pale[] = {"#6baed6", "#969696", "#fdae6b", "#74c476"};
  const char* strong[] = {"#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2"};
  json range = json::array();
  size_t np = 0, ns = 0;
  for (size_t i = 0; i < points.size(); ++i) range.push_back(pale[np++ % 4]);
  for (const auto& l : paths)
    range.push_back(l.label == "truth" || l.label.find("(truth)") != std::string::npos ? "#000000" : strong[ns++ % 7]);
  c.spec = base_spec(title);
  c.spec["width"] = width;
  c.spec["height"] = height;
  json color = {{"field", "s"}, {"type", "nominal"}, {"title", nullptr}, {"scale", {{"domain", domain}, {"range", range}}}};
  c.spec["layer"] = json::array(
      {{{"data", {{"values", point_values}}},
        {"mark", {{"type", "point"}, {"filled", true}, {"size", 10}, {"opacity", 0.7}, {"clip", true}}},
        {"encoding",
         {{"x", {{"field", "x"}, {"type", "quantitative"}, {"title", x_title}, {"scale", xscale}}},
          {"y", {{"field", "y"}, {"type", "quantitative"}, {"title", y_title}, {"scale", yscale}}},
          {"color", color}}}},
       {{"data", {{"values", line_values}}},
        {"mark", {{"type", "line"}, {"strokeWidth", 1.4}, {"clip", true}}},
        {"params", json::array({{{"name", "zoom"}, {"select", "interval"}, {"bind", "scales"}}})},
        {"encoding",
         {{"x", {{"field", "x"}, {"type", "quantitative"}, {"scale", xscale}}},
          {"y", {{"field", "y"}, {"type", "quantitative"}, {"scale", yscale}}},
          {"order", {{"field", "o"}}},
          {"color", color}}}}});
  return c;
}

const char* track_colour(std::uint64_t id) {
  static const char* palette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                                  "#8c564b", "#e377c2", "#17becf", "#bcbd22", "#7f7f7f"};
  return palette[id % 10];
}

Chart scene_chart(const std::string& title, const SceneView& v) {
  Chart c;
  c.title = title;
  json points = json::array(), truths = json::array(), tentative = json::array(), confirmed = json::array();
  // Each line's points carry its group "g" (drawn as one path), its sample index "o" (time order)
  // and, for tracks, its colour "c".
  auto add_line = [&](json& values, const Line& l, const std::string& group, const char* colour) {
    json part = json::array();
    std::vector<double> order(l.x.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<double>(i);
    const long n = append_points(part, l, &order);
    for (auto& p : part) {
      p["g"] = group;
      if (colour) p["c"] = colour;
      p.erase("s");
      values.push_back(std::move(p));
    }
    if (n > 0) {
      ++c.lines;
      c.line_points += n;
    }
    return n > 0 ? 1 : 0;
  };
  int truth_lines = 0, track_lines = 0;
  for (size_t k = 0; k < v.truths.size(); ++k) truth_lines += add_line(truths, v.truths[k], "t" + std::to_string(k), nullptr);
  for (const auto& t : v.tracks) {
    const char* colour = track_colour(t.id);
    add_line(tentative, t.tentative, std::to_string(t.id) + "t", colour);
    track_lines += add_line(confirmed, t.confirmed, std::to_string(t.id), colour);
  }
  const size_t all_points = std::numeric_limits<size_t>::max();
  const long clutter = append_points(points, v.clutter, nullptr, all_points);
  const long detections = append_points(points, v.target_detections, nullptr, all_points);
  c.symbols = clutter + detections;
  c.attributes = {{"data-truth-lines", std::to_string(truth_lines)},
                  {"data-track-lines", std::to_string(track_lines)},
                  {"data-clutter-points", std::to_string(clutter)},
                  {"data-target-detections", std::to_string(detections)}};
  std::vector<const Line*> drawn = {&v.clutter, &v.target_detections};
  for (const auto& l : v.truths) drawn.push_back(&l);
  for (const auto& t : v.tracks) {
    drawn.push_back(&t.confirmed);
    drawn.push_back(&t.tentative);
  }
  const PlaneScales scales = plane_scales(drawn, true);
  c.caption = scales.caption;
  auto xy = [&](bool titled) {
    json x = {{"field", "x"}, {"type", "quantitative"}, {"scale", scales.x}};
    json y = {{"field", "y"}, {"type", "quantitative"}, {"scale", scales.y}};
    if (titled) {
      x["title"] = "east x [m]";
      y["title"] = "north y [m]";
    }
    return std::make_pair(x, y);
  };
  auto line_layer = [&](const json& values, json mark, bool coloured) {
    const auto [x, y] = xy(false);
    json enc = {{"x", x}, {"y", y}, {"detail", {{"field", "g"}, {"type", "nominal"}}}, {"order", {{"field", "o"}}}};
    if (coloured) enc["color"] = {{"field", "c"}, {"type", "nominal"}, {"scale", nullptr}, {"legend", nullptr}};
    mark["type"] = "line";
    mark["clip"] = true;
    return json{{"data", {{"values", values}}}, {"mark", mark}, {"encoding", enc}};
  };
  const auto [x, y] = xy(true);
  json layers = json::array(
      {{{"data", {{"values", points}}},
        {"mark", {{"type", "point"}, {"filled", true}, {"size", 8}, {"opacity", 0.6}, {"clip", true}}},
        {"params", json::array({{{"name", "zoom"}, {"select", "interval"}, {"bind", "scales"}}})},
        {"encoding",
         {{"x", x},
          {"y", y},
          {"color",
           {{"field", "s"}, {"type", "nominal"}, {"title", nullptr},
            {"scale", {{"domain", {v.clutter.label, v.target_detections.label}}, {"range", {"#c7c7c7", "#555555"}}}}}}}}},
       line_layer(truths, {{"color", "#000000"}, {"strokeWidth", 1.2}, {"strokeDash", {4, 3}}}, false),
       line_layer(tentative, {{"strokeWidth", 1.2}, {"opacity", 0.3}}, true),
       line_layer(confirmed, {{"strokeWidth", 1.8}}, true)});
  c.spec = base_spec(title);
  c.spec["height"] = scales.height;
  c.spec["layer"] = std::move(layers);
  // The tracks' literal colours must not share a scale with the detections' legend.
  c.spec["resolve"] = {{"scale", {{"color", "independent"}}}};
  return c;
}

Chart graph_chart(const std::vector<GraphNodeView>& nodes, const std::vector<GraphEdgeView>& edges) {
  Chart c;
  c.title = "pipeline";
  int columns = 1, rows = 1;
  for (const auto& n : nodes) {
    columns = std::max(columns, n.column + 1);
    rows = std::max(rows, n.row + 1);
  }
  // Boxes 150 x 45 px in cells of 170 x 80; an edge that skips columns bends above the boxes
  // (each a little higher than the last) so that it is not hidden behind them.
  const int col_w = 170, row_h = 80, half_w = 75, half_h = 22;
  int skips = 0;
  for (const auto& e : edges)
    if (!e.attachment && nodes[static_cast<size_t>(e.to)].column - nodes[static_cast<size_t>(e.from)].column != 1) ++skips;
  const int top = 12 + 12 * skips;
  auto cx = [&](const GraphNodeView& n) { return n.column * col_w + col_w / 2; };
  auto cy = [&](const GraphNodeView& n) { return top + n.row * row_h + row_h / 2; };
  json node_values = json::array(), edge_values = json::array(), heads = json::array();
  for (const auto& n : nodes)
    node_values.push_back({{"x", cx(n)}, {"y", cy(n)}, {"id", n.id}, {"type", n.type}, {"kind", n.kind}});
  int skip = 0;
  for (size_t k = 0; k < edges.size(); ++k) {
    const auto& e = edges[k];
    const auto& a = nodes[static_cast<size_t>(e.from)];
    const auto& b = nodes[static_cast<size_t>(e.to)];
    std::vector<std::pair<int, int>> pts;
    std::string head = "triangle-right";
    if (e.attachment) {
      const bool up = cy(a) > cy(b);
      pts = {{cx(a), cy(a) + (up ? -half_h : half_h)}, {cx(b), cy(b) + (up ? half_h : -half_h) + (up ? 4 : -4)}};
      head = up ? "triangle-up" : "triangle-down";
    } else if (b.column - a.column == 1 && a.row == b.row) {
      pts = {{cx(a) + half_w, cy(a)}, {cx(b) - half_w - 4, cy(b)}};
    } else {
      const int lift = 12 * (++skip);
      const int y_top = std::min(cy(a), cy(b)) - half_h - lift + (b.column - a.column == 1 ? half_h + lift : 0);
      pts = {{cx(a) + half_w, cy(a)},
             {cx(a) + col_w / 2, y_top},
             {cx(b) - col_w / 2, y_top},
             {cx(b) - half_w - 4, cy(b)}};
    }
    for (size_t i = 0; i < pts.size(); ++i)
      edge_values.push_back({{"x", pts[i].first}, {"y", pts[i].second}, {"e", static_cast<int>(k)}, {"i", static_cast<int>(i)},
                             {"how", e.attachment ? "attached to" : "feeds"}});
    heads.push_back({{"x", pts.back().first}, {"y", pts.back().second}, {"shape", head}});
    ++c.lines;
    c.line_points += static_cast<long>(pts.size());
  }
  const json xs = {{"domain", {0, columns * col_w}}, {"range", {0, columns * col_w}}};
  const json ys = {{"domain", {0, top + rows * row_h}}, {"range", {0, top + rows * row_h}}};
  auto pos = [&](const char* f, const json& scale) {
    return json{{"field", f}, {"type", "quantitative"}, {"scale", scale}, {"axis", nullptr}};
  };
  c.spec = {{"$schema", "https://vega.github.io/schema/vega-lite/v6.json"},
            {"width", columns * col_w},
            {"height", top + rows * row_h},
            {"view", {{"stroke", nullptr}}},
            {"config", {{"font", "sans-serif"}, {"legend", {{"orient", "bottom"}, {"direction", "horizontal"}}}}},
            {"layer",
             json::array(
                 {{{"data", {{"values", edge_values}}},
                   {"mark", {{"type", "line"}, {"color", "#777"}, {"strokeWidth", 1.3}}},
                   {"encoding",
                    {{"x", pos("x", xs)},
                     {"y", pos("y", ys)},
                     {"detail", {{"field", "e"}, {"type", "nominal"}}},
                     {"order", {{"field", "i"}}},
                     {"strokeDash",
                      {{"field", "how"}, {"type", "nominal"}, {"title", nullptr},
                       {"scale", {{"domain", {"feeds", "attached to"}}, {"range", json::array({json::array({1, 0}), json::array({4, 3})})}}}}}}}},
                  {{"data", {{"values", heads}}},
                   {"mark", {{"type", "point"}, {"filled", true}, {"size", 40}, {"color", "#777"}, {"opacity", 1}}},
                   {"encoding", {{"x", pos("x", xs)}, {"y", pos("y", ys)}, {"shape", {{"field", "shape"}, {"type", "nominal"}, {"scale", nullptr}, {"legend", nullptr}}}}}},
                  {{"data", {{"values", node_values}}},
                   {"mark", {{"type", "point"}, {"shape", "M-1,-0.3H1V0.3H-1Z"}, {"size", 4 * half_w * half_w}, {"filled", true}, {"opacity", 1}}},
                   {"encoding",
                    {{"x", pos("x", xs)},
                     {"y", pos("y", ys)},
                     {"color", {{"field", "kind"}, {"type", "nominal"}, {"title", "kind"}, {"scale", {{"scheme", "pastel1"}}}}},
                     {"tooltip", json::array({{{"field", "id"}}, {{"field", "type"}}, {{"field", "kind"}}})}}}},
                  {{"data", {{"values", node_values}}},
                   {"mark", {{"type", "text"}, {"dy", -6}, {"fontWeight", "bold"}, {"fontSize", 12}}},
                   {"encoding", {{"x", pos("x", xs)}, {"y", pos("y", ys)}, {"text", {{"field", "id"}}}}}},
                  {{"data", {{"values", node_values}}},
                   {"mark", {{"type", "text"}, {"dy", 9}, {"fontSize", 10}, {"color", "#333"}}},
                   {"encoding", {{"x", pos("x", xs)}, {"y", pos("y", ys)}, {"text", {{"field", "type"}}}}}}})}};
  c.symbols = static_cast<long>(nodes.size() + heads.size());
  c.caption = "data flows left to right; dashed: an adapter attached to the filter it retunes";
  return c;
}

}  // namespace trackflow::report
