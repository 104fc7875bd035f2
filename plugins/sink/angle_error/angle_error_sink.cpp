// Purpose: sink.angle_error — azimuth and elevation errors in urad of raw measurements and filters, ensemble RMS and mean per analyst-given time interval (paper 003 Tables 3-6).
#include "interval_sums.hpp"
#include "scoring/truth_match.hpp"

#include <trackflow/number_text.hpp>
#include <trackflow/common_params.hpp>
#include <trackflow/error.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace trackflow {
namespace {

using angles::ErrorSums;
using angles::Interval;
using angles::IntervalTable;

constexpr double kMicro = 1e6;  // rad -> urad

struct AngleRunResult final : RunResult {
  IntervalTable table;
  std::vector<std::uint64_t> missed, non_finite;  // per source
  std::uint64_t unmatched = 0;
  // Its codec under mpirun (run_result_codec.hpp): one list, written and read in this order.
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.table.sums(), r.missed, r.non_finite, r.unmatched);
  }
};

// Items are kept during the run (capacity reused, so nothing is allocated once the first run has
// sized the buffers) and scored in end_run(): the truth and the radar's position are known by then,
// whatever order the pipeline delivers them in.
class AngleErrorSink final : public Component, public FieldListCodec<AngleRunResult> {
 public:
  AngleErrorSink(std::vector<Interval> intervals, std::optional<Vec3> radar, AzimuthConvention convention, double tolerance)
      : intervals_(std::move(intervals)), radar_(radar), convention_(convention), tolerance_(tolerance) {
    truth_.reserve(1 << 14);
    items_.reserve(1 << 15);
  }

  void set_inputs(const std::vector<InputInfo>& inputs) override {
    int truth_inputs = 0;
    slot_of_port_.assign(inputs.size(), -1);
    for (size_t p = 0; p < inputs.size(); ++p) {
      const InputInfo& in = inputs[p];
      if (in.kinds & mask(ItemKind::Truth)) {
        ++truth_inputs;
        continue;
      }
      slot_of_port_[p] = static_cast<int>(sources_.size());
      sources_.push_back(in.node);
      is_measurement_.push_back((in.kinds & mask(ItemKind::Measurement)) != 0);
    }
    if (truth_inputs != 1 || sources_.empty())
      throw ConfigError("sink.angle_error takes the truth and at least one measurement or filter stream: inputs: [truth, "
                        "radar, ekf, ...] (got " + std::to_string(truth_inputs) + " truth and " +
                        std::to_string(sources_.size()) + " other inputs)");
    total_ = IntervalTable(intervals_.size(), sources_.size());
    missed_.assign(sources_.size(), 0);
    non_finite_.assign(sources_.size(), 0);
  }

  void start_run(const RunContext&) override {
    truth_.clear();
    items_.clear();
    sensor_.reset();
    run_missed_.assign(sources_.size(), 0);
    run_non_finite_.assign(sources_.size(), 0);
  }

  void on_truth(const Truth& t, int) override { metrics::insert_truth(truth_, t); }

  void on_measurement(const Measurement& m, int port) override {
    const int slot = slot_of_port_[port];
    if (!m.valid) {
      ++run_missed_[slot];
      return;
    }
    if (m.frame != Frame::Spherical)
      throw DataError("sink.angle_error: input '" + sources_[slot] + "' delivers " + to_string(m.frame) +
                      " measurements; it scores the radar's own spherical angles (wire the radar, not a converter)");
    if (!m.sensor_level) throw DataError("sink.angle_error: " + tilted_sensor_message(m));
    if (!m.value.head<3>().allFinite()) {
      ++run_non_finite_[slot];
      return;
    }
    if (!sensor_) {
      sensor_ = m.sensor_position;
      measured_convention_ = m.azimuth;
    }
    items_.push_back({m.time, slot, true, Vec3(m.value(1), m.value(2), 0.0), m.azimuth});
  }

  void on_estimate(const Estimate& e, int port) override {
    if (!e.initialised) return;
    const int slot = slot_of_port_[port];
    if (!e.enu.head<3>().allFinite()) {
      ++run_non_finite_[slot];
      return;
    }
    items_.push_back({e.time, slot, false, e.enu.head<3>(), convention_});
  }

  std::unique_ptr<RunResult> end_run() override {
    auto r = std::make_unique<AngleRunResult>();
    r->table = IntervalTable(intervals_.size(), sources_.size());
    r->missed = run_missed_;
    r->non_finite = run_non_finite_;
    const Vec3 sensor = radar_ ? *radar_ : sensor_.value_or(Vec3::Zero());
    if (radar_ && sensor_ && (*sensor_ - *radar_).norm() > 1e-3)
      throw DataError("sink.angle_error: radar_position differs from the measurements' sensor position by " +
                      std::to_string((*sensor_ - *radar_).norm()) + " m");
    if (!radar_ && !sensor_ && !items_.empty())
      throw DataError("sink.angle_error: no valid measurement gave the radar's position; set radar_position");
    const metrics::TruthSpan span = metrics::truth_for(truth_, 0);
    // Items of one time step (the radar's measurement and each filter's estimate) share the truth's
    // angles: computed once per step.
    double truth_time = std::numeric_limits<double>::quiet_NaN();
    bool truth_ok = false;
    Angles truth_angles{};
    for (const Item& it : items_) {
      // Estimates are seen from the radar in the measurements' convention (or the parameter's).
      const AzimuthConvention c = it.measurement ? it.convention : (sensor_ ? measured_convention_ : convention_);
      if (!(it.time == truth_time) || c != truth_convention_) {
        Vec6 truth;
        truth_ok = metrics::truth_at(span, it.time, tolerance_, truth);
        truth_time = it.time;
        truth_convention_ = c;
        if (truth_ok) truth_angles = angles_of(truth.head<3>() - sensor, c);
      }
      if (!truth_ok) {
        ++r->unmatched;
        continue;
      }
      const Angles a = it.measurement ? Angles{it.data(0), it.data(1)} : angles_of(it.data - sensor, c);
      const double e_az = wrap_angle(a.az - truth_angles.az), e_el = a.el - truth_angles.el;
      for (size_t k = 0; k < intervals_.size(); ++k)
        if (intervals_[k].contains(it.time)) r->table.at(k, static_cast<size_t>(it.slot)).add(e_az, e_el);
    }
    return r;
  }

  // Under mpirun (run_result_codec.hpp) the receiving instance has the same intervals and inputs:
  // the table is shaped from them before the field list is read, and the sizes merge() indexes
  // by are checked (writing is FieldListCodec's).
  std::unique_ptr<RunResult> load_run_result(ByteReader& in) const override {
    auto r = std::make_unique<AngleRunResult>();
    r->table = IntervalTable(intervals_.size(), sources_.size());
    const std::size_t cells = r->table.sums().size();
    in.get_all(*r);
    if (r->table.sums().size() != cells || r->missed.size() != sources_.size() ||
        r->non_finite.size() != sources_.size())
      throw DataError("sink.angle_error: a run's result from another process has another table size");
    return r;
  }

  void merge(RunResult& result) override {
    const auto& r = static_cast<const AngleRunResult&>(result);
    total_.add(r.table);
    for (size_t s = 0; s < sources_.size(); ++s) {
      missed_[s] += r.missed[s];
      non_finite_[s] += r.non_finite[s];
    }
    unmatched_ += r.unmatched;
    ++runs_;
  }

  void finish(Summary& s, const FinishContext&) override {
    for (size_t k = 0; k < intervals_.size(); ++k)
      for (size_t src = 0; src < sources_.size(); ++src) {
        const ErrorSums& e = total_.at(k, src);
        const std::string tail = "_" + sources_[src] + "_" + label(intervals_[k]);
        if (e.n == 0) {
          s.notes.push_back("no samples of '" + sources_[src] + "' in " + label(intervals_[k]) + " s");
          continue;
        }
        s.metric("az_rms" + tail, kMicro * e.az_rms(), "urad");
        s.metric("az_mean" + tail, kMicro * e.az_mean(), "urad");
        s.metric("el_rms" + tail, kMicro * e.el_rms(), "urad");
        s.metric("el_mean" + tail, kMicro * e.el_mean(), "urad");
      }
    for (size_t src = 0; src < sources_.size(); ++src) {
      if (is_measurement_[src]) s.metric("missed_" + sources_[src], static_cast<double>(missed_[src]));
      if (non_finite_[src]) s.metric("non_finite_" + sources_[src], static_cast<double>(non_finite_[src]));
    }
    tables(s);
    s.series.push_back(series());
    if (unmatched_) s.notes.push_back(std::to_string(unmatched_) + " item(s) could not be matched to truth (left out)");
  }

 private:
  struct Angles {
    double az, el;
  };
  // enu_to_spherical's angles with sqrt for the horizontal range (hypot's overflow guard is not needed
  // at radar distances, and it is the costliest call of the sink).
  static Angles angles_of(const Vec3& d, AzimuthConvention c) {
    const double horizontal = std::sqrt(d.x() * d.x() + d.y() * d.y());
    return {c == AzimuthConvention::NorthClockwise ? std::atan2(d.x(), d.y()) : std::atan2(d.y(), d.x()),
            std::atan2(d.z(), horizontal)};
  }

  struct Item {
    double time;
    int slot;
    bool measurement;
    Vec3 data;  // measurement: [az, el, 0]; estimate: ENU position
    AzimuthConvention convention;
  };

  static std::string number(double t) {
    std::string s = number_text::general(t, 6);  // printf's "%g"
    std::replace(s.begin(), s.end(), '.', 'p');
    std::replace(s.begin(), s.end(), '-', 'm');
    s.erase(std::remove(s.begin(), s.end(), '+'), s.end());
    return s;
  }
  static std::string label(const Interval& i) { return number(i.start) + "_" + number(i.end); }

  // The paper's Tables 3-6 layout: one table per statistic, a row per source, a column per interval.
  void tables(Summary& s) const {
    struct Stat {
      const char* title;
      double (ErrorSums::*get)() const;
    };
    const Stat stats[] = {{"azimuth error RMS [urad]", &ErrorSums::az_rms},
                          {"elevation error RMS [urad]", &ErrorSums::el_rms},
                          {"azimuth error mean [urad]", &ErrorSums::az_mean},
                          {"elevation error mean [urad]", &ErrorSums::el_mean}};
    size_t w = 8;
    for (const auto& n : sources_) w = std::max(w, n.size() + 2);
    for (const Stat& st : stats) {
      std::string head = st.title;
      head.resize(std::max(head.size(), w), ' ');
      std::string line(w, ' ');
      for (const Interval& i : intervals_) {
        char range[40], buf[48];
        std::snprintf(range, sizeof range, "%g-%g", i.start, i.end);
        std::snprintf(buf, sizeof buf, "%10s", range);
        line += buf;
      }
      s.notes.push_back(st.title + std::string(" over ") + std::to_string(runs_) + " runs, per interval [s]:");
      s.notes.push_back(line);
      for (size_t src = 0; src < sources_.size(); ++src) {
        std::string row = sources_[src];
        row.resize(w, ' ');
        for (size_t k = 0; k < intervals_.size(); ++k) {
          char buf[40];
          std::snprintf(buf, sizeof buf, "%10.2f", kMicro * (total_.at(k, src).*st.get)());
          row += buf;
        }
        s.notes.push_back(row);
      }
    }
  }

  Series series() const {
    Series t;
    t.name = "intervals";
    t.description = "per interval [start, end): ensemble RMS and mean of the azimuth and elevation errors of each source";
    t.add_column("interval_start", "s");
    t.add_column("interval_end", "s");
    for (const auto& n : sources_) {
      t.add_column(n + "_az_rms", "urad");
      t.add_column(n + "_az_mean", "urad");
      t.add_column(n + "_el_rms", "urad");
      t.add_column(n + "_el_mean", "urad");
      t.add_column(n + "_samples");
    }
    for (size_t k = 0; k < intervals_.size(); ++k) {
      t.values.push_back(intervals_[k].start);
      t.values.push_back(intervals_[k].end);
      for (size_t src = 0; src < sources_.size(); ++src) {
        const ErrorSums& e = total_.at(k, src);
        t.values.insert(t.values.end(), {kMicro * e.az_rms(), kMicro * e.az_mean(), kMicro * e.el_rms(),
                                         kMicro * e.el_mean(), static_cast<double>(e.n)});
      }
    }
    return t;
  }

  std::vector<Interval> intervals_;
  std::optional<Vec3> radar_;
  AzimuthConvention convention_;
  double tolerance_;
  std::vector<std::string> sources_;
  std::vector<bool> is_measurement_;
  std::vector<int> slot_of_port_;
  // Per run.
  std::vector<Truth> truth_;
  std::vector<Item> items_;
  std::optional<Vec3> sensor_;
  AzimuthConvention measured_convention_ = AzimuthConvention::NorthClockwise;
  AzimuthConvention truth_convention_ = AzimuthConvention::NorthClockwise;
  std::vector<std::uint64_t> run_missed_, run_non_finite_;
  // Aggregating instance.
  IntervalTable total_;
  std::vector<std::uint64_t> missed_, non_finite_;
  std::uint64_t unmatched_ = 0, runs_ = 0;
};

std::vector<Interval> read_intervals(const Params& p) {
  std::vector<Interval> out;
  for (const Params& rec : p.records("intervals")) {
    Interval i{rec.real("start"), rec.real("end")};
    if (!(i.end > i.start)) throw rec.error("end", "must be after start");
    out.push_back(i);
  }
  if (out.empty()) throw p.error("intervals", "give at least one interval, e.g. [{start: 0 s, end: 200 s}]");
  return out;
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sink.angle_error";
  d.kind = ComponentKind::Sink;
  d.summary = "Azimuth and elevation error (urad) of raw measurements and filters: ensemble RMS and mean per time "
              "interval (paper 003 Tables 3-6)";
  d.doc =
      "Inputs: the truth and any number of measurement streams (spherical, the radar's own) and filters, e.g. inputs: "
      "[truth, radar, ekf, aekf]. Each item's angle error is its azimuth (wrapped to (-pi, pi]) and elevation minus "
      "the truth's, seen from the radar: a measurement's own angles; a filter's from its ENU position estimate. The "
      "radar's position is the measurements' sensor position (or radar_position, which must then agree), the "
      "azimuth convention the measurements' (or azimuth_convention without measurements). For each interval "
      "[start, end) (they may overlap, e.g. 0-200 next to 0-40 s) and each source: az_rms_<source>_<start>_<end>, "
      "az_mean_..., el_rms_..., el_mean_... in urad, the RMS and mean over all samples of all runs in the interval "
      "(for equally many runs per time step: the time average of the ensemble RMS-square, and of the ensemble mean); "
      "times written with '.' as 'p'. Invalid measurements (missed looks) are left out and counted as missed_<source>; "
      "filters count from their first initialised estimate. The summary also prints the four tables (RMS and mean, "
      "azimuth and elevation; a row per source, a column per interval) as paper 003's Tables 3-6; the series "
      "'intervals' holds the same numbers with sample counts.";
  d.params = {
      ParamSpec::records("intervals",
                         {ParamSpec::real("start", dim::time, "first time in the interval (inclusive)").req(),
                          ParamSpec::real("end", dim::time, "end of the interval (exclusive)").req()},
                         "time intervals {start, end}, e.g. paper 003: 0-200, 0-40, 40-80, 80-120, 120-160, 160-200 s")
          .req(),
      ParamSpec::real_list("radar_position", dim::length, "radar position in the ENU frame (default: the measurements')", 3),
      azimuth_convention_param("azimuth reference when no measurement stream gives it"),
      ParamSpec::real("time_tolerance", dim::time, "items closer in time than this are the same time step")
          .def("1 us")
          .positive(),
  };
  d.accepts = ItemKind::Estimate | ItemKind::Truth | mask(ItemKind::Measurement);
  d.min_inputs = 2;
  d.max_inputs = -1;
  d.produces = 0;
  d.create = [](const Params& p) {
    std::optional<Vec3> radar;
    if (p.has("radar_position")) radar = p.vec3("radar_position");
    return std::make_unique<AngleErrorSink>(read_intervals(p), radar, p.choice<AzimuthConvention>("azimuth_convention"),
                                            p.real("time_tolerance"));
  };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sink.angle_error", trackflow::register_components)
