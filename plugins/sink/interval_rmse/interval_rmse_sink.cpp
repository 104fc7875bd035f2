// Purpose: sink.interval_rmse — a filter's position RMSE next to the measurements' own, interval by interval (e.g. every 60 s of a launch).
#include "scoring/truth_match.hpp"

#include <trackflow/number_text.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace trackflow {
namespace {

struct Bin {
  double filter_sq = 0.0, measurement_sq = 0.0;
  std::uint64_t filter_n = 0, measurement_n = 0;
};

struct IntervalRunResult final : RunResult {
  std::vector<Bin> bins;
  std::uint64_t non_finite = 0, unmatched = 0;
  // Its codec under mpirun (run_result_codec.hpp): one list, written and read in this order.
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.bins, r.non_finite, r.unmatched);
  }
};

// Items are stored during the run and scored in end_run(), when all truth has arrived.
class IntervalRmseSink final : public Component, public FieldListCodec<IntervalRunResult> {
 public:
  IntervalRmseSink(double start, double interval, double skip_initial, double tolerance)
      : start_(start), interval_(interval), skip_initial_(skip_initial), tolerance_(tolerance) {
    truth_.reserve(1 << 15);
    estimates_.reserve(1 << 15);
    measurements_.reserve(1 << 15);
  }

  void set_inputs(const std::vector<InputInfo>& inputs) override {
    int estimate_inputs = 0, measurement_inputs = 0;
    for (const auto& in : inputs) {
      estimate_inputs += (in.kinds & mask(ItemKind::Estimate)) != 0;
      measurement_inputs += (in.kinds & mask(ItemKind::Measurement)) != 0;
    }
    if (estimate_inputs != 1 || measurement_inputs != 1)
      throw ConfigError("sink.interval_rmse compares one filter with one measurement stream: inputs: [filter, truth, "
                        "radar] (got " + std::to_string(estimate_inputs) + " estimate and " +
                        std::to_string(measurement_inputs) + " measurement inputs)");
  }

  void start_run(const RunContext&) override {
    truth_.clear();
    estimates_.clear();
    measurements_.clear();
  }

  void on_truth(const Truth& t, int) override { metrics::insert_truth(truth_, t); }

  void on_estimate(const Estimate& e, int) override {
    if (!e.initialised) return;
    estimates_.push_back({e.time, e.target, e.enu.allFinite(), e.enu.head<3>()});
  }

  void on_measurement(const Measurement& m, int) override {
    if (!m.valid || m.value.size() < m.position_dim() || !m.value.head(m.position_dim()).allFinite()) return;
    const Vec3 p = measured_position(m);
    measurements_.push_back({m.time, 0, true, p});
  }

  std::unique_ptr<RunResult> end_run() override {
    auto r = std::make_unique<IntervalRunResult>();
    double first = std::numeric_limits<double>::infinity();
    for (const auto& e : estimates_) first = std::min(first, e.time);
    const double from = first + skip_initial_ - tolerance_;
    const bool single = metrics::single_target(truth_);
    for (const auto& e : estimates_) {
      if (e.time < from) continue;
      if (!e.finite) {
        ++r->non_finite;
        continue;
      }
      score(e, metrics::truth_for(truth_, e.target), *r, true);
    }
    if (single)  // measurements carry no target id: only a single truth target can score them
      for (const auto& m : measurements_)
        if (m.time >= from) score(m, metrics::truth_for(truth_, 0), *r, false);
    return r;
  }

  void merge(RunResult& result) override {
    auto& r = static_cast<IntervalRunResult&>(result);
    ++runs_;
    non_finite_ += r.non_finite;
    unmatched_ += r.unmatched;
    if (bins_.size() < r.bins.size()) bins_.resize(r.bins.size());
    for (size_t i = 0; i < r.bins.size(); ++i) {
      bins_[i].filter_sq += r.bins[i].filter_sq;
      bins_[i].measurement_sq += r.bins[i].measurement_sq;
      bins_[i].filter_n += r.bins[i].filter_n;
      bins_[i].measurement_n += r.bins[i].measurement_n;
    }
  }

  void finish(Summary& s, const FinishContext&) override {
    double worst = 0.0;
    std::uint64_t compared = 0;
    for (size_t i = 0; i < bins_.size(); ++i) {
      const Bin& b = bins_[i];
      if (b.filter_n == 0 && b.measurement_n == 0) continue;
      const std::string at = label(i);
      const double f = b.filter_n ? std::sqrt(b.filter_sq / static_cast<double>(b.filter_n)) : NAN;
      const double m = b.measurement_n ? std::sqrt(b.measurement_sq / static_cast<double>(b.measurement_n)) : NAN;
      if (b.filter_n) s.metric("filter_rmse_" + at, f, "m");
      if (b.measurement_n) s.metric("measurement_rmse_" + at, m, "m");
      if (b.filter_n && b.measurement_n && m > 0.0) {
        s.metric("ratio_" + at, f / m);
        worst = std::max(worst, f / m);
        ++compared;
      } else {
        s.notes.push_back("interval " + at + ": no ratio (it lacks filter estimates or measurements)");
      }
    }
    s.series.push_back(series());
    s.metric("intervals", static_cast<double>(compared));
    if (compared) s.metric("max_ratio", worst);
    s.metric("non_finite_estimates", static_cast<double>(non_finite_));
    s.notes.push_back("per interval [start + k interval, start + (k+1) interval): ensemble RMS of |p - p_true| of the "
                      "filter and of the valid measurements (converted to ENU); metric names carry the interval's "
                      "start time; max_ratio = the largest filter/measurement ratio");
    if (unmatched_) s.notes.push_back(std::to_string(unmatched_) + " item(s) could not be matched to truth");
    if (non_finite_) s.notes.push_back(std::to_string(non_finite_) + " estimate(s) with a non-finite state left out");
  }

 private:
  struct Stored {
    double time;
    std::uint32_t target;
    bool finite;
    Vec3 position;
  };

  void score(const Stored& item, metrics::TruthSpan span, IntervalRunResult& r, bool filter) const {
    const double k = std::floor((item.time - start_ + tolerance_) / interval_);
    if (!(k >= 0.0) || k > 1e6) return;
    Vec6 truth;
    if (!metrics::truth_at(span, item.time, tolerance_, truth)) {
      ++r.unmatched;
      return;
    }
    const size_t i = static_cast<size_t>(k);
    if (r.bins.size() <= i) r.bins.resize(i + 1);
    const double sq = (item.position - truth.head<3>()).squaredNorm();
    if (filter) {
      r.bins[i].filter_sq += sq;
      ++r.bins[i].filter_n;
    } else {
      r.bins[i].measurement_sq += sq;
      ++r.bins[i].measurement_n;
    }
  }

  // The same numbers per interval as a table (`run --series`, `trackflow report`).
  Series series() const {
    Series t;
    t.name = "intervals";
    t.description = "per interval [start, start + interval): ensemble position RMSE of the filter and of the measurements";
    t.add_column("interval_start", "s");
    t.add_column("filter_rmse", "m");
    t.add_column("measurement_rmse", "m");
    t.add_column("ratio");
    for (size_t i = 0; i < bins_.size(); ++i) {
      const Bin& b = bins_[i];
      if (b.filter_n == 0 && b.measurement_n == 0) continue;
      const double f = b.filter_n ? std::sqrt(b.filter_sq / static_cast<double>(b.filter_n)) : NAN;
      const double m = b.measurement_n ? std::sqrt(b.measurement_sq / static_cast<double>(b.measurement_n)) : NAN;
      t.values.insert(t.values.end(), {start_ + static_cast<double>(i) * interval_, f, m, m > 0.0 ? f / m : NAN});
    }
    return t;
  }

  std::string label(size_t i) const {
    std::string s = number_text::general(start_ + static_cast<double>(i) * interval_, 6) + "s";  // printf's "%gs"
    std::replace(s.begin(), s.end(), '.', 'p');
    std::replace(s.begin(), s.end(), '-', 'm');
    s.erase(std::remove(s.begin(), s.end(), '+'), s.end());
    return s;
  }

  const double start_, interval_, skip_initial_, tolerance_;
  std::vector<Truth> truth_;
  std::vector<Stored> estimates_, measurements_;
  // Aggregating instance.
  std::uint64_t runs_ = 0, non_finite_ = 0, unmatched_ = 0;
  std::vector<Bin> bins_;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sink.interval_rmse";
  d.kind = ComponentKind::Sink;
  d.summary = "A filter's position RMSE next to the measurements' own, per time interval (e.g. every 60 s)";
  d.doc =
      "Inputs: one filter's estimates, the truth and one measurement stream, e.g. inputs: [kf, truth, radar]. For each "
      "interval [start + k interval, start + (k+1) interval): filter_rmse_<t0>s = ensemble RMS over runs and samples "
      "of the initialised estimates' position error, measurement_rmse_<t0>s the same for the valid measurements "
      "(spherical ones converted to ENU), ratio_<t0>s their quotient (t0 = the interval's start, '.' written 'p'). "
      "max_ratio is the largest ratio: below 1, the filter beats the raw measurements in every interval. Items "
      "earlier than the first estimate + skip_initial are left out. Truth is matched as in sink.metrics. The same "
      "numbers are published as the series 'intervals' (`trackflow run --series`, `trackflow report`).";
  d.params = {
      ParamSpec::real("interval", dim::time, "length of each interval").def("60 s").positive(),
      ParamSpec::real("start", dim::time, "start of the first interval").def("0 s"),
      ParamSpec::real("skip_initial", dim::time, "leave out items before the first estimate + this (transient)")
          .def("0 s")
          .at_least(0),
      ParamSpec::real("time_tolerance", dim::time, "items closer in time than this are the same time step")
          .def("1 us")
          .positive(),
  };
  d.accepts = ItemKind::Estimate | ItemKind::Truth | mask(ItemKind::Measurement);
  d.min_inputs = 3;
  d.max_inputs = 3;
  d.produces = 0;
  d.create = [](const Params& p) {
    return std::make_unique<IntervalRmseSink>(p.real("start"), p.real("interval"), p.real("skip_initial"),
                                              p.real("time_tolerance"));
  };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sink.interval_rmse", trackflow::register_components)
