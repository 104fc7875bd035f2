// Purpose: sink.gospa — GOSPA (with its localisation / missed / false parts for alpha = 2) and OSPA between truth and a tracker's track sets, per scan, Monte Carlo means and a per-step series.
#include "scoring/gospa.hpp"
#include "scoring/track_set_sink.hpp"

#include <trackflow/number_text.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/tracks.hpp>

#include <boost/math/distributions/students_t.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace trackflow {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One scored TrackSet. Parts are contributions to the p-th power: localisation + missed + false
// == gospa_pow_p (alpha = 2; 0 otherwise).
struct GospaStep {
  double time = 0.0;
  double gospa = 0.0, gospa_pow_p = 0.0, ospa = 0.0;
  double localisation = 0.0, missed = 0.0, false_tracks = 0.0;
  std::int32_t truths = 0, tracks = 0, missed_count = 0, false_count = 0;
};

struct GospaRunResult final : RunResult {
  std::uint64_t steps = 0;
  GospaStep sum;                       // sums over the scored steps (time unused)
  std::uint64_t non_finite_tracks = 0; // selected tracks with a non-finite position: left out
  std::uint64_t non_finite_truths = 0;
  std::uint64_t unscored_truth_steps = 0;  // truth batches with no TrackSet at their time
  std::uint64_t steps_without_truth = 0;   // TrackSets with no truth at their time (scored against none)
  std::uint64_t before_window = 0;         // TrackSets left out by skip_initial
  std::vector<GospaStep> series;           // per scored step, when `series`
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.steps, r.sum, r.non_finite_tracks, r.non_finite_truths, r.unscored_truth_steps, r.steps_without_truth,
      r.before_window, r.series);
  }
};

void add(GospaStep& a, const GospaStep& b) {
  a.gospa += b.gospa;
  a.gospa_pow_p += b.gospa_pow_p;
  a.ospa += b.ospa;
  a.localisation += b.localisation;
  a.missed += b.missed;
  a.false_tracks += b.false_tracks;
  a.truths += b.truths;
  a.tracks += b.tracks;
  a.missed_count += b.missed_count;
  a.false_count += b.false_count;
}

// Per-step sums over runs; counts as doubles (many runs of many targets).
struct StepSums {
  double time = 0.0;
  std::uint64_t runs = 0;
  double v[10] = {};
};

void add(StepSums& s, const GospaStep& g) {
  const double x[10] = {g.gospa,       g.gospa_pow_p,  g.ospa,     g.localisation,   g.missed,
                        g.false_tracks, double(g.truths), double(g.tracks), double(g.missed_count), double(g.false_count)};
  for (int i = 0; i < 10; ++i) s.v[i] += x[i];
  ++s.runs;
}

constexpr const char* kNames[10] = {"gospa",          "gospa_pow_p",    "ospa",   "gospa_localisation",
                                    "gospa_missed",   "gospa_false",    "truths", "tracks",
                                    "missed_targets", "false_tracks"};

enum class Dims { Two = 2, Three = 3 };

// Streams: truths of one time are kept until the next time's; each TrackSet is scored on arrival
// against the truths of exactly its time stamp. Buffers keep their capacity between scans and runs.
class GospaSink final : public Component, public FieldListCodec<GospaRunResult> {
 public:
  explicit GospaSink(const Params& p)
      : gospa_(p.real("cutoff"), p.real("order"), p.real("alpha")),
        statuses_(scoring::parse_track_statuses(p)),
        dims_(scoring::planar_dimensions(p) ? Dims::Two : Dims::Three),
        skip_initial_(p.real("skip_initial")),
        series_(p.boolean("series")) {}

  void set_inputs(const std::vector<InputInfo>& inputs) override { scoring::check_track_set_inputs(inputs, "sink.gospa"); }

  void start_run(const RunContext&) override {
    run_.steps = 0;
    run_.sum = GospaStep{};
    run_.non_finite_tracks = run_.non_finite_truths = run_.unscored_truth_steps = run_.steps_without_truth =
        run_.before_window = 0;
    run_.series.clear();  // keeps its capacity
    truth3_.clear();
    truth2_.clear();
    have_batch_ = false;
    batch_used_ = false;
    first_set_ = kNaN;
  }

  void on_truth(const Truth& t, int) override {
    if (!have_batch_ || t.time != batch_time_) {
      close_batch();
      have_batch_ = true;
      batch_used_ = false;
      batch_time_ = t.time;
      truth3_.clear();
      truth2_.clear();
    }
    if (!t.position.allFinite()) {
      ++run_.non_finite_truths;
      return;
    }
    truth3_.push_back(t.position);
    truth2_.push_back(t.position.head<2>());
  }

  void on_tracks(const TrackSet& set, int) override {
    if (std::isnan(first_set_)) first_set_ = set.time;
    const bool truth_now = have_batch_ && batch_time_ == set.time;
    if (truth_now) batch_used_ = true;
    if (set.time < first_set_ + skip_initial_) {
      ++run_.before_window;
      return;
    }
    track3_.clear();
    track2_.clear();
    for (const TrackEstimate& te : set.tracks) {
      if (!scoring::status_selected(statuses_, te.status) || !te.estimate.initialised) continue;
      const Vec3 pos = te.estimate.enu.head<3>();
      if (dims_ == Dims::Three ? !pos.allFinite() : !pos.head<2>().allFinite()) {
        ++run_.non_finite_tracks;
        continue;
      }
      track3_.push_back(pos);
      track2_.push_back(pos.head<2>());
    }
    if (!truth_now) {
      ++run_.steps_without_truth;
      truth3_.clear();
      truth2_.clear();
    }
    const metrics::GospaResult r =
        dims_ == Dims::Three
            ? gospa_.evaluate<3>(std::span<const Eigen::Vector3d>(truth3_), std::span<const Eigen::Vector3d>(track3_))
            : gospa_.evaluate<2>(std::span<const Eigen::Vector2d>(truth2_), std::span<const Eigen::Vector2d>(track2_));
    GospaStep s;
    s.time = set.time;
    s.gospa = r.gospa;
    s.gospa_pow_p = r.gospa_pow_p;
    s.ospa = r.ospa;
    s.truths = static_cast<std::int32_t>(truth3_.size());
    s.tracks = static_cast<std::int32_t>(track3_.size());
    int detected = 0;
    for (int j : r.track_for_truth) detected += j >= 0 ? 1 : 0;
    s.missed_count = s.truths - detected;
    s.false_count = s.tracks - detected;
    if (r.decomposition) {
      s.localisation = r.decomposition->localisation;
      s.missed = r.decomposition->missed;
      s.false_tracks = r.decomposition->false_tracks;
    }
    ++run_.steps;
    add(run_.sum, s);
    if (series_) run_.series.push_back(s);
  }

  std::unique_ptr<RunResult> end_run() override {
    close_batch();
    have_batch_ = false;
    return std::make_unique<GospaRunResult>(run_);
  }

  void merge(RunResult& result) override {
    const auto& r = static_cast<const GospaRunResult&>(result);
    ++runs_;
    non_finite_tracks_ += r.non_finite_tracks;
    non_finite_truths_ += r.non_finite_truths;
    unscored_truth_steps_ += r.unscored_truth_steps;
    steps_without_truth_ += r.steps_without_truth;
    steps_ += r.steps;
    if (r.steps) {
      ++scored_runs_;
      const double n = static_cast<double>(r.steps);
      const double x[10] = {r.sum.gospa,       r.sum.gospa_pow_p,   r.sum.ospa,         r.sum.localisation,
                            r.sum.missed,      r.sum.false_tracks,  double(r.sum.truths), double(r.sum.tracks),
                            double(r.sum.missed_count), double(r.sum.false_count)};
      for (int i = 0; i < 10; ++i) {
        run_mean_sum_[i] += x[i] / n;
        run_mean_sq_[i] += (x[i] / n) * (x[i] / n);
      }
    }
    for (const GospaStep& g : r.series) {
      StepSums& st = steps_by_time_[std::llround(g.time * 1e6)];
      st.time = g.time;
      add(st, g);
    }
  }

  void finish(Summary& s, const FinishContext&) override {
    const bool parts = gospa_.alpha() == 2.0;
    const std::string unit_p = gospa_.order() == 1.0 ? "m" : gospa_.order() == 2.0 ? "m2" : "";
    const std::string units[10] = {"m", unit_p, "m", unit_p, unit_p, unit_p, "", "", "", ""};
    const double runs = static_cast<double>(scored_runs_);
    for (int i = 0; i < 10; ++i) {
      if (!parts && i >= 3 && i <= 5) continue;
      if (!scored_runs_) break;
      const double mean = run_mean_sum_[i] / runs;
      s.metric(kNames[i], mean, units[i]);
      if (i == 0 && scored_runs_ >= 2) {
        // 95 % Student-t interval of the mean of the run means.
        const double var = std::max(0.0, (run_mean_sq_[i] - runs * mean * mean) / (runs - 1.0));
        const boost::math::students_t t(runs - 1.0);
        const double half = boost::math::quantile(boost::math::complement(t, 0.025)) * std::sqrt(var / runs);
        s.metric("gospa_ci95_lo", mean - half, "m");
        s.metric("gospa_ci95_hi", mean + half, "m");
      }
    }
    s.metric("runs_scored", runs);
    s.metric("scored_steps", static_cast<double>(steps_));
    s.metric("non_finite_tracks", static_cast<double>(non_finite_tracks_));
    if (non_finite_truths_) s.metric("non_finite_truths", static_cast<double>(non_finite_truths_));
    s.metric("unscored_truth_steps", static_cast<double>(unscored_truth_steps_));
    s.metric("steps_without_truth", static_cast<double>(steps_without_truth_));
    s.notes.push_back(
        "GOSPA (c = " + number_text::general(gospa_.cutoff(), 6) + " m, p = " + number_text::general(gospa_.order(), 6) +
        ", alpha = " + number_text::general(gospa_.alpha(), 6) + ") per TrackSet against the truths of exactly its time; " +
        "gospa: mean over a run's steps of d, then over runs; gospa_pow_p: the same of d^p" +
        (parts ? ", = gospa_localisation + gospa_missed + gospa_false (means of the p-th-power parts)" : "") +
        "; missed_targets / false_tracks: per step, truths / tracks without a partner closer than c");
    if (non_finite_tracks_ || non_finite_truths_)
      s.notes.push_back("positions that are not finite were left out of the sets: " +
                        std::to_string(non_finite_tracks_) + " tracks, " + std::to_string(non_finite_truths_) +
                        " truths");
    if (series_ && !steps_by_time_.empty()) s.series.push_back(make_series(parts));
  }

 private:
  void close_batch() {
    if (have_batch_ && !batch_used_) ++run_.unscored_truth_steps;
  }

  Series make_series(bool parts) const {
    Series out;
    out.name = "gospa";
    out.description = "per time step, means over the runs with a track set at that step: GOSPA, its p-th power and "
                      "parts (alpha = 2), OSPA, truths, tracks, missed targets, false tracks";
    out.add_column("time", "s");
    out.add_column("runs");
    const std::string unit_p = gospa_.order() == 1.0 ? "m" : gospa_.order() == 2.0 ? "m2" : "";
    const std::string units[10] = {"m", unit_p, "m", unit_p, unit_p, unit_p, "", "", "", ""};
    // Without alpha = 2 there is no decomposition: its three columns are left out, not filled with NaN.
    auto has_column = [parts](int i) { return parts || i < 3 || i > 5; };
    for (int i = 0; i < 10; ++i)
      if (has_column(i)) out.add_column(kNames[i], units[i]);
    out.values.reserve(steps_by_time_.size() * out.columns.size());
    for (const auto& [key, st] : steps_by_time_) {
      out.values.push_back(st.time);
      out.values.push_back(static_cast<double>(st.runs));
      for (int i = 0; i < 10; ++i)
        if (has_column(i)) out.values.push_back(st.v[i] / static_cast<double>(st.runs));
    }
    return out;
  }

  metrics::Gospa gospa_;
  const std::uint8_t statuses_;
  const Dims dims_;
  const double skip_initial_;
  const bool series_;

  GospaRunResult run_;
  std::vector<Eigen::Vector3d> truth3_, track3_;
  std::vector<Eigen::Vector2d> truth2_, track2_;
  bool have_batch_ = false, batch_used_ = false;
  double batch_time_ = 0.0, first_set_ = kNaN;

  std::uint64_t runs_ = 0, scored_runs_ = 0, steps_ = 0;
  std::uint64_t non_finite_tracks_ = 0, non_finite_truths_ = 0, unscored_truth_steps_ = 0, steps_without_truth_ = 0;
  double run_mean_sum_[10] = {}, run_mean_sq_[10] = {};
  std::map<long long, StepSums> steps_by_time_;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sink.gospa";
  d.kind = ComponentKind::Sink;
  d.summary = "GOSPA (localisation / missed / false parts) and OSPA of a tracker's track sets against truth";
  d.doc =
      "Inputs: a tracker's track sets and truth, e.g. inputs: [tracker, scenario]. Each TrackSet is scored on "
      "arrival against the truths whose time equals its time exactly (they arrive first, in time order): "
      "GOSPA d_p^(c,alpha) of Rahmathullah, Garcia-Fernandez and Svensson (FUSION 2017, Definition 1 Eq. (1)) and "
      "OSPA, on the tracks of the chosen statuses (initialised, finite positions), in x-y-z or x-y "
      "(dimensions: 2). A TrackSet with no truth at its time is scored against no truth (steps_without_truth); a "
      "truth batch with no TrackSet at its time is not scored (unscored_truth_steps). Per run: means over its "
      "scored steps; metrics are the means of those over runs: gospa (of d), gospa_pow_p (of d^p), for alpha = 2 "
      "gospa_localisation, gospa_missed and gospa_false (the p-th-power parts of Proposition 1, Eq. (2), summing "
      "to gospa_pow_p), ospa, truths, tracks, missed_targets and false_tracks per step, and a 95 % Student-t "
      "interval of the run means of gospa (gospa_ci95_lo/hi, two runs or more). Series `gospa`: the same per "
      "time step over runs. docs/multi-target-metrics.md.";
  d.params = {
      ParamSpec::real("cutoff", dim::length, "cut-off distance c").req().positive(),
      ParamSpec::real("order", dim::none, "order p, >= 1").def("2").at_least(1),
      ParamSpec::real("alpha", dim::none, "alpha in (0, 2]; 2 gives the localisation / missed / false parts")
          .def("2")
          .positive()
          .at_most(2),
      ParamSpec::boolean("series", "publish the per-step series (kept per step in each run)").def("true"),
  };
  for (ParamSpec& spec : scoring::track_set_params()) d.params.push_back(std::move(spec));
  d.accepts = ItemKind::Tracks | ItemKind::Truth;
  d.min_inputs = 2;
  d.max_inputs = -1;
  d.produces = 0;
  d.create = [](const Params& p) { return std::make_unique<GospaSink>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sink.gospa", trackflow::register_components)
