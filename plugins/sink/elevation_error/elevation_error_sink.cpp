// Purpose: sink.elevation_error — a filter's (or a measurement stream's) elevation error against truth in degrees, max and RMS per run and over the ensemble, optionally within an elevation band, and the refraction-bias estimate's error (paper 004 Fig 5).
#include "physics/refraction.hpp"
#include "scoring/truth_match.hpp"

#include <trackflow/error.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

namespace trackflow {
namespace {

constexpr double kToDeg = 180.0 / std::numbers::pi;

double elevation_of(const Vec3& d) { return std::atan2(d.z(), std::hypot(d.x(), d.y())); }

struct Sample {
  double time, error, elevation, bias_error, bias_true, bias_est;  // rad
};

struct ElevationRunResult final : RunResult {
  std::vector<Sample> samples;  // scored samples of the run, in time order
  std::uint64_t non_finite = 0, unmatched = 0;
  // Its codec under mpirun (run_result_codec.hpp): one list, written and read in this order.
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.samples, r.non_finite, r.unmatched);
  }
};

// Per-step sums over runs (the k-th scored sample of every run; the runs share their times when
// the trajectory is deterministic).
struct StepSums {
  double time = 0.0, elevation = 0.0, error = 0.0, error_sq = 0.0, bias_true = 0.0, bias_est = 0.0, bias_sq = 0.0;
  std::uint64_t n = 0;
};

class ElevationErrorSink final : public Component, public FieldListCodec<ElevationRunResult> {
 public:
  explicit ElevationErrorSink(const Params& p)
      : below_(p.real_or("below", std::numeric_limits<double>::infinity())),
        above_(p.real_or("above", -std::numeric_limits<double>::infinity())),
        from_(p.real_or("from_time", -std::numeric_limits<double>::infinity())),
        sensor_(p.vec3("sensor_position")),
        tolerance_(p.real("time_tolerance")),
        score_bias_(p.boolean("score_bias")),
        reference_(sim::read_elevation_bias(p, p.real("radar_height"))) {
    if (!(above_ < below_)) throw p.error("above", "must be below 'below'");
    if (score_bias_ && reference_.kind == sim::RefractionKind::None)
      throw p.error("score_bias", "needs the truth's refraction model (refraction: clark or exponential, with the "
                                  "radar's parameters) to know the true bias");
    if (!score_bias_ && reference_.kind != sim::RefractionKind::None)
      throw p.error("refraction", "describes the true bias, used only with score_bias: true");
    truth_.reserve(1 << 15);
    items_.reserve(1 << 15);
  }

  void set_inputs(const std::vector<InputInfo>& inputs) override {
    int scored = 0, truth = 0;
    for (const auto& in : inputs) {
      const bool t = (in.kinds & mask(ItemKind::Truth)) != 0;
      truth += t;
      if (!t) {
        ++scored;
        estimates_ = (in.kinds & mask(ItemKind::Estimate)) != 0;
        if (score_bias_) bias_index_ = bias_component(in);
      }
    }
    if (scored != 1 || truth != 1)
      throw ConfigError("sink.elevation_error scores one filter or one measurement stream against the truth: inputs: "
                        "[kf, truth] or [radar, truth]");
  }

  // The input's state component "bias" (rad), by name: filter.refraction_ekf's b, or any
  // filter's that names an elevation bias so.
  static int bias_component(const InputInfo& in) {
    const int i = in.state.index_of(kBiasName);
    if (i < 0 || std::strcmp(in.state.components[i].unit, "rad") != 0) {
      std::string names;
      for (int k = 0; k < in.state.dim; ++k)
        names += std::string(k ? ", " : "") + in.state.components[k].name + " (" + in.state.components[k].unit + ")";
      throw ConfigError("score_bias reads the state component '" + std::string(kBiasName) +
                        "' (rad) of its input (filter.refraction_ekf's b); input '" + in.node + "' (" + in.type +
                        ") has " + (names.empty() ? std::string("no state layout") : "the state " + names));
    }
    return i;
  }

  void start_run(const RunContext&) override {
    truth_.clear();
    items_.clear();
  }

  void on_truth(const Truth& t, int) override { metrics::insert_truth(truth_, t); }

  void on_estimate(const Estimate& e, int) override {
    if (!e.initialised) return;
    Item it{e.time, e.enu.head<3>().allFinite() ? elevation_of(e.enu.head<3>() - sensor_) : NAN, sensor_, NAN};
    if (score_bias_ && bias_index_ >= 0 && e.state.size() > bias_index_) it.bias = e.state(bias_index_);
    items_.push_back(it);
  }

  void on_measurement(const Measurement& m, int) override {
    if (!m.valid || m.frame != Frame::Spherical || m.value.size() < 3) return;
    if (!m.sensor_level) throw DataError("sink.elevation_error: " + tilted_sensor_message(m));
    items_.push_back({m.time, m.value(2), m.sensor_position, NAN});
  }

  std::unique_ptr<RunResult> end_run() override {
    auto r = std::make_unique<ElevationRunResult>();
    const auto span = metrics::truth_for(truth_, 0);
    for (const Item& it : items_) {
      if (it.time < from_ - tolerance_) continue;
      Vec6 x;
      if (!metrics::truth_at(span, it.time, tolerance_, x)) {
        ++r->unmatched;
        continue;
      }
      const Vec3 d = x.head<3>() - it.sensor;
      const double el = elevation_of(d);
      if (!(el < below_ && el > above_)) continue;
      if (!std::isfinite(it.elevation) || (score_bias_ && !std::isfinite(it.bias))) {
        ++r->non_finite;
        continue;
      }
      Sample s{it.time, it.elevation - el, el, NAN, NAN, NAN};
      if (score_bias_) {
        bool defined = true;
        const double b = reference_.bias(d, el, defined);
        if (!defined) continue;
        s.bias_true = b;
        s.bias_est = it.bias;
        s.bias_error = it.bias - b;
      }
      r->samples.push_back(s);
    }
    return r;
  }

  void merge(RunResult& result) override {
    auto& r = static_cast<ElevationRunResult&>(result);
    ++runs_;
    non_finite_ += r.non_finite;
    unmatched_ += r.unmatched;
    double run_max = 0.0, run_sq = 0.0, run_bias_max = 0.0, run_bias_sq = 0.0;
    if (steps_.size() < r.samples.size()) steps_.resize(r.samples.size());
    for (size_t k = 0; k < r.samples.size(); ++k) {
      const Sample& s = r.samples[k];
      run_max = std::max(run_max, std::abs(s.error));
      run_sq += s.error * s.error;
      sum_ += s.error;
      StepSums& st = steps_[k];
      if (st.n == 0) st.time = s.time;
      st.elevation += s.elevation;
      st.error += s.error;
      st.error_sq += s.error * s.error;
      if (score_bias_) {
        run_bias_max = std::max(run_bias_max, std::abs(s.bias_error));
        run_bias_sq += s.bias_error * s.bias_error;
        bias_true_sq_ += s.bias_true * s.bias_true;
        st.bias_true += s.bias_true;
        st.bias_est += s.bias_est;
        st.bias_sq += s.bias_error * s.bias_error;
      }
      ++st.n;
    }
    const double n = static_cast<double>(r.samples.size());
    samples_ += r.samples.size();
    sq_ += run_sq;
    bias_sq_ += run_bias_sq;
    max_ = std::max(max_, run_max);
    bias_max_ = std::max(bias_max_, run_bias_max);
    run_rows_.insert(run_rows_.end(), {static_cast<double>(runs_ - 1), n, n ? run_max * kToDeg : NAN,
                                       n ? std::sqrt(run_sq / n) * kToDeg : NAN,
                                       n && score_bias_ ? std::sqrt(run_bias_sq / n) * kToDeg : NAN});
    if (r.samples.empty()) ++empty_runs_;
    run_max_sum_ += run_max;
  }

  void finish(Summary& s, const FinishContext&) override {
    const double n = static_cast<double>(samples_);
    s.metric("samples", n);
    if (samples_) {
      s.metric("max_error", max_ * kToDeg, "deg");
      s.metric("rms_error", std::sqrt(sq_ / n) * kToDeg, "deg");
      s.metric("mean_error", sum_ / n * kToDeg, "deg");
      s.metric("run_max_error_mean", run_max_sum_ / static_cast<double>(runs_ - empty_runs_) * kToDeg, "deg");
      if (score_bias_) {
        s.metric("bias_rms_error", std::sqrt(bias_sq_ / n) * kToDeg, "deg");
        s.metric("bias_max_error", bias_max_ * kToDeg, "deg");
        s.metric("bias_rms", std::sqrt(bias_true_sq_ / n) * kToDeg, "deg");
      }
    }
    s.metric("non_finite", static_cast<double>(non_finite_));
    std::string band = std::isfinite(below_) || std::isfinite(above_) ? " with the true elevation" : "";
    if (std::isfinite(above_)) band += " above " + std::to_string(above_ * kToDeg) + " deg";
    if (std::isfinite(below_)) band += std::string(std::isfinite(above_) ? " and" : "") + " below " +
                                       std::to_string(below_ * kToDeg) + " deg";
    s.notes.push_back("elevation error (estimated or measured minus true elevation seen from the radar, deg) over " +
                      std::string(estimates_ ? "initialised estimates" : "valid measurements") + band +
                      (std::isfinite(from_) ? " from t = " + std::to_string(from_) + " s" : "") +
                      ": max_error = largest |error| of any run, rms_error over all samples of all runs, "
                      "run_max_error_mean = the mean of each run's max" +
                      (score_bias_ ? "; bias_*: estimated b (refraction_ekf state) minus the true bias of the "
                                     "truth's refraction model, bias_rms the true bias's own RMS"
                                   : ""));
    if (empty_runs_) s.notes.push_back(std::to_string(empty_runs_) + " run(s) had no sample in the band");
    if (unmatched_) s.notes.push_back(std::to_string(unmatched_) + " item(s) could not be matched to truth");
    if (non_finite_) s.notes.push_back(std::to_string(non_finite_) + " non-finite estimate(s) left out");
    s.series.push_back(run_series());
    s.series.push_back(step_series());
  }

 private:
  struct Item {
    double time, elevation;
    Vec3 sensor;
    double bias;
  };

  Series run_series() const {
    Series t;
    t.name = "runs";
    t.description = "per run: samples scored, max and RMS elevation error (and RMS bias error)";
    t.add_column("run");
    t.add_column("samples");
    t.add_column("max_error", "deg");
    t.add_column("rms_error", "deg");
    t.add_column("bias_rms_error", "deg");
    t.values = run_rows_;
    return t;
  }

  Series step_series() const {
    Series t;
    t.name = "elevation";
    t.description = "per scored step over the runs: true elevation, mean and RMS elevation error, mean true and "
                    "estimated bias";
    t.add_column("time", "s");
    t.add_column("true_elevation", "deg");
    t.add_column("error_mean", "deg");
    t.add_column("error_rms", "deg");
    t.add_column("bias_true", "deg");
    t.add_column("bias_estimate", "deg");
    t.add_column("bias_error_rms", "deg");
    for (const StepSums& st : steps_) {
      const double n = static_cast<double>(st.n);
      const bool b = score_bias_;
      t.values.insert(t.values.end(), {st.time, st.elevation / n * kToDeg, st.error / n * kToDeg,
                                       std::sqrt(st.error_sq / n) * kToDeg, b ? st.bias_true / n * kToDeg : NAN,
                                       b ? st.bias_est / n * kToDeg : NAN, b ? std::sqrt(st.bias_sq / n) * kToDeg : NAN});
    }
    return t;
  }

  const double below_, above_, from_;
  const Vec3 sensor_;
  const double tolerance_;
  const bool score_bias_;
  static constexpr const char* kBiasName = "bias";
  int bias_index_ = -1;  // in the input's state (set_inputs)
  const sim::ElevationBias reference_;
  bool estimates_ = true;
  std::vector<Truth> truth_;
  std::vector<Item> items_;
  // Aggregating instance.
  std::uint64_t runs_ = 0, empty_runs_ = 0, samples_ = 0, non_finite_ = 0, unmatched_ = 0;
  double max_ = 0.0, sq_ = 0.0, sum_ = 0.0, run_max_sum_ = 0.0, bias_max_ = 0.0, bias_sq_ = 0.0, bias_true_sq_ = 0.0;
  std::vector<StepSums> steps_;
  std::vector<double> run_rows_;
};

const char* const kDoc =
    "Inputs: one filter (estimates) or one spherical measurement stream, and the truth: inputs: [kf, truth] or "
    "[radar, truth]. Error = elevation of the estimate's ENU position seen from sensor_position (a measurement: its "
    "elevation value, seen from its own sensor) minus the true elevation seen from the same point, the truth matched "
    "as in sink.metrics. Only samples at or after from_time whose true elevation lies in (above, below) are scored. "
    "Metrics in degrees (the paper's unit; the unit is in each metric): max_error (largest |error| over every run), "
    "rms_error and mean_error (over all samples of all runs), run_max_error_mean (mean over runs of each run's max). "
    "score_bias: true compares filter.refraction_ekf's estimated b (state 'bias') with the true bias b(truth) of "
    "the refraction model given here (refraction, n0, clark_*, scale_height, earth_radius, radar_height: write the "
    "radar's values): bias_rms_error, bias_max_error, and bias_rms (the true bias's RMS, for scale). Series: 'runs' "
    "(per run max/RMS) and 'elevation' (per scored step: mean true elevation, mean/RMS error, mean true and "
    "estimated bias), for `run --series` and `trackflow report`.";

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sink.elevation_error";
  d.kind = ComponentKind::Sink;
  d.summary = "Elevation error against truth in degrees (max, RMS, per run and ensemble) in an elevation band, and "
              "the refraction-bias estimate's error (paper 004)";
  d.doc = kDoc;
  d.params = {
      ParamSpec::real("below", dim::angle, "score only where the true elevation is below this (e.g. 10 deg)"),
      ParamSpec::real("above", dim::angle, "score only where the true elevation is above this (e.g. 2 deg)"),
      ParamSpec::real("from_time", dim::time, "score only samples at or after this time"),
      ParamSpec::real_list("sensor_position", dim::length, "radar position in the ENU frame, for estimates", 3)
          .def("[0, 0, 0]"),
      ParamSpec::real("time_tolerance", dim::time, "items closer in time than this are the same time step")
          .def("1 us")
          .positive(),
      ParamSpec::boolean("score_bias", "also score filter.refraction_ekf's bias estimate against the true bias").def("false"),
      sim::refraction_kind_param("score_bias: the truth's refraction model (the radar's)"),
      sim::n0_param(),
      ParamSpec::real("radar_height", dim::length, "score_bias, exponential: the radar's height (its site's)").def("0 m"),
  };
  for (auto& spec : sim::clark_param_specs(true)) d.params.push_back(std::move(spec));
  for (auto& spec : sim::exponential_param_specs()) d.params.push_back(std::move(spec));
  d.accepts = ItemKind::Estimate | ItemKind::Truth | mask(ItemKind::Measurement);
  d.min_inputs = 2;
  d.max_inputs = 2;
  d.produces = 0;
  d.create = [](const Params& p) { return std::make_unique<ElevationErrorSink>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sink.elevation_error", trackflow::register_components)
