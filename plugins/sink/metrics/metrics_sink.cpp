// Purpose: sink.metrics — ensemble RMSE, bias, ANEES and ANIS (with chi-square bands) of one filter against truth.
#include "ensemble.hpp"
#include "stream_scorer.hpp"
#include "record_scoring.hpp"
#include "scoring/truth_match.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/number_text.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>


#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

namespace trackflow {
namespace {

using metrics::EstimateRecord;
using metrics::MetricsRunResult;

// Several estimates of one run at one time stamp (a filter taking several sensors publishes after
// each sensor's update; a fusion node after each local estimate): score each, or only the last
// (the state after every update of that time).
enum class SameTime { All, Last };

// When every input is time-ordered (InputInfo::time_ordered) a run is scored as it arrives
// (stream_scorer.hpp): an estimate as soon as its truth is certain, so only those still waiting
// for truth are kept, and without truth nothing per estimate (the series in bounded bins). Otherwise items are stored
// during the run and everything is evaluated in end_run(), when the truth of the whole run is
// known (truth of a time step may arrive after the estimate of that step, and out of order).
// Both give the same records; they cross processes under mpirun by MetricsRunResult's field
// list (ensemble.hpp).
class MetricsSink final : public Component, public FieldListCodec<MetricsRunResult> {
 public:
  explicit MetricsSink(const Params& p)
      : skip_initial_(p.real("skip_initial")),
        confidence_(p.real("confidence")),
        tolerance_(p.real("time_tolerance")),
        series_(p.boolean("series")),
        last_at_time_(p.choice<SameTime>("same_time") == SameTime::Last) {
    if (!(confidence_ > 0.0 && confidence_ < 1.0))
      throw p.error("confidence", "must lie strictly between 0 and 1 (e.g. 0.95)");
    ensemble_.annotation_channels = series_ ? channels_.count() : 0;
  }

  void set_inputs(const std::vector<InputInfo>& inputs) override {
    std::string estimate_sources;
    int estimate_inputs = 0;
    bool streaming = !inputs.empty();
    for (const auto& in : inputs) {
      if (in.kinds & mask(ItemKind::Estimate)) {
        estimate_sources += (estimate_inputs++ ? ", '" : "'") + in.node + "'";
        channels_ = metrics::AnnotationChannels(in.annotations);
        ensemble_.annotation_channels = series_ ? channels_.count() : 0;
      }
      truth_input_ |= (in.kinds & mask(ItemKind::Truth)) != 0;
      measurement_input_ |= (in.kinds & mask(ItemKind::Measurement)) != 0;
      streaming &= in.time_ordered;
    }
    streaming_ = streaming;
    if (streaming_)
      scorer_.configure({skip_initial_, tolerance_, confidence_, series_, last_at_time_, truth_input_, estimate_inputs > 0,
                         measurement_input_, !truth_input_},
                        &channels_);
    if (estimate_inputs > 1)
      throw ConfigError("inputs " + estimate_sources +
                        " all deliver estimates, but the metrics of one filter are computed per node: "
                        "use one sink.metrics per filter");
  }

  void start_run(const RunContext&) override {
    if (streaming_) return scorer_.start_run();
    constexpr size_t kReserve = 4096;  // the stored path's buffers (a no-op after the first run)
    truth_.reserve(kReserve);
    estimates_.reserve(kReserve);
    measurements_.reserve(kReserve);
    truth_nan_time_ = false;
    truth_.clear();
    estimates_.clear();
    measurements_.clear();
  }

  void on_truth(const Truth& t, int) override {
    if (streaming_) return scorer_.on_truth(t);
    truth_nan_time_ = truth_nan_time_ || std::isnan(t.time);
    metrics::insert_truth(truth_, t);
  }

  // Every estimate is kept (uninitialised ones only count towards the per-step fractions).
  void on_estimate(const Estimate& e, int) override {
    if (streaming_) return scorer_.on_estimate(e);
    if (!e.initialised && !series_) return;
    const bool replace = last_at_time_ && !estimates_.empty() && std::abs(e.time - estimates_.back().time) <= tolerance_;
    StoredEstimate& s = replace ? estimates_.back() : estimates_.emplace_back();
    if (replace) s = StoredEstimate{};
    s.time = e.time;
    s.target = e.target;
    s.initialised = e.initialised;
    s.updated = e.updated;
    if (!e.initialised) return;
    s.nis = e.nis;
    s.enu = e.enu;
    s.covariance = e.enu_covariance;
    s.innovation = e.innovation;
    if (series_) channels_.read(e, s.annotation);
  }

  void on_measurement(const Measurement& m, int) override {
    if (!m.valid || m.value.size() < m.position_dim()) return;
    const Vec3 p = measured_position(m);
    if (streaming_) return scorer_.on_measurement(m.time, p);
    measurements_.push_back({m.time, p});
  }

  std::unique_ptr<RunResult> end_run() override {
    if (streaming_) return scorer_.end_run();
    auto r = std::make_unique<MetricsRunResult>();
    r->had_truth = !truth_.empty();
    r->records.reserve(estimates_.size());
    r->measurement_records.reserve(measurements_.size());
    const double start = window_start();
    // One target whose samples are in time order: lookups walk forward from the previous one.
    cursor_ = nullptr;
    use_cursor_ = !truth_nan_time_ && metrics::single_target(truth_);
    for (const StoredEstimate& e : estimates_) {
      if (!std::isfinite(e.time)) {
        if (e.initialised) ++r->non_finite;
        continue;
      }
      EstimateRecord& rec = r->records.emplace_back();
      rec.key = metrics::round_key(e.time / tolerance_);
      rec.time = e.time;
      rec.initialised = e.initialised;
      rec.updated = e.initialised && e.updated;
      if (!e.initialised) continue;
      std::copy(std::begin(e.annotation), std::end(e.annotation), std::begin(rec.annotation));
      if (e.time + tolerance_ < start) {
        ++r->before_window;
        continue;
      }
      if (!e.enu.allFinite()) {
        ++r->non_finite;
        continue;
      }
      evaluate(e, rec, *r);
    }
    measurement_errors(start, *r);
    return r;
  }

  void merge(RunResult& result) override { ensemble_.add(static_cast<MetricsRunResult&>(result)); }

  void finish(Summary& summary, const FinishContext&) override {
    const metrics::ReportOptions opt{confidence_, skip_initial_, truth_input_, measurement_input_};
    metrics::report(ensemble_, opt, summary);
    if (series_ && ensemble_.runs > 0) summary.series.push_back(metrics::ensemble_series(ensemble_, opt, channels_));
    if (series_ && ensemble_.bin_width > 1)
      summary.notes.push_back("series: " + std::to_string(ensemble_.bins.size()) + " rows, each the mean over " +
                              number_text::general(static_cast<double>(ensemble_.bin_width) * tolerance_, 6) +
                              " s of the runs' steps (a run without truth keeps at most " +
                              std::to_string(metrics::kMaxSeriesBins) + " series rows in memory)");
  }

 private:
  struct StoredEstimate {
    double time = 0.0;
    std::uint32_t target = 0;
    bool initialised = false, updated = false;
    double nis = 0.0;
    Vec6 enu;
    Mat6 covariance;
    MeasVec innovation;
    float annotation[metrics::kMaxAnnotations] = {};
  };
  struct StoredMeasurement {
    double time;
    Vec3 position;
  };

  // The transient to leave out is measured from the first initialised estimate; a run without
  // estimates (a measurement-only baseline) starts at its first measurement.
  double window_start() const {
    double first = std::numeric_limits<double>::infinity();
    for (const auto& e : estimates_)
      if (e.initialised) first = std::min(first, e.time);
    if (!std::isfinite(first))
      for (const auto& m : measurements_) first = std::min(first, m.time);
    return first + skip_initial_;
  }

  void evaluate(const StoredEstimate& e, EstimateRecord& rec, MetricsRunResult& r) const {
    metrics::score_innovation(rec, e.updated, e.nis, e.innovation);
    Vec6 truth;
    if (!metrics::truth_at(metrics::truth_for(truth_, e.target), e.time, tolerance_, truth,
                           use_cursor_ ? &cursor_ : nullptr)) {
      ++r.unmatched;
      return;
    }
    metrics::score_error(rec, e.enu, e.covariance, truth, r);
  }

  void measurement_errors(double start, MetricsRunResult& r) const {
    // Measurements carry a sensor, not a target, so they can only be scored against a single truth target.
    const bool usable = metrics::single_target(truth_);
    const metrics::TruthSpan span = metrics::truth_for(truth_, 0);
    const Truth* cursor = nullptr;
    const Truth** from = truth_nan_time_ ? nullptr : &cursor;
    for (const auto& m : measurements_) {
      if (m.time + tolerance_ < start) continue;
      Vec6 truth;
      const bool matched = usable && metrics::truth_at(span, m.time, tolerance_, truth, from);
      metrics::add_measurement(r, m.time, matched, matched ? (m.position - truth.head<3>()).squaredNorm() : 0.0,
                               tolerance_, series_);
    }
  }

  const double skip_initial_, confidence_, tolerance_;
  const bool series_, last_at_time_;
  bool truth_input_ = false, measurement_input_ = false;
  bool streaming_ = false;  // every input time-ordered: scorer_ takes the items
  metrics::StreamScorer scorer_;
  bool truth_nan_time_ = false;  // a truth sample without a time: samples not in time order
  std::vector<Truth> truth_;
  // end_run's truth lookups (evaluate): where the last one ended, and whether to start there.
  mutable const Truth* cursor_ = nullptr;
  bool use_cursor_ = false;
  std::vector<StoredEstimate> estimates_;
  std::vector<StoredMeasurement> measurements_;
  metrics::AnnotationChannels channels_;
  metrics::Ensemble ensemble_;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sink.metrics";
  d.kind = ComponentKind::Sink;
  d.summary = "Ensemble RMSE, bias, ANEES and ANIS with chi-square bands of one filter against truth";
  d.doc =
      "Inputs: one filter's estimates, truth, and optionally converted measurements (for a measurement-only "
      "RMSE baseline and rmse_ratio), e.g. inputs: [kf, truth, cm]. Estimates are matched to truth at the same "
      "time (within time_tolerance) or by linear interpolation between truth samples; estimates outside the "
      "truth's time span are counted as unmatched_estimates. ANEES_k = sum over runs of NEES / (n M) per time "
      "step (n = 6, or 3 for anees_position), inside its per-step band "
      "[chi2inv((1-c)/2, nM), chi2inv((1+c)/2, nM)]/(nM) when consistent (Bar-Shalom, Li & Kirubarajan 2001 "
      "§5.4.2). The verdict is the per-step test: anees_steps_in_band, the fraction of steps inside their band, "
      "against the binomial acceptance for the effective number of independent steps (anees_effective_steps: "
      "the errors are correlated in time); anees, the mean over steps, has no band. ANIS likewise with the "
      "innovation dimension, whose steps are independent when consistent, so anis also gets the band of the mean "
      "(docs/report.md, Consistency tests). Without truth (recorded logs) only anis, mean_innovation_<i> "
      "and counts are reported. Only initialised estimates are scored. When every input is time-ordered (its "
      "sources declare so, e.g. sim.trajectory, source.csv) a run is scored as it arrives: an estimate as soon as "
      "its truth is certain, with only those still waiting for truth kept; without truth nothing is kept per "
      "estimate, anis is summed per run (the same mean when the runs share their time steps, else a note), and "
      "the series is kept in at most 16384 rows: a longer log's rows are means over bins of 2^k time_tolerance "
      "seconds (said in a note), so memory stays flat however long the log. Per time step it also publishes the "
      "ensemble series (`trackflow run --series`, `trackflow report`): position/velocity RMSE, mean error per axis, "
      "ANEES and ANIS with the band for the runs at that step, measurement RMSE, fractions of runs initialised and "
      "updated, and the mean of each adapter annotation (e.g. quality grades, adapted sigmas); the series' mean ANEES "
      "is anees.";
  d.params = {
      ParamSpec::real("skip_initial", dim::time, "leave out estimates earlier than the first initialised estimate + this (transient)")
          .def("0 s")
          .at_least(0),
      ParamSpec::real("confidence", dim::none, "probability of the chi-square acceptance bands, in (0, 1)")
          .def("0.95")
          .positive()
          .at_most(1),
      ParamSpec::real("time_tolerance", dim::time, "items closer in time than this are the same time step")
          .def("1 us")
          .positive(),
      ParamSpec::choice<SameTime>("same_time", {{SameTime::All, "all"}, {SameTime::Last, "last"}},
                                  "several estimates of one run at one time (within time_tolerance; a filter with "
                                  "several sensors, a fusion node): score all, or only the last of them (its ANIS "
                                  "then sees only that estimate's innovation)")
          .def("all"),
      ParamSpec::boolean("series",
                         "publish the per-step ensemble series (measurement RMSE, fractions of runs, annotations per "
                         "step); false keeps only what the summary needs")
          .def("true"),
  };
  d.accepts = ItemKind::Estimate | ItemKind::Truth | mask(ItemKind::Measurement);
  d.min_inputs = 1;
  d.max_inputs = -1;
  d.produces = 0;
  d.create = [](const Params& p) { return std::make_unique<MetricsSink>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sink.metrics", trackflow::register_components)
