// Purpose: reference-output regression test: runs a pipeline with a test.estimate_dump sink on every filter and compares each filter's full output with the CSV stored from the code before the performance work (tests/reference/data), to 1e-9 relative.
//
// Usage: tf_reference_outputs check|write CASE PLUGIN_DIR TEST_PLUGIN_DIR SOURCE_DIR [OUT_DIR]
//   check: exit 0 when every value agrees, 1 with the first disagreement of each file otherwise.
//   write: (re)writes tests/reference/data/CASE.<filter id>.csv from the current code. Only for a
//          deliberate change of the filters' results, stated in the commit.
//
// Tolerance. Two values a (reference) and b (now) agree when
//   |a - b| <= 1e-9 max(|a|, |b|)            (relative), or
//   |a - b| <= 1e-8 scale                    (absolute floor for values near 0),
// where scale is the value's own uncertainty: sqrt(P_ii) for state element i, sqrt(P_ii P_jj) for
// covariance entry (i, j), the RMS of the state's standard deviations for an innovation (its units
// are the measurement's, so no state variance is its scale; the floor only matters for innovations
// near 0), 1 for NIS and annotations. An off-diagonal covariance near 0 thus has a tolerance of
// 1e-8 in correlation, and a state near 0 (within its sigma) of 1e-8 of its standard deviation.
// Why 1e-8 for the floor: the reference's own rounding noise reaches ~1e-9 of sigma on the long
// runs (16 000 steps at 40 Hz of a CA filter whose acceleration is barely observable): changing
// only how the original code symmetrises P (mirroring the upper triangle instead of averaging it
// with its transpose, a one-ulp change per step) moved its estimates by up to 7e-10 sigma
// (shot_noise, worst_noise); the floor sits a decade above that noise. Row structure (run, step,
// flags, sizes) must match exactly.
#include <trackflow/host/config.hpp>
#include <trackflow/host/engine.hpp>
#include <trackflow/host/graph.hpp>
#include <trackflow/host/plugins.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace trackflow;
using namespace trackflow::host;
namespace fs = std::filesystem;

namespace {

constexpr double kRelative = 1e-9, kFloor = 1e-8;

struct Case {
  const char* name;      // ctest name and file prefix
  const char* pipeline;  // relative to the source dir
  int runs;              // runs executed and dumped
  int head, every;       // rows kept: the first `head` estimates, then every `every`-th
};

// Every filter plugin appears here (filter.kalman CV and CA, filter.decoupled, filter.ekf with
// CV/CA/Singer, filter.ukf, filter.ekf_spherical, filter.gain_transform), with and without their
// adapters (adapt.quality_switch, adapt.innovation_r). Steps and rows per run are in comments.
const Case kCases[] = {
    {"quickstart", "pipelines/quickstart.yaml", 2, 10, 30},                        // 601 -> 30
    {"debiased_long_range", "pipelines/debiased_long_range.yaml", 1, 10, 8},       // 121 -> 24
    {"gain_transform_circle", "pipelines/gain_transform_circle.yaml", 1, 10, 80},  // 1885 -> 34
    {"gain_transform_maneuver", "pipelines/gain_transform_maneuver.yaml", 1, 10, 20},
    {"launch_normal_noise", "pipelines/launch_normal_noise.yaml", 1, 10, 800},  // 21601 -> 37
    {"beacon_skin", "pipelines/beacon_skin.yaml", 1, 10, 300},                  // 8001 -> 37
    {"shot_noise", "pipelines/shot_noise.yaml", 1, 10, 500},                    // 16001 -> 42
    {"worst_noise", "pipelines/worst_noise.yaml", 1, 10, 500},
    {"rbs_landing_scn1", "pipelines/rbs_landing_scn1.yaml", 2, 10, 60},  // 1336 -> 32
    {"rbs_landing_scn3", "pipelines/rbs_landing_scn3.yaml", 2, 10, 60},
    {"monopulse_glint", "pipelines/monopulse_glint_ekf_vs_aekf.yaml", 1, 10, 250},        // filter.ekf + adapt.range_r
    {"refraction_bias_estimation", "pipelines/refraction_bias_estimation.yaml", 1, 10, 100},  // filter.refraction_ekf
    {"variants", "tests/reference/variants.yaml", 1, 10, 10},
};

const Case* find_case(const std::string& name) {
  for (const auto& c : kCases)
    if (name == c.name) return &c;
  return nullptr;
}

struct Row {
  std::vector<std::string> cells;
  int line = 0;
};

std::vector<Row> read_rows(const fs::path& file) {
  std::ifstream is(file);
  if (!is) throw std::runtime_error("cannot read " + file.string());
  std::vector<Row> rows;
  std::string line;
  int n = 0;
  while (std::getline(is, line)) {
    ++n;
    if (line.empty() || line[0] == '#') continue;
    Row r;
    r.line = n;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) r.cells.push_back(cell);
    rows.push_back(std::move(r));
  }
  return rows;
}

// Layout of a row (see test.estimate_dump): run,step,time,initialised,updated,n,x,P,m,nu,nis,k,a.
struct Layout {
  int n = 0, m = 0, k = 0;
  int x0 = 6, p0 = 0, m_at = 0, nu0 = 0, nis = 0, k_at = 0, a0 = 0, size = 0;
  static bool of(const Row& r, Layout& l) {
    try {
      if (r.cells.size() < 7) return false;
      l.n = std::stoi(r.cells.at(5));
      l.p0 = l.x0 + l.n;
      l.m_at = l.p0 + l.n * (l.n + 1) / 2;
      l.m = std::stoi(r.cells.at(l.m_at));
      l.nu0 = l.m_at + 1;
      l.nis = l.nu0 + l.m;
      l.k_at = l.nis + 1;
      l.k = std::stoi(r.cells.at(l.k_at));
      l.a0 = l.k_at + 1;
      l.size = l.a0 + l.k;
      return static_cast<int>(r.cells.size()) == l.size;
    } catch (const std::exception&) {
      return false;
    }
  }
  std::string name(int c) const {
    static const char* const kFixed[] = {"run", "step", "time", "initialised", "updated", "n"};
    if (c < x0) return kFixed[c];
    if (c < p0) return "x[" + std::to_string(c - x0) + "]";
    if (c < m_at) {
      int i = 0, off = c - p0;
      while (off >= n - i) off -= n - i++;
      return "P[" + std::to_string(i) + "," + std::to_string(i + off) + "]";
    }
    if (c == m_at) return "m";
    if (c < nis) return "nu[" + std::to_string(c - nu0) + "]";
    if (c == nis) return "nis";
    if (c == k_at) return "k";
    return "annotation[" + std::to_string(c - a0) + "]";
  }
};

double number(const std::string& s) { return s.empty() ? std::nan("") : std::stod(s); }

// Compares one filter's dump; returns the number of disagreeing values (prints the first few).
int compare(const fs::path& ref_file, const fs::path& now_file, int& values) {
  const auto ref = read_rows(ref_file), now = read_rows(now_file);
  int bad = 0;
  auto report = [&](const std::string& what) {
    if (++bad <= 5) std::printf("  %s: %s\n", ref_file.filename().c_str(), what.c_str());
  };
  if (ref.size() != now.size()) report("rows: reference " + std::to_string(ref.size()) + ", now " + std::to_string(now.size()));
  double worst = 0.0;
  std::string worst_at;
  for (size_t r = 0; r < std::min(ref.size(), now.size()); ++r) {
    Layout la, lb;
    if (!Layout::of(ref[r], la) || !Layout::of(now[r], lb)) {
      report("line " + std::to_string(ref[r].line) + ": malformed row");
      continue;
    }
    if (la.n != lb.n || la.m != lb.m || la.k != lb.k) {
      report("line " + std::to_string(ref[r].line) + ": sizes (n, m, k) differ");
      continue;
    }
    for (int c : {0, 1, 3, 4})
      if (ref[r].cells[c] != now[r].cells[c])
        report("line " + std::to_string(ref[r].line) + ": " + la.name(c) + " " + ref[r].cells[c] + " -> " + now[r].cells[c]);
    std::vector<double> sd(la.n, 0.0);
    double sd_rms = 0.0;
    for (int i = 0, c = la.p0; i < la.n; ++i) {
      sd[i] = std::sqrt(std::fabs(number(ref[r].cells[c])));
      sd_rms += sd[i] * sd[i];
      c += la.n - i;
    }
    sd_rms = la.n ? std::sqrt(sd_rms / la.n) : 1.0;
    for (int c = 2; c < la.size; ++c) {
      if (c == 3 || c == 4 || c == 5 || c == la.m_at || c == la.k_at) continue;
      const double a = number(ref[r].cells[c]), b = number(now[r].cells[c]);
      ++values;
      if (std::isnan(a) || std::isnan(b)) {
        if (std::isnan(a) != std::isnan(b)) report("line " + std::to_string(ref[r].line) + ": " + la.name(c) + " NaN in one only");
        continue;
      }
      double scale = 1.0;
      if (c >= la.x0 && c < la.p0) {
        scale = sd[c - la.x0];
      } else if (c >= la.p0 && c < la.m_at) {
        int i = 0, off = c - la.p0;
        while (off >= la.n - i) off -= la.n - i++;
        scale = sd[i] * sd[i + off];
      } else if (c >= la.nu0 && c < la.nis) {
        scale = sd_rms;
      } else if (c == 2) {
        scale = 0.0;  // time: relative only
      }
      const double diff = std::fabs(a - b), tol = std::max(kRelative * std::max(std::fabs(a), std::fabs(b)), kFloor * scale);
      const double rel = diff / std::max({std::fabs(a), std::fabs(b), scale, 1e-300});
      if (rel > worst) {
        worst = rel;
        worst_at = "line " + std::to_string(ref[r].line) + " " + la.name(c);
      }
      if (diff > tol) {
        char buf[200];
        std::snprintf(buf, sizeof buf, "line %d: %s reference %.17g, now %.17g (relative to its scale %.3g)",
                      ref[r].line, la.name(c).c_str(), a, b, rel);
        report(buf);
      }
    }
  }
  std::printf("%-48s %6zu rows, largest difference %.2e of scale (%s)%s\n", ref_file.filename().c_str(), ref.size(),
              worst, worst_at.empty() ? "-" : worst_at.c_str(), bad ? "  FAIL" : "");
  return bad;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 6) {
    std::fprintf(stderr, "usage: %s check|write CASE PLUGIN_DIR TEST_PLUGIN_DIR SOURCE_DIR [OUT_DIR]\n", argv[0]);
    return 2;
  }
  const std::string mode = argv[1];
  const Case* c = find_case(argv[2]);
  if (!c || (mode != "check" && mode != "write")) {
    std::fprintf(stderr, "unknown mode or case\n");
    return 2;
  }
  const fs::path source = argv[5];
  const fs::path out = argc > 6 ? fs::path(argv[6]) : fs::temp_directory_path() / ("tf-reference-" + std::string(c->name));
  const fs::path data = source / "tests/reference/data";
  try {
    PluginRegistry reg;
    reg.load_directories({argv[3], argv[4]});
    const std::string file = (source / c->pipeline).string();
    PipelineConfig cfg = parse_pipeline(load_yaml_file(file), file);
    // One dump per filter, named "<case>.<filter id>".
    std::vector<std::string> dumps;
    const size_t nodes = cfg.nodes.size();
    for (size_t i = 0; i < nodes; ++i) {
      const RegisteredType* t = reg.find(cfg.nodes[i].type);
      if (!t || t->decl.kind != ComponentKind::Filter) continue;
      NodeConfig d;
      d.id = std::string(c->name) + "." + cfg.nodes[i].id;
      d.type = "test.estimate_dump";
      d.inputs = {cfg.nodes[i].id};
      d.input_locs = {cfg.nodes[i].loc};
      d.loc = d.type_loc = cfg.nodes[i].loc;
      d.params = load_yaml_string("{ head: " + std::to_string(c->head) + ", every: " + std::to_string(c->every) +
                                      ", runs: " + std::to_string(c->runs) + " }",
                                  "reference");
      cfg.nodes.push_back(d);
      dumps.push_back(d.id);
    }
    if (dumps.empty()) throw std::runtime_error(std::string(c->pipeline) + " has no filter");
    const Graph g = build_graph(cfg, reg);
    RunOptions opt;
    opt.runs = static_cast<std::uint64_t>(c->runs);
    opt.threads = 1;
    opt.seed = cfg.seed;
    opt.output_dir = (mode == "write" ? data : out).string();
    fs::create_directories(opt.output_dir);
    run_graph(g, reg, opt);
    if (mode == "write") {
      for (const auto& id : dumps) std::printf("wrote %s\n", (data / (id + ".csv")).c_str());
      return 0;
    }
    int bad = 0, values = 0;
    for (const auto& id : dumps) {
      const fs::path ref = data / (id + ".csv");
      if (!fs::exists(ref)) {
        std::printf("%s: no reference file (filter added after the references were written?)\n", ref.c_str());
        ++bad;
        continue;
      }
      bad += compare(ref, fs::path(opt.output_dir) / (id + ".csv"), values);
    }
    std::printf("%s: %d values compared, %d disagree (tolerance 1e-9 relative, floor 1e-8 of the value's own "
                "standard deviation)\n",
                c->name, values, bad);
    return bad ? 1 : 0;
  } catch (const ConfigError& e) {
    std::fprintf(stderr, "%s\n", e.message().c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
}
