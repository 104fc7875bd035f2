// Purpose: adapt.quality_switch — grades each radar channel BEST/NORMAL/WORST from the RMS of successive differences and switches q and R from beacon/skin tables (paper 000 §III.2).
#include "difference_window.hpp"

#include <trackflow/common_params.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/noise.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>

#include <array>
#include <cmath>
#include <string>

namespace trackflow {
namespace {

using adapt::DifferenceWindow;
using adapt::Grade;
using adapt::kGrades;

// Spectral density of an angular white jerk, rad²/s⁵ (paper 000's q_θ, q_φ).
constexpr Dimension kAngularJerkPsd{0, -5, 2, 0};

constexpr int kChannels = 3;  // range, azimuth, elevation
const char* const kChannelName[kChannels] = {"range", "azimuth", "elevation"};
const char* const kChannelUnit[kChannels] = {"m", "rad", "rad"};

// One row of a table: what the filter uses for a channel graded `grade`.
struct GradeRow {
  double q_range = 0.0, q_angle = 0.0;              // m²/s⁵, rad²/s⁵
  double sigma_range = -1.0, sigma_angle = -1.0;    // < 0: keep the measurement's own σ
};

enum class Table : int { Beacon = 0, Skin = 1 };

struct Settings {
  int window = 10;
  bool detrend = false;
  double reference[kChannels] = {};
  double normal_above = 1.0, worst_above = 2.0;
  GradeRow rows[2][kGrades];  // [table][grade]
  Table unknown_mode = Table::Beacon;
  Grade initial = Grade::Normal;
};

// The counts of one run; the aggregating instance sums them in run order.
struct QualityRunResult final : RunResult {
  std::uint64_t steps = 0, invalid = 0, resets = 0, switches = 0, ungraded = 0;
  std::uint64_t table_steps[2] = {};
  std::uint64_t graded[kChannels][kGrades] = {};
  std::uint64_t graded_in[2][kChannels][kGrades] = {};  // the same per table in force (beacon, skin)
  double rms_sum[kChannels] = {};
  std::uint64_t rms_count[kChannels] = {};
  // Its codec under mpirun (run_result_codec.hpp): one list, written and read in this order.
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.steps, r.invalid, r.resets, r.switches, r.ungraded, r.table_steps, r.graded, r.graded_in, r.rms_sum, r.rms_count);
  }
};

class QualitySwitchAdapter final : public Adapter, public FieldListCodec<QualityRunResult> {
 public:
  explicit QualitySwitchAdapter(const Settings& s)
      : s_(s),
        windows_{DifferenceWindow(s.window, false, s.detrend), DifferenceWindow(s.window, true, s.detrend),
                 DifferenceWindow(s.window, false, s.detrend)} {}

  // R of [range, azimuth, elevation]; white-jerk PSDs per ENU axis or per line-of-sight channel
  // (converted from the per-channel table rows with the SDK's helpers, whichever the filter has).
  NoiseNeeds needs() const override {
    NoiseNeeds n;
    n.measurement = MeasurementSpace::Spherical;
    n.process = true;
    n.process_kind = NoiseKind::SpectralDensity;
    n.process_dimension = dim::jerk_psd;
    n.process_axes = mask(NoiseAxes::Enu) | mask(NoiseAxes::LineOfSight);
    return n;
  }

  // The grade per channel: 0 best, 1 normal, 2 worst; no value until the channel is graded.
  std::vector<std::string> annotation_names() const override {
    return {"grade_range", "grade_azimuth", "grade_elevation"};
  }

  void start_run(const RunContext&) override {
    for (auto& w : windows_) w.reset();
    for (auto& g : grade_) g = -1;
    has_geometry_ = false;
    run_ = QualityRunResult{};
  }

  void before_update(const Measurement& m, Filter& f) override {
    ++run_.steps;
    const Table table = table_for(m.mode);
    ++run_.table_steps[static_cast<int>(table)];
    const bool usable = m.valid && m.value.size() >= 3 && m.value.head<3>().allFinite();
    if (usable) {
      for (int c = 0; c < kChannels; ++c) {
        windows_[c].add(m.value(c));
        if (!windows_[c].full()) continue;
        const double rms = windows_[c].rms();
        const int g = static_cast<int>(adapt::grade_of(rms, s_.reference[c], s_.normal_above, s_.worst_above));
        if (grade_[c] >= 0 && g != grade_[c]) ++run_.switches;
        grade_[c] = g;
        ++run_.graded[c][g];
        ++run_.graded_in[static_cast<int>(table)][c][g];
        run_.rms_sum[c] += rms;
        ++run_.rms_count[c];
      }
      if (!has_geometry_) set_geometry(m.value.head<3>(), m.azimuth);
    } else {
      // Not locked (or unusable): no grade from it, and no difference across it — the next
      // valid sample starts a fresh window; the grades in force are kept meanwhile.
      ++run_.invalid;
      bool had_samples = false;
      for (auto& w : windows_) {
        had_samples |= w.differences() > 0;
        w.reset();
      }
      if (had_samples) ++run_.resets;
    }
    bool graded_all = true;
    for (int c = 0; c < kChannels; ++c) {
      graded_all &= grade_[c] >= 0;
      if (grade_[c] >= 0) annotate(f, c, grade_[c]);
    }
    if (!graded_all) ++run_.ungraded;
    apply(table, f);
  }

  // The filter's own estimate is the geometry for the next step's q: a measurement in a shot
  // burst may put the target anywhere.
  void after_update(const Measurement& m, const Estimate& e, Filter&) override {
    if (!e.initialised) return;
    const Vec3 d = frame_to_sensor(m, e.enu.head<3>() - m.sensor_position);  // the sensor's own axes
    if (!d.allFinite() || d.norm() <= 0.0) return;
    set_geometry(enu_to_spherical(d, m.azimuth), m.azimuth);
  }

  std::unique_ptr<RunResult> end_run() override { return std::make_unique<QualityRunResult>(run_); }

  void merge(RunResult& result) override {
    const auto& r = static_cast<QualityRunResult&>(result);
    total_.steps += r.steps;
    total_.invalid += r.invalid;
    total_.resets += r.resets;
    total_.switches += r.switches;
    total_.ungraded += r.ungraded;
    for (int t = 0; t < 2; ++t) total_.table_steps[t] += r.table_steps[t];
    for (int c = 0; c < kChannels; ++c) {
      for (int g = 0; g < kGrades; ++g) {
        total_.graded[c][g] += r.graded[c][g];
        for (int t = 0; t < 2; ++t) total_.graded_in[t][c][g] += r.graded_in[t][c][g];
      }
      total_.rms_sum[c] += r.rms_sum[c];
      total_.rms_count[c] += r.rms_count[c];
    }
  }

  void finish(Summary& s, const FinishContext&) override {
    s.metric("steps", static_cast<double>(total_.steps));
    s.metric("beacon_table_steps", static_cast<double>(total_.table_steps[0]));
    s.metric("skin_table_steps", static_cast<double>(total_.table_steps[1]));
    s.metric("invalid_steps", static_cast<double>(total_.invalid));
    s.metric("window_resets", static_cast<double>(total_.resets));
    s.metric("ungraded_steps", static_cast<double>(total_.ungraded));
    s.metric("grade_switches", static_cast<double>(total_.switches));
    for (int c = 0; c < kChannels; ++c) {
      std::uint64_t n = 0;
      for (int g = 0; g < kGrades; ++g) n += total_.graded[c][g];
      if (n == 0) continue;
      for (int g = 0; g < kGrades; ++g)
        s.metric(std::string(adapt::grade_name(static_cast<Grade>(g))) + "_fraction_" + kChannelName[c],
                 static_cast<double>(total_.graded[c][g]) / static_cast<double>(n));
      s.metric(std::string("mean_rmse_") + kChannelName[c],
               total_.rms_sum[c] / static_cast<double>(total_.rms_count[c]), kChannelUnit[c]);
    }
    // Per table, when both were in force (paper 000 §IV.3 grades beacon and skin stretches apart).
    const char* const table_name[2] = {"beacon", "skin"};
    auto graded_in_table = [&](int t) {
      std::uint64_t n = 0;
      for (int g = 0; g < kGrades; ++g) n += total_.graded_in[t][0][g];
      return n;
    };
    if (graded_in_table(0) > 0 && graded_in_table(1) > 0) {
      for (int t = 0; t < 2; ++t)
        for (int c = 0; c < kChannels; ++c) {
          std::uint64_t n = 0;
          for (int g = 0; g < kGrades; ++g) n += total_.graded_in[t][c][g];
          if (n == 0) continue;
          for (int g = 0; g < kGrades; ++g)
            s.metric(std::string(table_name[t]) + "_" + adapt::grade_name(static_cast<Grade>(g)) + "_fraction_" +
                         kChannelName[c],
                     static_cast<double>(total_.graded_in[t][c][g]) / static_cast<double>(n));
        }
    }
    if (total_.rms_count[0] == 0)
      s.notes.push_back("no channel was ever graded: fewer than window + 1 consecutive valid measurements per run");
    s.notes.push_back("grades per channel are published on each estimate as annotations grade_range, grade_azimuth, "
                      "grade_elevation (0 best, 1 normal, 2 worst, none until graded); mean_rmse_*: the mean of the "
                      "graded RMS of differences, the paper's 'RMSE mean' to set reference_* from; beacon_* / skin_*: the "
                      "fractions among the steps of each table, when both were in force");
  }

 private:
  Table table_for(MeasMode mode) const {
    if (mode == MeasMode::Beacon) return Table::Beacon;
    if (mode == MeasMode::Skin) return Table::Skin;
    return s_.unknown_mode;
  }

  void set_geometry(const Vec3& range_az_el, AzimuthConvention c) {
    if (!range_az_el.allFinite() || !(range_az_el(0) > 0.0)) return;
    rae_ = range_az_el;
    convention_ = c;
    has_geometry_ = true;
  }

  // Writes the rows of the grades in force (the initial grade until a channel is graded) into
  // the filter's q and R.
  void apply(Table table, Filter& f) {
    const NoiseHandles h = f.noise();
    const GradeRow* row[kChannels];
    for (int c = 0; c < kChannels; ++c) {
      const int g = grade_[c] >= 0 ? grade_[c] : static_cast<int>(s_.initial);
      row[c] = &s_.rows[static_cast<int>(table)][g];
    }
    // No geometry yet in this run (no valid measurement so far): the filter keeps its own q,
    // which the engine restored at the start of the run.
    if (h.process && h.process.count == 3 && has_geometry_) {
      const ChannelPsd q{row[0]->q_range, row[1]->q_angle, row[2]->q_angle};
      const Vec3 mapped = h.process.axes == NoiseAxes::LineOfSight
                              ? line_of_sight_psd(q, rae_(0), rae_(2))
                              : enu_axis_psd(q, rae_(0), rae_(1), rae_(2), convention_);
      for (int i = 0; i < 3; ++i) h.process.values[i] = mapped(i);
    }
    MeasCov* R = h.measurement.R;
    if (!R || R->rows() < 3 || R->cols() < 3) return;
    const double sigma[kChannels] = {row[0]->sigma_range, row[1]->sigma_angle, row[2]->sigma_angle};
    for (int c = 0; c < kChannels; ++c) {
      if (sigma[c] < 0.0) continue;
      R->row(c).setZero();
      R->col(c).setZero();
      (*R)(c, c) = sigma[c] * sigma[c];
    }
  }

  Settings s_;
  std::array<DifferenceWindow, kChannels> windows_;
  int grade_[kChannels] = {-1, -1, -1};
  Vec3 rae_ = Vec3::Zero();
  AzimuthConvention convention_ = AzimuthConvention::NorthClockwise;
  bool has_geometry_ = false;
  QualityRunResult run_;
  QualityRunResult total_;  // aggregating instance
};

// Reads one of the `beacon` / `skin` tables: exactly one row per grade.
void read_table(const Params& p, const char* name, GradeRow (&rows)[kGrades]) {
  const auto& records = p.records(name);
  bool seen[kGrades] = {};
  for (const Params& rec : records) {
    const int i = static_cast<int>(rec.choice<Grade>("grade"));
    if (seen[i]) throw rec.error("grade", "grade '" + rec.choice_word("grade") + "' appears twice in '" + name + "'");
    seen[i] = true;
    rows[i].q_range = rec.real("q_range");
    rows[i].q_angle = rec.real("q_angle");
    rows[i].sigma_range = rec.has("sigma_range") ? rec.real("sigma_range") : -1.0;
    rows[i].sigma_angle = rec.has("sigma_angle") ? rec.real("sigma_angle") : -1.0;
  }
  for (int i = 0; i < kGrades; ++i)
    if (!seen[i])
      throw p.error(name, std::string("has no row for grade '") + adapt::grade_name(static_cast<Grade>(i)) +
                              "': give one row each for best, normal and worst");
}

ParamSpec grade_param(const char* name, const char* doc) {
  return ParamSpec::choice<Grade>(name, {{Grade::Best, "best"}, {Grade::Normal, "normal"}, {Grade::Worst, "worst"}}, doc);
}

std::vector<ParamSpec> row_fields() {
  return {
      grade_param("grade", "the grade this row applies to").req(),
      ParamSpec::real("q_range", dim::jerk_psd, "range-channel white-jerk PSD q_r (paper: cm2, i.e. cm2/s5)").req().at_least(0),
      ParamSpec::real("q_angle", kAngularJerkPsd, "azimuth and elevation white-jerk PSD q_θ = q_φ (paper: urad2, i.e. urad2/s5)")
          .req()
          .at_least(0),
      ParamSpec::real("sigma_range", dim::length, "range sigma of R (default: the measurement's own)").positive(),
      ParamSpec::real("sigma_angle", dim::angle, "azimuth and elevation sigma of R (default: the measurement's own)").positive()
          .plausible_up_to(kPlausibleAngleSigma, kAngleSigmaHint),
  };
}

// Paper 000 Table 13 (R of Table 7 in each mode; q in cm²/s⁵ and µrad²/s⁵).
const char* const kBeaconTable13 =
    "[{grade: best, q_range: 100 cm2/s5, q_angle: 0.1 urad2/s5, sigma_range: 50 cm, sigma_angle: 50 urad}, "
    "{grade: normal, q_range: 300 cm2/s5, q_angle: 0.01 urad2/s5, sigma_range: 50 cm, sigma_angle: 50 urad}, "
    "{grade: worst, q_range: 500 cm2/s5, q_angle: 0.001 urad2/s5, sigma_range: 50 cm, sigma_angle: 50 urad}]";
const char* const kSkinTable13 =
    "[{grade: best, q_range: 100 cm2/s5, q_angle: 1 urad2/s5, sigma_range: 300 cm, sigma_angle: 150 urad}, "
    "{grade: normal, q_range: 300 cm2/s5, q_angle: 0.1 urad2/s5, sigma_range: 300 cm, sigma_angle: 150 urad}, "
    "{grade: worst, q_range: 500 cm2/s5, q_angle: 0.01 urad2/s5, sigma_range: 300 cm, sigma_angle: 150 urad}]";

const char* const kDoc =
    "Paper 000 §III.2 (eq 3.64, Tables 1, 12, 13). Before each update, for each channel c of the measurement "
    "(range, azimuth, elevation): RMSE_k = sqrt(sum over the last `window` differences (z_i - z_{i-1})^2 / n), azimuth "
    "differences wrapped to (-pi, pi]; detrend: true subtracts the differences' window mean first (not in the paper: "
    "the target's own rate of change then does not count as noise). Grade against the channel's reference mean M "
    "(reference_*; Table 12): RMSE <= l1 M BEST, <= l2 M NORMAL, else WORST, [l1, l2] = grade_limits (default [1, 2]: "
    "Table 1's scale 0.5M <-> M <-> 2M <-> 3M with BEST, NORMAL, WORST under its spans). Each grade selects a row of "
    "the `beacon` or `skin` table (by Measurement::mode; unknown_mode for neither): the range grade picks q_range and "
    "sigma_range, the azimuth and elevation grades each pick q_angle and sigma_angle. R: the diagonal of the "
    "[range, azimuth, elevation] block is replaced (a range-rate entry is kept). q: the channel PSDs (q_r m2/s5; q_az, "
    "q_el rad2/s5) become linear PSDs along the line of sight [q_r, (r cos el)^2 q_az, r^2 q_el] at the filter's latest "
    "estimate; to a filter whose q is per line-of-sight channel these are written (filter.ekf_spherical's q_r, q_h, "
    "q_v), to one whose q is per ENU axis the diagonal of J diag(q) J' (filter.ekf or filter.ukf with motion: "
    "constant_acceleration, q_jerk per ENU axis; the cross-axis terms are dropped). Any other filter is refused "
    "when the pipeline is built (the typed noise handles say what each q is). Invalid (unlocked) or non-finite measurements: not graded, and the windows restart after "
    "them (no difference across a gap); the grades in force are kept and the filter coasts. Until a channel's window "
    "holds `window` differences it uses initial_grade and is reported as not graded. The grade per channel is "
    "published on each estimate as annotations grade_range, grade_azimuth, grade_elevation (0 best, 1 normal, 2 worst, "
    "none until graded; sink.csv columns <adapter id>.grade_*). Defaults: Table 12's reference means and Table 13's tables. See docs/filters.md.";

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "adapt.quality_switch";
  d.kind = ComponentKind::Adapter;
  // Its channels are three position values (2-D measurements are refused when the pipeline is built).
  d.accepts_frames = mask(Frame::Spherical);
  d.summary = "Quality-switching adaptive q and R: BEST/NORMAL/WORST per channel from the RMS of successive "
              "measurement differences, beacon/skin tables (paper 000)";
  d.doc = kDoc;
  d.accepts = 0;
  d.min_inputs = 0;
  d.max_inputs = 0;
  d.produces = 0;
  d.params = {
      ParamSpec::integer("window", "differences n in the RMS of eq 3.64 (paper: 10)")
          .def("10")
          .at_least(1)
          .at_most(DifferenceWindow::kMaxLength),
      ParamSpec::boolean("detrend", "subtract the differences' window mean (removes the target's own rate; not in the paper)")
          .def("false"),
      ParamSpec::real("reference_range", dim::length, "reference mean M of the range RMSE (Table 12: 222.54 cm)")
          .def("222.54 cm")
          .positive(),
      ParamSpec::real("reference_azimuth", dim::angle, "reference mean M of the azimuth RMSE (Table 12: 33 urad)")
          .def("33 urad")
          .positive(),
      ParamSpec::real("reference_elevation", dim::angle, "reference mean M of the elevation RMSE (Table 12: 33 urad)")
          .def("33 urad")
          .positive(),
      ParamSpec::real_list("grade_limits", dim::none, "[l1, l2]: BEST up to l1 M, NORMAL up to l2 M, WORST beyond", 2)
          .def("[1, 2]")
          .positive(),
      ParamSpec::records("beacon", row_fields(), "q and R per grade in beacon mode (default: paper 000 Table 13)")
          .def(kBeaconTable13),
      ParamSpec::records("skin", row_fields(), "q and R per grade in skin mode (default: paper 000 Table 13)")
          .def(kSkinTable13),
      ParamSpec::choice<Table>("unknown_mode", {{Table::Beacon, "beacon"}, {Table::Skin, "skin"}},
                               "table for measurements whose mode is neither")
          .def("beacon"),
      grade_param("initial_grade", "grade used until a channel's window is full").def("normal"),
  };
  d.create = [](const Params& p) {
    Settings s;
    s.window = static_cast<int>(p.integer("window"));
    s.detrend = p.boolean("detrend");
    s.reference[0] = p.real("reference_range");
    s.reference[1] = p.real("reference_azimuth");
    s.reference[2] = p.real("reference_elevation");
    const auto& limits = p.reals("grade_limits");
    if (!(limits[0] < limits[1])) throw p.error("grade_limits", "must be increasing: [l1, l2] with l1 < l2, e.g. [1, 2]");
    s.normal_above = limits[0];
    s.worst_above = limits[1];
    read_table(p, "beacon", s.rows[0]);
    read_table(p, "skin", s.rows[1]);
    s.unknown_mode = p.choice<Table>("unknown_mode");
    s.initial = p.choice<Grade>("initial_grade");
    return std::make_unique<QualitySwitchAdapter>(s);
  };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("adapt.quality_switch", trackflow::register_components)
