// Purpose: assembles the HTML report: header, pipeline graph and table, summary and expects, plots of the nodes' series.
#include "html_report.hpp"

#include "charts.hpp"
#include "pipeline_layout.hpp"
#include "report_assets.hpp"
#include "script_json.hpp"

#include <trackflow/number_text.hpp>
#include <trackflow/safe_output.hpp>
#include <trackflow/version.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <utility>

namespace trackflow::report {
namespace {

std::string esc(const std::string& s) {
  std::string o;
  o.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string num(double v) {
  if (!std::isfinite(v)) return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
  return number_text::general(v, 5);
}

// A parameter value as the analyst wrote it, in YAML flow style.
std::string value_text(const host::Value& v) {
  switch (v.kind) {
    case host::Value::Kind::Null: return "~";
    case host::Value::Kind::Scalar: return v.scalar;
    case host::Value::Kind::List: {
      std::string s = "[";
      for (size_t i = 0; i < v.items.size(); ++i) s += (i ? ", " : "") + value_text(v.items[i]);
      return s + "]";
    }
    case host::Value::Kind::Map: {
      std::string s = "{";
      for (size_t i = 0; i < v.entries.size(); ++i)
        s += (i ? ", " : "") + v.entries[i].first + ": " + value_text(v.entries[i].second);
      return s + "}";
    }
  }
  return {};
}

const char* kStyle = R"css(
body { font-family: sans-serif; margin: 24px auto; max-width: 1000px; color: #222; }
h1 { font-size: 1.5em; margin-bottom: 0.2em; } h2 { border-bottom: 1px solid #ccc; margin-top: 1.6em; }
.meta { color: #555; font-size: 0.9em; } code { background: #f3f3f3; padding: 1px 3px; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.88em; }
td, th { border: 1px solid #ddd; padding: 3px 7px; text-align: left; vertical-align: top; }
td.n { text-align: right; font-variant-numeric: tabular-nums; }
.pass { color: #1a7f37; font-weight: bold; } .fail { color: #c62828; font-weight: bold; }
.chart { margin: 0.8em 0 0.2em 0; min-height: 60px; } .caption { color: #555; font-size: 0.85em; margin-bottom: 1em; }
.note { color: #555; font-size: 0.88em; }
)css";

// Inline data as columns instead of row objects (about a third of the size): numbers as one
// array per field, strings run-length coded. The page's script turns them back into rows.
void compact_data(json& node) {
  if (node.is_array()) {
    for (auto& x : node) compact_data(x);
    return;
  }
  if (!node.is_object()) return;
  auto d = node.find("data");
  if (d != node.end() && d->is_object() && d->contains("values") && (*d)["values"].is_array()) {
    const json& rows = (*d)["values"];
    json cols = json::object();
    std::vector<std::string> keys;
    for (const auto& r : rows)
      for (auto it = r.begin(); it != r.end(); ++it)
        if (!cols.contains(it.key())) {
          cols[it.key()] = json::array();
          keys.push_back(it.key());
        }
    bool ok = !rows.empty();
    for (const auto& k : keys) {
      json col = json::array();
      bool text = false;
      for (const auto& r : rows) {
        if (!r.contains(k)) {
          ok = false;
          break;
        }
        text = text || r[k].is_string();
        col.push_back(r[k]);
      }
      if (!ok) break;
      if (text) {
        json rle = json::array();
        for (const auto& v : col) {
          if (!rle.empty() && rle.back()[0] == v)
            rle.back()[1] = rle.back()[1].get<long>() + 1;
          else
            rle.push_back(json::array({v, 1}));
        }
        cols[k] = {{"rle", rle}};
      } else {
        cols[k] = std::move(col);
      }
    }
    if (ok) *d = {{"tf_columns", cols}, {"tf_rows", rows.size()}};
  }
  for (auto it = node.begin(); it != node.end(); ++it)
    if (it.key() != "data") compact_data(it.value());
}

// The page, chart by chart; charts are rendered by the inlined script at load.
class Page {
 public:
  void html(const std::string& s) { body_ += s; }
  void chart(const Chart& c) {
    // A plot with nothing to draw (e.g. errors of a pipeline without truth) becomes a note.
    if (c.lines + c.areas + c.symbols == 0) {
      body_ += "<p class=\"note\">" + esc(c.title) + ": no data to plot.</p>\n";
      return;
    }
    const std::string id = "chart-" + std::to_string(charts_.size());
    body_ += "<div class=\"chart\" id=\"" + id + "\" data-title=\"" + esc(c.title) + "\" data-lines=\"" +
             std::to_string(c.lines) + "\" data-line-points=\"" + std::to_string(c.line_points) + "\" data-areas=\"" +
             std::to_string(c.areas) + "\" data-symbols=\"" + std::to_string(c.symbols) + "\"";
    for (const auto& [name, value] : c.attributes) body_ += " " + name + "=\"" + esc(value) + "\"";
    body_ += "></div>\n";
    if (!c.caption.empty()) body_ += "<div class=\"caption\">" + esc(c.caption) + "</div>\n";
    json spec = c.spec;
    compact_data(spec);
    charts_.push_back({{"id", id}, {"spec", std::move(spec)}});
  }
  std::string finish(const std::string& title) const {
    // Labels come from plugins (metric and series names): invalid UTF-8 becomes U+FFFD, not an exception.
    std::string specs = charts_.dump(-1, ' ', false, json::error_handler_t::replace);
    specs = report::script_safe_json(specs);  // a label "<!--<script>" cannot break the page
    std::string out;
    out.reserve(specs.size() + vega_js().size() + vega_lite_js().size() + body_.size() + 4096);
    out += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" + esc(title) +
           "</title>\n<style>" + std::string(kStyle) + "</style>\n</head>\n<body>\n";
    out += body_;
    out += "<script id=\"tf-charts\" type=\"application/json\">" + specs + "</script>\n";
    out += "<script>\n";
    out += vega_js();
    out += "\n</script>\n<script>\n";
    out += vega_lite_js();
    out += "\n</script>\n<script>\n";
    out += R"js(// Renders every chart as SVG; data-rendered / data-failed on <body> say when all are done.
(function () {
  var charts = JSON.parse(document.getElementById('tf-charts').textContent);
  // Inline data come as columns ({tf_columns: {x: [...], s: {rle: [[v, n], ...]}}, tf_rows: n}).
  function rows(data) {
    var cols = {}, n = data.tf_rows, out = new Array(n);
    Object.keys(data.tf_columns).forEach(function (k) {
      var c = data.tf_columns[k];
      if (c && c.rle) {
        var full = [];
        c.rle.forEach(function (r) { for (var i = 0; i < r[1]; i++) full.push(r[0]); });
        c = full;
      }
      cols[k] = c;
    });
    for (var i = 0; i < n; i++) {
      var row = {};
      for (var k in cols) row[k] = cols[k][i];
      out[i] = row;
    }
    return out;
  }
  function expand(node) {
    if (Array.isArray(node)) { node.forEach(expand); return; }
    if (!node || typeof node !== 'object') return;
    if (node.data && node.data.tf_columns) node.data = { values: rows(node.data) };
    Object.keys(node).forEach(function (k) { if (k !== 'data') expand(node[k]); });
  }
  var jobs = charts.map(function (c) {
    var el = document.getElementById(c.id);
    try {
      expand(c.spec);
      var spec = vegaLite.compile(c.spec).spec;
      return new vega.View(vega.parse(spec), { renderer: 'svg', container: el, hover: true }).runAsync()
        .catch(function (e) { el.textContent = 'plot failed: ' + e; throw e; });
    } catch (e) {
      el.textContent = 'plot failed: ' + e;
      return Promise.reject(e);
    }
  });
  Promise.allSettled(jobs).then(function (r) {
    document.body.setAttribute('data-failed', r.filter(function (x) { return x.status === 'rejected'; }).length);
    document.body.setAttribute('data-rendered', r.filter(function (x) { return x.status === 'fulfilled'; }).length);
  });
})();
)js";
    out += "</script>\n</body>\n</html>\n";
    return out;
  }

 private:
  std::string body_;
  json charts_ = json::array();
};

std::string header_html(const host::PipelineConfig& c, const std::string& kind, const std::string& command) {
  std::string h = "<h1>" + esc(c.name) + " &mdash; " + kind + "</h1>\n";
  if (!c.description.empty()) h += "<p>" + esc(c.description) + "</p>\n";
  h += "<p class=\"meta\">pipeline file <code>" + esc(c.file) + "</code> &middot; trackflow " + kSdkVersion;
  if (!command.empty()) h += " &middot; <code>" + esc(command) + "</code>";
  h += "</p>\n";
  return h;
}

// The recorders the report adds: drawn from, not shown as the analyst's nodes.
using Hidden = std::set<std::string>;

// swept: node id -> the parameters a sweep varies, marked in the table (the values shown are the
// first grid point's, not fixed ones).
void pipeline_section(Page& page, const host::Graph& g, const Hidden& hidden,
                      const std::map<std::string, std::vector<std::string>>& swept = {}) {
  page.html("<h2>Pipeline</h2>\n");
  std::vector<GraphNodeView> nodes;
  std::vector<int> view_index(g.nodes.size(), -1);
  const auto pos = layout_pipeline(g);
  for (size_t i = 0; i < g.nodes.size(); ++i) {
    if (hidden.count(g.nodes[i].config.id)) continue;
    view_index[i] = static_cast<int>(nodes.size());
    nodes.push_back({g.nodes[i].config.id, g.nodes[i].config.type, to_string(g.nodes[i].type->decl.kind), pos[i].column,
                     pos[i].row});
  }
  std::vector<GraphEdgeView> edges;
  for (size_t i = 0; i < g.nodes.size(); ++i) {
    if (view_index[i] < 0) continue;
    for (int in : g.nodes[i].inputs)
      if (view_index[static_cast<size_t>(in)] >= 0) edges.push_back({view_index[static_cast<size_t>(in)], view_index[i], false});
    if (g.nodes[i].attach_to >= 0) edges.push_back({view_index[i], view_index[static_cast<size_t>(g.nodes[i].attach_to)], true});
  }
  page.chart(graph_chart(nodes, edges));
  const auto swept_text = [&](const std::string& id) {
    const auto it = swept.find(id);
    if (it == swept.end()) return std::string();
    std::string names;
    for (const auto& p : it->second) names += (names.empty() ? "" : ", ") + std::string("<code>") + esc(p) + "</code>";
    return "<br><b>swept:</b> " + names + " (shown at the first grid point's value; every value is in the table below)";
  };
  page.html("<table><tr><th>node</th><th>type</th><th>kind</th><th>inputs</th><th>parameters (as written)</th></tr>\n");
  for (const auto& n : g.nodes) {
    if (hidden.count(n.config.id)) continue;
    std::string inputs;
    for (size_t k = 0; k < n.config.inputs.size(); ++k) inputs += (k ? ", " : "") + n.config.inputs[k];
    if (!n.config.attach_to.empty()) inputs = "attached to " + n.config.attach_to;
    page.html("<tr><td><b>" + esc(n.config.id) + "</b></td><td><code>" + esc(n.config.type) + "</code></td><td>" +
              to_string(n.type->decl.kind) + "</td><td>" + esc(inputs) + "</td><td><code>" +
              esc(n.config.params.kind == host::Value::Kind::Null ? std::string("defaults") : value_text(n.config.params)) +
              "</code>" + swept_text(n.config.id) + "</td></tr>\n");
  }
  page.html("</table>\n");
}

void summary_section(Page& page, const host::Outcome& out, const std::vector<host::ExpectResult>& expects,
                     unsigned threads, std::uint64_t seed, const Hidden& hidden) {
  page.html("<h2>Summary</h2>\n<p>" + std::to_string(out.runs) + (out.runs == 1 ? " run" : " runs") + ", seed " +
            std::to_string(seed) + ", " + std::to_string(threads) + (threads == 1 ? " thread" : " threads") + ", " +
            num(out.seconds) + " s" +
            // As the text summary: filters are counted when there are some (a tracker's pipeline has none).
            (out.filters > 0 ? "; " + std::to_string(out.measurements_processed) + " measurements processed by " +
                                   std::to_string(out.filters) + (out.filters == 1 ? " filter" : " filters")
                             : std::string()) +
            ".</p>\n");
  for (const auto& n : out.nodes) {
    if (hidden.count(n.id)) continue;
    if (n.summary.metrics.empty() && n.summary.notes.empty() && n.skips == 0) continue;
    page.html("<h3>" + esc(n.id) + " <small>(" + esc(n.type) + ")</small></h3>\n");
    if (!n.summary.metrics.empty()) {
      page.html("<table><tr><th>metric</th><th>value</th><th>unit</th><th>band</th><th></th></tr>\n");
      for (const auto& m : n.summary.metrics) {
        std::string band, verdict;
        if (m.has_band) {
          band = num(m.confidence * 100) + " % [" + num(m.band_lo) + ", " + num(m.band_hi) + "]";
          const bool in = m.value >= m.band_lo && m.value <= m.band_hi;
          verdict = in ? "<span class=\"pass\">inside</span>" : "<span class=\"fail\">outside</span>";
        }
        page.html("<tr><td>" + esc(m.name) + "</td><td class=\"n\">" + num(m.value) + "</td><td>" + esc(m.unit) +
                  "</td><td>" + band + "</td><td>" + verdict + "</td></tr>\n");
      }
      page.html("</table>\n");
    }
    if (n.skips) page.html("<p class=\"note\">skipped: " + std::to_string(n.skips) + "</p>\n");
    for (const auto& s : n.summary.notes) page.html("<p class=\"note\">" + esc(s) + "</p>\n");
  }
  for (const auto& w : out.warnings) page.html("<p class=\"note\">warning: " + esc(w) + "</p>\n");
  if (!expects.empty()) {
    page.html("<h3>expect</h3>\n<table><tr><th></th><th>check</th><th>where</th></tr>\n");
    size_t failed = 0;
    for (const auto& e : expects) {
      failed += e.passed ? 0 : 1;
      page.html(std::string("<tr><td>") + (e.passed ? "<span class=\"pass\">pass</span>" : "<span class=\"fail\">FAIL</span>") +
                "</td><td>" + esc(e.text) + "</td><td><code>" + esc(e.expect.loc.str()) + "</code></td></tr>\n");
    }
    page.html("</table>\n<p>" + std::to_string(expects.size() - failed) + " passed, " + std::to_string(failed) +
              " failed</p>\n");
  }
}

// A column of a series as a Line against another column (time by default).
Line column_line(const Series& s, const std::string& column, const std::string& label, const std::string& x = "time") {
  Line l;
  l.label = label;
  const int cx = s.column(x), cy = s.column(column);
  if (cx < 0 || cy < 0) return l;
  l.x.reserve(s.rows());
  l.y.reserve(s.rows());
  for (size_t r = 0; r < s.rows(); ++r) {
    l.x.push_back(s.at(r, static_cast<size_t>(cx)));
    l.y.push_back(s.at(r, static_cast<size_t>(cy)));
  }
  return l;
}

bool has_values(const Line& l) {
  for (size_t i = 0; i < l.x.size(); ++i)
    if (std::isfinite(l.x[i]) && std::isfinite(l.y[i])) return true;
  return false;
}

// A scoring node's series and what it scores, from the graph's wiring.
struct Scored {
  const host::NodeOutcome* node;
  const Series* series;
  std::string filter;       // the estimate input
  std::string measurement;  // the measurement input ("" none)
};

std::vector<Scored> scored_series(const host::Graph& g, const host::Outcome& out) {
  std::vector<Scored> v;
  for (size_t i = 0; i < out.nodes.size() && i < g.nodes.size(); ++i)
    for (const auto& s : out.nodes[i].summary.series) {
      if (s.name != "ensemble" || s.column("position_rmse") < 0) continue;
      Scored sc{&out.nodes[i], &s, out.nodes[i].id, {}};
      const auto& gn = g.nodes[i];
      for (size_t k = 0; k < gn.inputs.size(); ++k) {
        const auto& up = g.nodes[static_cast<size_t>(gn.inputs[k])].config.id;
        if (gn.input_kinds[k] & mask(ItemKind::Estimate)) sc.filter = up;
        if ((gn.input_kinds[k] & mask(ItemKind::Measurement)) && sc.measurement.empty()) sc.measurement = up;
      }
      v.push_back(sc);
    }
  return v;
}

std::string label_for(const Scored& s, const std::vector<Scored>& all) {
  int same = 0;
  for (const auto& o : all) same += o.filter == s.filter ? 1 : 0;
  return same > 1 ? s.filter + " (" + s.node->id + ")" : s.filter;
}

// The times where a simulated trajectory changes segment (turn onsets and ends): sim.trajectory
// nodes' segment boundaries, drawn as dashed rules in the plots against time so a peak in the
// error can be read against the manoeuvre that caused it.
std::vector<double> segment_boundaries(const host::Graph& g) {
  std::vector<double> times;
  for (const auto& n : g.nodes) {
    if (n.config.type != "sim.trajectory" || !n.params.has("segments")) continue;
    double t = n.params.has("start_time") ? n.params.real("start_time") : 0.0;
    const auto& segments = n.params.records("segments");
    for (size_t i = 0; i + 1 < segments.size(); ++i) {
      if (segments[i].has("duration")) t += segments[i].real("duration");
      if (std::find(times.begin(), times.end(), t) == times.end()) times.push_back(t);
    }
  }
  std::sort(times.begin(), times.end());
  if (times.size() > 40) times.clear();  // a dense plan: rules would hide the lines
  return times;
}

// Adds the boundaries to a plot against time as dashed grey rules (a layer of their own).
void add_time_rules(Chart& c, const std::vector<double>& times) {
  if (times.empty()) return;
  json rules = json::array();
  for (double t : times) rules.push_back({{"x", round6(t)}});
  json rule = {{"data", {{"values", rules}}},
               {"mark", {{"type", "rule"}, {"strokeDash", json::array({4, 3})}, {"color", "#777777"}, {"strokeWidth", 1}}},
               {"encoding", {{"x", {{"field", "x"}, {"type", "quantitative"}}}}}};
  if (!c.spec.contains("layer")) {
    json main = json::object();
    for (const char* k : {"mark", "encoding", "params"})
      if (c.spec.contains(k)) {
        main[k] = c.spec[k];
        c.spec.erase(k);
      }
    c.spec["layer"] = json::array({main});
  }
  c.spec["layer"].push_back(rule);
  c.attributes.emplace_back("data-rules", std::to_string(times.size()));
  c.caption += std::string(c.caption.empty() ? "" : "; ") + "dashed: where the trajectory's segments change";
}

void error_section(Page& page, const std::vector<Scored>& scored, const std::vector<double>& rules) {
  if (scored.empty()) return;
  page.html("<h2>Error against time</h2>\n<p class=\"note\">Ensemble over the runs, per time step (after each scoring "
            "node's skip_initial). The measurement RMSE is that of the converted measurements the scoring node "
            "received.</p>\n");
  std::vector<Line> pos, vel;
  std::set<std::string> measured;
  for (const auto& s : scored) {
    const std::string label = label_for(s, scored);
    pos.push_back(column_line(*s.series, "position_rmse", label));
    vel.push_back(column_line(*s.series, "velocity_rmse", label));
  }
  for (const auto& s : scored) {
    if (s.measurement.empty() || !measured.insert(s.measurement).second) continue;
    Line m = column_line(*s.series, "measurement_rmse", s.measurement + " (measurements)");
    if (has_values(m)) pos.push_back(std::move(m));
  }
  Chart c = line_chart("position RMSE against time", "time [s]", "position RMSE [m]", pos, true);
  c.caption = "one line per filter and per measurement stream; log scale; drag to pan, wheel to zoom";
  add_time_rules(c, rules);
  page.chart(c);
  Chart v = line_chart("velocity RMSE against time", "time [s]", "velocity RMSE [m/s]", vel, true);
  add_time_rules(v, rules);
  page.chart(v);
  for (const auto& s : scored) {
    std::vector<Line> bias;
    for (const char* a : {"x", "y", "z"})
      bias.push_back(column_line(*s.series, std::string("mean_error_") + a, std::string("mean error ") + a));
    page.chart(line_chart("mean position error per axis - " + label_for(s, scored), "time [s]", "mean error [m]", bias));
  }
}

// "86 of 90 steps (95.6 %)": counts first, the percentage rounded to what 90 steps can tell.
std::string steps_inside(size_t in, size_t n) {
  if (n == 0) return "no steps with a band";
  return std::to_string(in) + " of " + std::to_string(n) + " steps (" +
         number_text::fixed(100.0 * static_cast<double>(in) / static_cast<double>(n), 1) + " %)";
}

// One plot per statistic with every filter on it, on one scale, inside the band they share (the
// band depends only on the runs at each step and the dimension, so filters scored over the same
// runs share it; filters whose bands differ, e.g. ANIS of 2-D and 3-D measurements, get a plot per band).
void consistency_section(Page& page, const std::vector<Scored>& scored, const std::vector<double>& rules) {
  bool any = false;
  for (const char* m : {"anees", "anis"}) {
    const std::string name = m == std::string("anees") ? "ANEES" : "ANIS";
    struct Group {
      Line lo, hi;
      std::vector<Line> values;
      std::vector<std::string> inside;
    };
    std::vector<Group> groups;
    for (const auto& s : scored) {
      const std::string label = label_for(s, scored);
      Line value = column_line(*s.series, m, label);
      if (!has_values(value)) continue;
      const Line lo = column_line(*s.series, std::string(m) + "_band_lo", "band");
      const Line hi = column_line(*s.series, std::string(m) + "_band_hi", "band");
      size_t in = 0, n = 0;
      for (size_t i = 0; i < value.y.size() && i < lo.y.size() && i < hi.y.size(); ++i)
        if (std::isfinite(value.y[i]) && std::isfinite(lo.y[i]) && std::isfinite(hi.y[i])) {
          ++n;
          in += value.y[i] >= lo.y[i] && value.y[i] <= hi.y[i] ? 1 : 0;
        }
      const auto same = [](const Line& a, const Line& b) {
        if (a.x.size() != b.x.size()) return false;
        for (size_t i = 0; i < a.x.size(); ++i) {
          const bool fa = std::isfinite(a.y[i]), fb = std::isfinite(b.y[i]);
          if (a.x[i] != b.x[i] || fa != fb || (fa && std::abs(a.y[i] - b.y[i]) > 1e-9 * std::abs(a.y[i]))) return false;
        }
        return true;
      };
      Group* g = nullptr;
      for (auto& x : groups)
        if (same(x.lo, lo) && same(x.hi, hi)) g = &x;
      if (!g) g = &groups.emplace_back(Group{lo, hi, {}, {}});
      g->values.push_back(value);
      g->inside.push_back(label + ": " + steps_inside(in, n));
    }
    if (groups.empty()) continue;
    if (!any) {
      page.html("<h2>Consistency against time</h2>\n<p class=\"note\">Per step: average NEES over the runs / 6 "
                "(ANEES), average NIS / innovation dimension (ANIS), every filter on one scale, with the two-sided "
                "chi-square band for the number of runs at that step (grey). A consistent filter stays inside the "
                "band at about its confidence.</p>\n");
      any = true;
    }
    for (const auto& g : groups) {
      std::string who;
      if (groups.size() > 1)
        for (const auto& v : g.values) who += (who.empty() ? " - " : ", ") + v.label;
      Chart c = band_chart(name + " against time" + who, name, g.values, g.lo, g.hi, "chi-square band for the runs at each step");
      std::string inside;
      for (const auto& t : g.inside) inside += (inside.empty() ? "" : "; ") + t;
      c.caption += "; inside the band: " + inside;
      add_time_rules(c, rules);
      page.chart(c);
    }
  }
}

void annotation_section(Page& page, const std::vector<Scored>& scored) {
  bool header = false;
  for (const auto& s : scored) {
    std::vector<Line> lines;
    for (const auto& col : s.series->columns) {
      const std::string& n = col.name;
      if (n.size() > 5 && n.compare(n.size() - 5, 5, "_mean") == 0) lines.push_back(column_line(*s.series, n, n.substr(0, n.size() - 5)));
    }
    std::vector<Line> fractions = {column_line(*s.series, "initialised_fraction", "initialised"),
                                   column_line(*s.series, "updated_fraction", "updated")};
    if (!header) {
      page.html("<h2>Filter state and annotations (the filter's own and its adapters') against time</h2>\n");
      header = true;
    }
    const std::string label = label_for(s, scored);
    // A fraction that never changes (every run initialised and updated at every step, the usual
    // case) is said in a line, not drawn as a flat plot.
    std::vector<Line> varying;
    std::string constant;
    for (const auto& f : fractions) {
      double first = NAN;
      bool flat = true, seen = false;
      for (double v : f.y)
        if (std::isfinite(v)) {
          if (!seen) first = v;
          flat = flat && v == first;
          seen = true;
        }
      if (!seen) continue;
      if (flat) constant += (constant.empty() ? "" : ", ") + f.label + " in " + num(100.0 * first) + " % of the runs";
      else varying.push_back(f);
    }
    if (!constant.empty())
      page.html("<p class=\"note\">" + esc(label) + ": at every step " + esc(constant) + " (not plotted).</p>\n");
    if (!varying.empty())
      page.chart(line_chart("fraction of runs " + std::string(varying.size() == 2 ? "initialised and updated" : varying[0].label) +
                                " - " + label,
                            "time [s]", "fraction of runs", varying));
    if (!lines.empty()) {
      Chart c = line_chart("annotations (mean over runs) - " + label, "time [s]", "mean value", lines);
      c.caption = "per channel: mean over the runs of the value the adapters attached to the estimate "
                  "(<adapter>.grade_*: quality grades, 0 best, 1 normal, 2 worst; <adapter>.sigma_*: adapted R, m)";
      page.chart(c);
    }
  }
}

void track_section(Page& page, const host::Graph& g, const host::Outcome& out, const std::string& track_node,
                   std::uint64_t run) {
  const host::NodeOutcome* t = out.find(track_node);
  if (!t || t->summary.series.empty()) return;
  // Measurements drawn are those the filters received (the others are the same points before conversion).
  std::set<std::string> fed;
  for (const auto& n : g.nodes)
    if (n.type->decl.kind == ComponentKind::Filter)
      for (int in : n.inputs) fed.insert(g.nodes[static_cast<size_t>(in)].config.id);
  std::vector<Line> ground_paths, ground_points, alt_paths, alt_points;
  for (const auto& s : t->summary.series) {
    const auto colon = s.name.find(':');
    const std::string kind = s.name.substr(0, colon), node = s.name.substr(colon + 1);
    if (kind == "measurement" && !fed.empty() && !fed.count(node)) continue;
    const std::string label = kind == "truth"         ? (node == "truth" ? node : node + " (truth)")
                              : kind == "measurement" ? node + " (measurements)"
                                                      : node;
    Line ground = column_line(s, "y", label, "x");
    Line alt = column_line(s, "z", label);
    if (kind == "measurement") {
      ground_points.push_back(std::move(ground));
      alt_points.push_back(std::move(alt));
    } else {
      ground_paths.push_back(std::move(ground));
      alt_paths.push_back(std::move(alt));
    }
  }
  page.html("<h2>Track of run " + std::to_string(run) + "</h2>\n<p class=\"note\">Truth, the measurements the filters "
            "received (converted to the ENU frame) and each filter's estimates, for one run (<code>--track-run</code>). "
            "The radar is at the origin.</p>\n");
  page.chart(track_chart("ground track (east-north)", "east x [m]", "north y [m]", ground_paths, ground_points, true));
  page.chart(track_chart("altitude against time", "time [s]", "up z [m]", alt_paths, alt_points, false));
}

// sink.scene's series as lines: truths by target, tracks by id split into confirmed / tentative,
// detections split into clutter / target-originated.
SceneView scene_view(const host::NodeOutcome& scene, const Series& tracks) {
  SceneView v;
  v.clutter.label = "clutter";
  v.target_detections.label = "target detections";
  std::map<double, size_t> truth_of;
  std::map<double, size_t> track_of;
  bool unknown = false;
  for (const auto& s : scene.summary.series) {
    const int cx = s.column("x"), cy = s.column("y");
    if (cx < 0 || cy < 0) continue;
    const bool truth = s.name.rfind("truth:", 0) == 0, scan = s.name.rfind("scan:", 0) == 0;
    for (size_t r = 0; truth && r < s.rows(); ++r) {
      const double id = s.at(r, static_cast<size_t>(s.column("target")));
      auto [it, fresh] = truth_of.try_emplace(id, v.truths.size());
      if (fresh) v.truths.emplace_back().label = "truth " + num(id);
      v.truths[it->second].x.push_back(s.at(r, static_cast<size_t>(cx)));
      v.truths[it->second].y.push_back(s.at(r, static_cast<size_t>(cy)));
    }
    for (size_t r = 0; scan && r < s.rows(); ++r) {
      const double origin = s.at(r, static_cast<size_t>(s.column("origin")));
      unknown |= origin == -2.0;
      Line& l = origin >= 0.0 ? v.target_detections : v.clutter;
      l.x.push_back(s.at(r, static_cast<size_t>(cx)));
      l.y.push_back(s.at(r, static_cast<size_t>(cy)));
    }
  }
  if (unknown) v.clutter.label = "clutter or unknown origin";
  const int cx = tracks.column("x"), cy = tracks.column("y"), ct = tracks.column("track"), cs = tracks.column("status");
  if (cx < 0 || cy < 0 || ct < 0 || cs < 0) return v;
  for (size_t r = 0; r < tracks.rows(); ++r) {
    const double id = tracks.at(r, static_cast<size_t>(ct));
    auto [it, fresh] = track_of.try_emplace(id, v.tracks.size());
    if (fresh) v.tracks.emplace_back().id = static_cast<std::uint64_t>(id);
    TrackPath& t = v.tracks[it->second];
    Line& l = tracks.at(r, static_cast<size_t>(cs)) == 0.0 ? t.tentative : t.confirmed;
    l.x.push_back(tracks.at(r, static_cast<size_t>(cx)));
    l.y.push_back(tracks.at(r, static_cast<size_t>(cy)));
  }
  return v;
}

// The multi-target picture of one run per tracker: truth, its tracks coloured by id, the scans' detections.
void scene_section(Page& page, const host::Outcome& out, const std::string& scene_node, std::uint64_t run) {
  const host::NodeOutcome* scene = out.find(scene_node);
  if (!scene) return;
  const Metric* stride = scene->summary.find("clutter_scan_stride");
  const Metric* lost = scene->summary.find("points_not_recorded");
  std::string recorded = "every detection of every scan";
  if (stride && stride->value > 1.0)
    recorded = "target detections of every scan, clutter of every " + num(stride->value) +
               "th scan only (the recorder's cap, sink.scene max_points, default 200 000 points)";
  if (lost && lost->value > 0.0) recorded += "; " + num(lost->value) + " points past that cap were not recorded";
  bool header = false;
  for (const auto& s : scene->summary.series) {
    if (s.name.rfind("tracks:", 0) != 0) continue;
    if (!header) {
      page.html("<h2>Scene of run " + std::to_string(run) + "</h2>\n<p class=\"note\">Truth, tracks and clutter per "
                "scan in the radar's plane (east-north, ENU) for one run (<code>--track-run</code>): each target's "
                "truth black and dashed, each track in its own colour by track id (a fixed palette of 10: colour = id "
                "mod 10; pale while tentative), the scans' detections as dots, clutter grey and target-originated "
                "dark.</p>\n");
      header = true;
    }
    const std::string tracker = s.name.substr(7);
    Chart c = scene_chart("scene of run " + std::to_string(run) + " - " + tracker, scene_view(*scene, s));
    c.caption += (c.caption.empty() ? "" : "; ") + std::string("drawn: ") + recorded;
    page.chart(c);
  }
}

// Series of per-interval RMSE (sink.interval_rmse): the filter against the measurements.
// sink.gospa's series: GOSPA of every scored tracker against time, then each one's parts (alpha = 2).
void gospa_section(Page& page, const host::Outcome& out) {
  std::vector<Line> totals;
  std::vector<std::pair<std::string, const Series*>> with_parts;
  for (const auto& n : out.nodes)
    for (const auto& s : n.summary.series) {
      if (s.name != "gospa" || s.column("gospa") < 0) continue;
      totals.push_back(column_line(s, "gospa", n.id));
      if (s.column("gospa_localisation") >= 0) with_parts.emplace_back(n.id, &s);
    }
  if (totals.empty()) return;
  page.html("<h2>GOSPA against time</h2>\n<p class=\"note\">Mean over the runs, per track set, of the GOSPA distance "
            "between the truths and the tracks (docs/multi-target-metrics.md); below, the three parts of its p-th "
            "power: localisation of the tracks that follow a target, missed targets, false tracks.</p>\n");
  page.chart(line_chart("GOSPA against time", "time [s]", "GOSPA [m]", totals));
  for (const auto& [id, s] : with_parts) {
    std::vector<Line> parts = {column_line(*s, "gospa_localisation", "localisation"),
                               column_line(*s, "gospa_missed", "missed"), column_line(*s, "gospa_false", "false")};
    page.chart(line_chart("GOSPA parts (p-th power) against time - " + id, "time [s]", "part of GOSPA^p", parts));
  }
}

void interval_section(Page& page, const host::Graph& g, const host::Outcome& out) {
  bool header = false;
  for (size_t i = 0; i < out.nodes.size() && i < g.nodes.size(); ++i)
    for (const auto& s : out.nodes[i].summary.series) {
      if (s.name != "intervals" || s.column("filter_rmse") < 0) continue;
      if (!header) {
        page.html("<h2>RMSE per interval</h2>\n");
        header = true;
      }
      std::vector<Line> lines = {column_line(s, "filter_rmse", "filter", "interval_start"),
                                 column_line(s, "measurement_rmse", "measurements", "interval_start")};
      Chart c = line_chart("position RMSE per interval - " + out.nodes[i].id, "interval start [s]", "position RMSE [m]",
                           lines, true);
      c.spec["mark"]["point"] = true;
      c.symbols = c.line_points;  // a symbol on every point
      page.chart(c);
    }
}

void files_section(Page& page, const std::vector<std::string>& files) {
  if (files.empty()) return;
  page.html("<h2>Files</h2>\n<p class=\"note\">The numbers behind the plots, at full precision and every step "
            "(units in the column names):</p>\n<ul>\n");
  for (const auto& f : files) page.html("<li><code>" + esc(f) + "</code></li>\n");
  page.html("</ul>\n");
}

}  // namespace

std::string render_run_report(const RunReport& r) {
  const host::Graph& g = *r.graph;
  const host::Outcome& out = *r.outcome;
  Page page;
  page.html(header_html(g.config, "run report", r.command));
  const Hidden hidden = {r.track_node, r.scene_node};
  pipeline_section(page, g, hidden);
  static const std::vector<host::ExpectResult> none;
  summary_section(page, out, r.expects ? *r.expects : none, r.threads, g.config.seed, hidden);
  const auto scored = scored_series(g, out);
  const std::vector<double> rules = segment_boundaries(g);
  error_section(page, scored, rules);
  consistency_section(page, scored, rules);
  gospa_section(page, out);
  if (!r.track_node.empty()) track_section(page, g, out, r.track_node, r.track_run);
  if (!r.scene_node.empty()) scene_section(page, out, r.scene_node, r.track_run);
  annotation_section(page, scored);
  interval_section(page, g, out);
  files_section(page, r.files);
  return page.finish(g.config.name + " - trackflow report");
}

std::string render_sweep_report(const SweepReport& r) {
  const host::Graph& g = *r.graph;
  Page page;
  page.html(header_html(g.config, "sweep report", r.command));
  std::map<std::string, std::vector<std::string>> swept;
  for (const auto& a : r.axes) {
    const auto dot = a.name.find('.');
    swept[a.name.substr(0, dot)].push_back(a.name.substr(dot + 1));
  }
  pipeline_section(page, g, Hidden{}, swept);
  const size_t points = r.metrics.empty() ? 0 : r.metrics.front().value.size();
  page.html("<h2>Sweep</h2>\n<p>" + std::to_string(points) + " grid points" +
            (r.zipped ? std::string(" (zipped: point i takes the i-th value of every axis)") : std::string()) + ", " +
            std::to_string(r.runs) + " runs each, the same seed at every point (common random numbers).</p>\n");
  // Each metric against each numeric axis that changes it (one line per combination of the other
  // axes); a metric no axis changes is listed once, not plotted flat. Zipped axes move together:
  // they are one x axis, named by all of them, and every metric is one line.
  const auto numeric = [](const SweepAxisView& a) {
    return std::all_of(a.value.begin(), a.value.end(), [](double v) { return std::isfinite(v); });
  };
  std::vector<size_t> x_axes;
  for (size_t a = 0; a < r.axes.size(); ++a)
    if (numeric(r.axes[a]) && (!r.zipped || x_axes.empty())) x_axes.push_back(a);
  std::string zipped_name;
  for (const auto& a : r.axes) zipped_name += (zipped_name.empty() ? "" : " = ") + a.name;
  // The other axes' values at point p, as a label ("" when x is the only axis, or zipped).
  const auto rest_of = [&](size_t x, size_t p) {
    std::string rest;
    if (r.zipped) return rest;
    for (size_t a = 0; a < r.axes.size(); ++a)
      if (a != x) rest += (rest.empty() ? "" : ", ") + r.axes[a].name + "=" + r.axes[a].text[p];
    return rest;
  };
  // Does the metric change along axis x, the other axes held? (NaN equals NaN here: a metric
  // undefined at every point changes nothing.)
  const auto changes = [&](const SweepMetricView& m, size_t x) {
    std::map<std::string, double> first;
    for (size_t p = 0; p < m.value.size(); ++p) {
      const auto [it, fresh] = first.emplace(rest_of(x, p), m.value[p]);
      if (!fresh && !(it->second == m.value[p] || (std::isnan(it->second) && std::isnan(m.value[p])))) return true;
    }
    return false;
  };
  std::vector<std::string> constant;
  for (const auto& m : r.metrics) {
    bool plotted = false;
    for (size_t x : x_axes) {
      if (!changes(m, x)) continue;
      plotted = true;
      const auto& ax = r.axes[x];
      bool log_x = true;
      double lo = INFINITY, hi = 0;
      for (double v : ax.value) {
        log_x = log_x && v > 0;
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
      log_x = log_x && hi / lo >= 100;
      std::map<std::string, Line> by_rest;
      std::vector<std::string> order;
      for (size_t p = 0; p < m.value.size(); ++p) {
        std::string rest = rest_of(x, p);
        if (rest.empty()) rest = m.name;
        if (!by_rest.count(rest)) order.push_back(rest);
        Line& l = by_rest[rest];
        l.label = rest;
        l.x.push_back(ax.value[p]);
        l.y.push_back(m.value[p]);
      }
      std::vector<Line> lines;
      for (const auto& k : order) lines.push_back(by_rest[k]);
      const std::string x_name = r.zipped ? zipped_name : ax.name;
      const std::string xt = x_name + (ax.unit.empty() ? "" : " [" + ax.unit + "]");
      const std::string yt = m.name + (m.unit.empty() ? "" : " [" + m.unit + "]");
      Chart c = line_chart(m.name + " against " + x_name, xt, yt, lines);
      if (log_x) {
        c.spec["encoding"]["x"]["scale"] = {{"type", "log"}};
        c.spec["encoding"]["x"]["axis"] = log_axis();
      }
      c.spec["mark"]["point"] = true;
      c.symbols = c.line_points;  // a symbol on every point
      c.caption = std::string(log_x ? "log scale on x" : "") +
                  (r.zipped ? std::string(log_x ? "; " : "") + "zipped axes: point i takes the i-th value of each" : "");
      page.chart(c);
    }
    if (!plotted) constant.push_back(m.name + " = " + num(m.value.empty() ? NAN : m.value.front()));
  }
  if (x_axes.empty())
    page.html("<p class=\"note\">No axis has numeric values only: see the table.</p>\n");
  else if (!constant.empty()) {
    std::string list;
    for (const auto& c : constant) list += (list.empty() ? "" : ", ") + esc(c);
    page.html("<p class=\"note\">The same at every grid point (no swept parameter changes them), so not plotted: " + list +
              ".</p>\n");
  }
  page.html("<table><tr>");
  for (const auto& a : r.axes) page.html("<th>" + esc(a.name) + (a.unit.empty() ? "" : " [" + esc(a.unit) + "]") + "</th>");
  for (const auto& m : r.metrics) page.html("<th>" + esc(m.name) + (m.unit.empty() ? "" : " [" + esc(m.unit) + "]") + "</th>");
  page.html("</tr>\n");
  for (size_t p = 0; p < points; ++p) {
    page.html("<tr>");
    for (const auto& a : r.axes) page.html("<td class=\"n\">" + esc(a.text[p]) + "</td>");
    for (const auto& m : r.metrics) page.html("<td class=\"n\">" + num(m.value[p]) + "</td>");
    page.html("</tr>\n");
  }
  page.html("</table>\n");
  files_section(page, r.files);
  return page.finish(g.config.name + " - trackflow sweep report");
}

void write_text_file(const std::string& path, const std::string& text) { write_user_file(path, text); }

}  // namespace trackflow::report
