// Purpose: sink.gospa — GOSPA (with its localisation / missed / false parts for alpha = 2) and OSPA between truth and a tracker's track sets, per scan, Monte Carlo means and a per-step series.
#include "scoring/gospa.hpp"
#include "scoring/track_set_sink.hpp"
#include "scoring/track_set_steps.hpp"

#include <trackflow/number_text.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/tracks.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace trackflow {
namespace {

// One scored TrackSet. Parts are contributions to the p-th power: localisation + missed + false
// == gospa_pow_p (alpha = 2; 0 otherwise).
struct GospaStep {
  double time = 0.0;
  double gospa = 0.0, gospa_pow_p = 0.0, ospa = 0.0;
  double localisation = 0.0, missed = 0.0, false_tracks = 0.0;
  std::int32_t truths = 0, tracks = 0, missed_count = 0, false_count = 0;
};

constexpr int kValues = 10;
using Values = std::array<double, kValues>;

// In the order of kNames (counts as doubles: many runs of many targets).
Values values(const GospaStep& g) {
  return {g.gospa,        g.gospa_pow_p,    g.ospa,           g.localisation,          g.missed,
          g.false_tracks, double(g.truths), double(g.tracks), double(g.missed_count), double(g.false_count)};
}

constexpr std::array<const char*, kValues> kNames = {"gospa",          "gospa_pow_p",    "ospa",   "gospa_localisation",
                                                     "gospa_missed",   "gospa_false",    "truths", "tracks",
                                                     "missed_targets", "false_tracks"};

struct GospaRunResult final : RunResult {
  std::uint64_t steps = 0;
  GospaStep sum;                  // sums over the scored steps (time unused)
  scoring::TrackSetCounts counts;
  std::vector<GospaStep> series;  // per scored step, when `series`
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.steps, r.sum, r.counts, r.series);
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

// Each TrackSet is scored on arrival against the truths of its time (scoring::TrackSetSteps).
class GospaSink final : public Component, public FieldListCodec<GospaRunResult> {
 public:
  explicit GospaSink(const Params& p)
      : gospa_(p.real("cutoff"), p.real("order"), p.real("alpha")), steps_in_(p), series_(p.boolean("series")) {}

  void set_inputs(const std::vector<InputInfo>& inputs) override { scoring::check_track_set_inputs(inputs, "sink.gospa"); }

  void start_run(const RunContext&) override {
    run_.steps = 0;
    run_.sum = GospaStep{};
    run_.series.clear();  // keeps its capacity
    steps_in_.start_run();
  }

  void on_truth(const Truth& t, int) override { steps_in_.on_truth(t); }

  void on_tracks(const TrackSet& set, int) override {
    if (!steps_in_.on_tracks(set)) return;
    const metrics::GospaResult r = steps_in_.score([this](auto truth, auto tracks) { return gospa_.evaluate(truth, tracks); });
    GospaStep s;
    s.time = set.time;
    s.gospa = r.gospa;
    s.gospa_pow_p = r.gospa_pow_p;
    s.ospa = r.ospa;
    s.truths = static_cast<std::int32_t>(steps_in_.truths());
    s.tracks = static_cast<std::int32_t>(steps_in_.tracks());
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
    steps_in_.end_run();
    run_.counts = steps_in_.counts();
    return std::make_unique<GospaRunResult>(run_);
  }

  void merge(RunResult& result) override {
    const auto& r = static_cast<const GospaRunResult&>(result);
    counts_.add(r.counts);
    steps_ += r.steps;
    means_.add(values(r.sum), r.steps);
    for (const GospaStep& g : r.series) by_time_.add(g.time, values(g));
  }

  void finish(Summary& s, const FinishContext&) override {
    const bool parts = gospa_.alpha() == 2.0;
    const std::array<std::string, kValues> units = this->units();
    for (int i = 0; i < kValues; ++i) {
      if (!parts && i >= 3 && i <= 5) continue;
      if (!means_.runs()) break;
      const double mean = means_.mean(i);
      s.metric(kNames[static_cast<std::size_t>(i)], mean, units[static_cast<std::size_t>(i)]);
      if (i == 0 && means_.runs() >= 2) {
        const double half = means_.ci95_half(i);
        s.metric("gospa_ci95_lo", mean - half, "m");
        s.metric("gospa_ci95_hi", mean + half, "m");
      }
    }
    scoring::publish_counts(s, means_.runs(), steps_, counts_);
    s.notes.push_back(
        "GOSPA (c = " + number_text::general(gospa_.cutoff(), 6) + " m, p = " + number_text::general(gospa_.order(), 6) +
        ", alpha = " + number_text::general(gospa_.alpha(), 6) + ") per TrackSet against the truths of exactly its time; " +
        "gospa: mean over a run's steps of d, then over runs; gospa_pow_p: the same of d^p" +
        (parts ? ", = gospa_localisation + gospa_missed + gospa_false (means of the p-th-power parts)" : "") +
        "; missed_targets / false_tracks: per step, truths / tracks without a partner closer than c");
    scoring::note_non_finite(s, counts_);
    // Without alpha = 2 there is no decomposition: its three columns are left out, not filled with NaN.
    if (series_ && !by_time_.empty())
      s.series.push_back(by_time_.series(
          "gospa",
          "per time step, means over the runs with a track set at that step: GOSPA, its p-th power and "
          "parts (alpha = 2), OSPA, truths, tracks, missed targets, false tracks",
          kNames, units, [parts](int i) { return parts || i < 3 || i > 5; }));
  }

 private:
  std::array<std::string, kValues> units() const {
    const std::string unit_p = scoring::pow_p_unit(gospa_.order());
    return {"m", unit_p, "m", unit_p, unit_p, unit_p, "", "", "", ""};
  }

  metrics::Gospa gospa_;
  scoring::TrackSetSteps steps_in_;
  const bool series_;

  GospaRunResult run_;
  std::uint64_t steps_ = 0;
  scoring::TrackSetCounts counts_;
  scoring::RunMeans<kValues> means_;
  scoring::StepMeans<kValues> by_time_;
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
