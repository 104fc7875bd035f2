// Purpose: sink.recovery — how many samples a filter needs after each shot-noise burst to return near the truth, and its RMSE outside the bursts.
#include "burst_recovery.hpp"
#include "scoring/truth_match.hpp"

#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace trackflow {
namespace {

struct RecoveryRunResult final : RunResult {
  recovery::RunStats stats;
  std::uint64_t non_finite = 0, unmatched = 0, samples = 0;
  // Its codec under mpirun (run_result_codec.hpp): one list, written and read in this order.
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.stats.bursts, r.stats.sq_error, r.stats.count, r.non_finite, r.unmatched, r.samples);
  }
};

// Estimates are stored during the run and judged in end_run(), when all truth has arrived.
class RecoverySink final : public Component, public FieldListCodec<RecoveryRunResult> {
 public:
  RecoverySink(const recovery::Settings& s, double skip_initial, double tolerance)
      : s_(s), skip_initial_(skip_initial), tolerance_(tolerance) {
    truth_.reserve(1 << 14);
    estimates_.reserve(1 << 14);
    samples_.reserve(1 << 14);
  }

  void set_inputs(const std::vector<InputInfo>& inputs) override {
    int estimate_inputs = 0;
    for (const auto& in : inputs) estimate_inputs += (in.kinds & mask(ItemKind::Estimate)) != 0;
    if (estimate_inputs != 1)
      throw ConfigError("sink.recovery judges one filter: give exactly one estimate input and the truth, e.g. "
                        "inputs: [kf, truth] (got " + std::to_string(estimate_inputs) + " estimate inputs)");
  }

  void start_run(const RunContext&) override {
    truth_.clear();
    estimates_.clear();
  }

  void on_truth(const Truth& t, int) override { metrics::insert_truth(truth_, t); }

  // Every estimate is a sample, initialised or not: the burst schedule counts the radar's
  // measurements, and the filter publishes one estimate per measurement.
  void on_estimate(const Estimate& e, int) override {
    estimates_.push_back({e.time, e.target, e.initialised,
                          e.initialised && !(e.enu.allFinite() && e.enu_covariance.allFinite()), e.enu.head<3>()});
  }

  std::unique_ptr<RunResult> end_run() override {
    auto r = std::make_unique<RecoveryRunResult>();
    samples_.assign(estimates_.size(), recovery::Sample{});
    double first = std::numeric_limits<double>::infinity();
    for (const auto& e : estimates_)
      if (e.initialised) first = std::min(first, e.time);
    for (size_t k = 0; k < estimates_.size(); ++k) {
      const Stored& e = estimates_[k];
      if (!e.initialised) continue;
      if (e.non_finite) {
        ++r->non_finite;
        continue;
      }
      Vec6 truth;
      if (!metrics::truth_at(metrics::truth_for(truth_, e.target), e.time, tolerance_, truth)) {
        ++r->unmatched;
        continue;
      }
      samples_[k].error = (e.position - truth.head<3>()).norm();
      samples_[k].scored = e.time + tolerance_ >= first + skip_initial_;
    }
    r->samples = samples_.size();
    r->stats = recovery::evaluate(samples_, s_);
    return r;
  }

  void merge(RunResult& result) override {
    const auto& r = static_cast<RecoveryRunResult&>(result);
    ++runs_;
    non_finite_ += r.non_finite;
    unmatched_ += r.unmatched;
    sq_error_ += r.stats.sq_error;
    scored_ += r.stats.count;
    for (const auto& b : r.stats.bursts) {
      ++bursts_;
      unrecovered_ += !b.recovered;
      sum_samples_ += static_cast<double>(b.samples);
      max_samples_ = std::max(max_samples_, static_cast<double>(b.samples));
      peak_sum_ += b.peak_error;
    }
  }

  void finish(Summary& s, const FinishContext&) override {
    s.metric("non_finite_estimates", static_cast<double>(non_finite_));
    s.metric("runs", static_cast<double>(runs_));
    if (scored_ > 0)
      s.metric("rmse_excluding_bursts", std::sqrt(sq_error_ / static_cast<double>(scored_)), "m");
    else
      s.notes.push_back("rmse_excluding_bursts not reported: no estimate outside the bursts was matched to truth");
    s.metric("bursts", static_cast<double>(bursts_));
    if (bursts_ == 0) {
      s.notes.push_back("no burst was followed by a sample: the runs are shorter than shot_offset + shot_length");
    } else {
      s.metric("unrecovered_bursts", static_cast<double>(unrecovered_));
      s.metric("mean_recovery_samples", sum_samples_ / static_cast<double>(bursts_));
      s.metric("max_recovery_samples", max_samples_);
      const double peak = peak_sum_ / static_cast<double>(bursts_);
      if (std::isfinite(peak))
        s.metric("mean_peak_error", peak, "m");
      else
        s.notes.push_back("mean_peak_error not reported: some burst had an estimate without a finite, matched error");
    }
    char text[160];
    std::snprintf(text, sizeof text,
                  "recovered: position error <= %g m for %lld consecutive samples; an unrecovered burst counts the "
                  "samples up to the next burst or the end of the run",
                  s_.threshold, s_.hold);
    s.notes.push_back(text);
    if (unmatched_)
      s.notes.push_back(std::to_string(unmatched_) + " initialised estimate(s) could not be matched to truth");
    if (non_finite_)
      s.notes.push_back(std::to_string(non_finite_) + " initialised estimate(s) had a non-finite state or covariance");
  }

 private:
  struct Stored {
    double time;
    std::uint32_t target;
    bool initialised, non_finite;
    Vec3 position;
  };

  const recovery::Settings s_;
  const double skip_initial_, tolerance_;
  std::vector<Truth> truth_;
  std::vector<Stored> estimates_;
  std::vector<recovery::Sample> samples_;
  // Aggregating instance.
  std::uint64_t runs_ = 0, non_finite_ = 0, unmatched_ = 0, scored_ = 0, bursts_ = 0, unrecovered_ = 0;
  double sq_error_ = 0.0, sum_samples_ = 0.0, max_samples_ = 0.0, peak_sum_ = 0.0;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sink.recovery";
  d.kind = ComponentKind::Sink;
  d.summary = "Shot-noise recovery of one filter: samples after each burst until the position error is back within a "
              "threshold, and the RMSE outside the bursts";
  d.doc =
      "Inputs: one filter's estimates and the truth, e.g. inputs: [kf, truth]. Samples are the filter's estimates of "
      "a run counted from 0 (one per radar measurement, initialised or not), so shot_period/shot_length/shot_offset "
      "are sim.radar's values. For each burst [s, s + length): recovery_samples = the number of samples after its "
      "last one until the first of `hold` consecutive samples whose position error |p - p_true| <= threshold (0: "
      "already within right after the burst). A burst not recovered before the next burst starts (or the run ends) "
      "counts the samples available and is an unrecovered_burst. mean_peak_error: the largest position error from the "
      "burst's start until recovery, averaged over bursts. rmse_excluding_bursts: position RMSE over initialised "
      "estimates after skip_initial, leaving out the burst samples and exclude_after samples after each. "
      "non_finite_estimates counts initialised estimates with a NaN/inf state or covariance (left out of everything "
      "else). Truth is matched as in sink.metrics (same time, else linear interpolation).";
  d.params = {
      ParamSpec::integer("shot_length", "samples per burst (sim.radar shot_length)").def("10").at_least(1),
      ParamSpec::integer("shot_period", "samples from one burst start to the next (sim.radar shot_period)")
          .def("4000")
          .at_least(1),
      ParamSpec::integer("shot_offset", "sample index of the first burst (default: shot_period, as sim.radar)").at_least(0),
      ParamSpec::real("threshold", dim::length, "position error that counts as recovered, e.g. 3 sigma of the measurement")
          .req()
          .positive(),
      ParamSpec::integer("hold", "consecutive samples within the threshold that make a recovery").def("1").at_least(1),
      ParamSpec::integer("exclude_after", "samples after each burst also left out of rmse_excluding_bursts")
          .def("0")
          .at_least(0),
      ParamSpec::real("skip_initial", dim::time, "leave the first estimates (initial transient) out of the RMSE")
          .def("0 s")
          .at_least(0),
      ParamSpec::real("time_tolerance", dim::time, "items closer in time than this are the same time step")
          .def("1 us")
          .positive(),
  };
  d.accepts = ItemKind::Estimate | ItemKind::Truth;
  d.min_inputs = 2;
  d.max_inputs = 2;
  d.produces = 0;
  d.create = [](const Params& p) {
    recovery::Settings s;
    s.bursts.length = p.integer("shot_length");
    s.bursts.period = p.integer("shot_period");
    s.bursts.offset = p.has("shot_offset") ? p.integer("shot_offset") : s.bursts.period;
    s.threshold = p.real("threshold");
    s.hold = p.integer("hold");
    s.exclude_after = p.integer("exclude_after");
    if (s.bursts.length > s.bursts.period)
      throw p.error("shot_length", "must not exceed shot_period (" + std::to_string(s.bursts.period) + ")");
    if (s.bursts.length + s.exclude_after > s.bursts.period)
      throw p.error("exclude_after", "shot_length + exclude_after must not exceed shot_period (nothing would be left)");
    return std::make_unique<RecoverySink>(s, p.real("skip_initial"), p.real("time_tolerance"));
  };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sink.recovery", trackflow::register_components)
