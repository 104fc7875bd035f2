// Purpose: expect checks, the terminal summary and the metrics JSON file.
#include <trackflow/host/report.hpp>
#include <trackflow/host/suggest.hpp>
#include <trackflow/number_text.hpp>
#include <trackflow/safe_output.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace trackflow::host {
namespace {

std::string fmt(double v) {
  if (!std::isfinite(v)) return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
  const double a = std::fabs(v);
  std::string s = a != 0.0 && (a >= 1e7 || a < 1e-3) ? number_text::general(v, 4) : number_text::fixed(v, 4);
  if (s.find('.') != std::string::npos && s.find('e') == std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  return s;
}

}  // namespace

namespace {

const Metric& find_metric(const Outcome& out, const std::string& node, const std::string& metric, const SourceLoc& loc) {
  const NodeOutcome* n = out.find(node);
  if (!n) {
    std::vector<std::string> ids;
    for (const auto& x : out.nodes) ids.push_back(x.id);
    throw ConfigError("expect names node '" + node + "', which does not exist" + did_you_mean(node, ids), loc);
  }
  const Metric* m = n->summary.find(metric);
  if (!m) {
    std::vector<std::string> names;
    for (const auto& x : n->summary.metrics) names.push_back(x.name);
    // Its notes say why a metric is missing (e.g. sink.metrics without truth: no errors, issue 26).
    std::string why;
    for (const auto& note : n->summary.notes)
      if (note.find("not reported") != std::string::npos || note.rfind("no truth", 0) == 0)
        why += (why.empty() ? "; its notes say: " : "; ") + note;
    throw ConfigError("expect: node '" + node + "' has no metric '" + metric + "'" + did_you_mean(metric, names) +
                          "; it reports: " + (names.empty() ? "none" : join(names)) + why,
                      loc);
  }
  return *m;
}

}  // namespace

std::vector<ExpectResult> check_expects(const Graph& g, const Outcome& out) {
  std::vector<ExpectResult> results;
  for (const auto& e : g.config.expects) {
    const Metric* m = &find_metric(out, e.node, e.metric, e.loc);
    ExpectResult r{e, false, m->value, {}};
    const std::string name = e.node + "." + e.metric + " = " + fmt(m->value);
    bool comparable = std::isfinite(m->value);
    if (e.op == "max") {
      r.passed = m->value <= e.value;
      r.text = name + " <= " + fmt(e.value);
    } else if (e.op == "min") {
      r.passed = m->value >= e.value;
      r.text = name + " >= " + fmt(e.value);
    } else if (e.op == "equals") {
      r.passed = std::fabs(m->value - e.value) <= e.tolerance;
      r.text = name + " == " + fmt(e.value) + " ± " + fmt(e.tolerance);
    } else if (e.op == "ratio_min" || e.op == "ratio_max") {
      const Metric& ref = find_metric(out, e.ref_node, e.ref_metric, e.loc);
      const double ratio = m->value / ref.value;
      comparable = comparable && std::isfinite(ratio);
      r.value = ratio;
      r.passed = e.op == "ratio_min" ? ratio >= e.value : ratio <= e.value;
      r.text = name + " / " + e.ref_node + "." + e.ref_metric + " = " + fmt(ratio) +
               (e.op == "ratio_min" ? " >= " : " <= ") + fmt(e.value);
    } else if (e.op == "less_than" || e.op == "greater_than") {
      const Metric& ref = find_metric(out, e.ref_node, e.ref_metric, e.loc);
      const bool less = e.op == "less_than";
      r.passed = less ? m->value < ref.value : m->value > ref.value;
      comparable = comparable && std::isfinite(ref.value);
      r.text = name + (less ? " < " : " > ") + e.ref_node + "." + e.ref_metric + " = " + fmt(ref.value);
    } else if (e.op == "within_band" || e.op == "outside_band") {
      if (!m->has_band) {
        // A metric that may lack its band in a run where its test has no power (sink.metrics:
        // "<metric>: no band: ..." or "...: no acceptance: ..." in the notes) fails the check:
        // the claim cannot be verified from this run. Any other band-less metric is a mistake.
        const NodeOutcome* node = out.find(e.node);
        const std::string prefix = e.metric + ": no ";
        const auto note = std::find_if(node->summary.notes.begin(), node->summary.notes.end(),
                                       [&](const std::string& n) { return n.rfind(prefix, 0) == 0; });
        if (note != node->summary.notes.end()) {
          r.passed = false;
          r.text = name + " has no band in this run (" + *note + ")";
          results.push_back(std::move(r));
          continue;
        }
        // sink.metrics' mean ANEES has no band (issue 25): its verdict is the per-step test.
        const std::string per_step = e.metric + "_steps_in_band";
        const Metric* steps = node->summary.find(per_step);
        const bool has_per_step = steps && steps->has_band;
        throw ConfigError("expect: metric '" + e.metric + "' of '" + e.node + "' has no band; use min/max" +
                              (has_per_step ? " (its consistency verdict is the per-step test: " + e.node + "." +
                                                  per_step + ": { " + e.op + ": " + fmt(e.value) + " })"
                                            : std::string()),
                          e.loc);
      }
      if (std::fabs(m->confidence - e.value) > 1e-9)
        throw ConfigError("expect asks for a " + fmt(e.value * 100) + " % band, but '" + e.node + "' computes its " +
                              e.metric + " band at " + fmt(m->confidence * 100) + " % (set its 'confidence' param)",
                          e.loc);
      const bool inside = m->value >= m->band_lo && m->value <= m->band_hi;
      r.passed = e.op == "within_band" ? inside : !inside;
      r.text = name + (e.op == "within_band" ? " in [" : " outside [") + fmt(m->band_lo) + ", " + fmt(m->band_hi) +
               "] (" + fmt(e.value * 100) + " % band)";
    } else {
      throw ConfigError("unknown expect check '" + e.op + "'", e.loc);
    }
    if (!comparable) r.passed = false;
    results.push_back(std::move(r));
  }
  return results;
}

void print_summary(std::ostream& os, const Graph& g, const Outcome& out, unsigned threads,
                   const std::vector<ExpectResult>& expects) {
  const auto& c = g.config;
  // Every text below comes from the pipeline file or a plugin: printed through printable(), so a
  // description or a sink path cannot send terminal escapes or forge a line with a '\n'.
  os << "pipeline " << printable(c.name);
  if (!c.description.empty()) os << ": " << printable(c.description);
  os << "\n  " << out.runs << (out.runs == 1 ? " run" : " runs") << ", " << threads
     << (threads == 1 ? " thread" : " threads") << ", seed " << c.seed << "; " << fmt(out.seconds) << " s\n";
  if (out.filters > 0) {
    os << "  measurements processed: " << out.measurements_processed << " by " << out.filters
       << (out.filters == 1 ? " filter" : " filters");
    if (out.seconds > 0) os << " (" << fmt(std::round(out.measurements_processed / out.seconds)) << " measurements/s)";
    os << "\n";
  }
  os << "  source items: " << out.source_items;
  if (out.seconds > 0) os << " (" << fmt(std::round(out.source_items / out.seconds)) << " items/s)";
  os << "\n";
  for (const auto& n : out.nodes) {
    const bool has_any = !n.summary.metrics.empty() || !n.summary.notes.empty() || n.skips > 0 || !n.summary.files.empty();
    if (!has_any) continue;
    os << "\n" << printable(n.id) << " (" << printable(n.type) << ")\n";
    size_t w = 6;
    for (const auto& m : n.summary.metrics) w = std::max(w, m.name.size() + (m.unit.empty() ? 0 : m.unit.size() + 3));
    for (const auto& m : n.summary.metrics) {
      std::string label = printable(m.name + (m.unit.empty() ? "" : " [" + m.unit + "]"));
      os << "  " << std::left << std::setw(static_cast<int>(w) + 2) << label << std::right << std::setw(12) << fmt(m.value);
      if (m.has_band) {
        const bool in = m.value >= m.band_lo && m.value <= m.band_hi;
        os << "   " << fmt(m.confidence * 100) << " % band [" << fmt(m.band_lo) << ", " << fmt(m.band_hi) << "] "
           << (in ? "inside" : "OUTSIDE");
      }
      os << "\n";
    }
    if (n.skips > 0) {
      os << "  skipped: " << n.skips << "\n";
      for (const auto& s : n.skip_examples) os << "    " << printable(s) << "\n";
      if (n.skips > n.skip_examples.size()) os << "    ...\n";
    }
    for (const auto& s : n.summary.notes) os << "  " << printable(s) << "\n";
    for (const auto& f : n.summary.files) os << "  wrote " << printable(f) << "\n";
  }
  for (const auto& w : out.warnings) os << "warning: " << printable(w) << "\n";
  if (!expects.empty()) {
    size_t failed = 0;
    os << "\nexpect\n";
    for (const auto& r : expects) {
      os << "  " << (r.passed ? "pass  " : "FAIL  ") << printable(r.text) << "   (" << printable(r.expect.loc.str())
         << ")\n";
      failed += r.passed ? 0 : 1;
    }
    os << "  " << expects.size() - failed << " passed, " << failed << " failed\n";
  }
}

// Each metric as an object with its unit (and band), written by nlohmann::json: NaN or
// infinity become null, strings are escaped by the library.
void write_metrics_json(const std::string& path, const Outcome& out) {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (const auto& n : out.nodes) {
    if (n.summary.metrics.empty() && n.skips == 0) continue;
    nlohmann::ordered_json node = nlohmann::ordered_json::object();
    for (const auto& m : n.summary.metrics) {
      nlohmann::ordered_json v = {{"value", m.value}, {"unit", m.unit}};
      if (m.has_band) {
        v["band_lo"] = m.band_lo;
        v["band_hi"] = m.band_hi;
        v["confidence"] = m.confidence;
      }
      node[m.name] = std::move(v);
    }
    if (n.skips > 0) node["skipped"] = {{"value", n.skips}, {"unit", ""}};
    j[n.id] = std::move(node);
  }
  // Node ids are ASCII, but metric names come from plugins: invalid UTF-8 becomes U+FFFD rather
  // than an exception or an invalid file.
  const std::string text = j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
  // Through a temporary renamed into place (safe_output.hpp): a full disk leaves no truncated file.
  SafeOutputFile f;
  if (!f.open_user_path(path)) throw ConfigError("cannot write metrics JSON '" + path + "': " + std::strerror(f.error_number()));
  if (!f.write(text) || !f.commit())
    throw ConfigError("error writing metrics JSON '" + path + "': " + std::strerror(f.error_number()));
}

}  // namespace trackflow::host
