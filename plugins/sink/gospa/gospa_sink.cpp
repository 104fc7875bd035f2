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

constexpr int kValues = 10;
using Values = std::array<double, kValues>;
// Per scored TrackSet, in this order (counts as doubles: many runs of many targets). The parts are
// contributions to the p-th power: localisation + missed + false == gospa_pow_p (alpha = 2; 0 otherwise).
constexpr std::array<const char*, kValues> kNames = {"gospa",          "gospa_pow_p",    "ospa",   "gospa_localisation",
                                                     "gospa_missed",   "gospa_false",    "truths", "tracks",
                                                     "missed_targets", "false_tracks"};

// Each TrackSet is scored on arrival against the truths of its time (scoring::TrackSetScores).
class GospaSink final : public Component, public FieldListCodec<scoring::StepRunResult<kValues>> {
 public:
  explicit GospaSink(const Params& p) : gospa_(p.real("cutoff"), p.real("order"), p.real("alpha")), scores_(p) {}

  void set_inputs(const std::vector<InputInfo>& inputs) override { scoring::check_track_set_inputs(inputs, "sink.gospa"); }
  void start_run(const RunContext&) override { scores_.start_run(); }
  void on_truth(const Truth& t, int) override { scores_.on_truth(t); }

  void on_tracks(const TrackSet& set, int) override {
    if (!scores_.on_tracks(set)) return;
    const metrics::GospaResult r = scores_.score([this](auto truth, auto tracks) { return gospa_.evaluate(truth, tracks); });
    const int truths = static_cast<int>(scores_.steps().truths()), tracks = static_cast<int>(scores_.steps().tracks());
    int detected = 0;
    for (int j : r.track_for_truth) detected += j >= 0 ? 1 : 0;
    const metrics::GospaDecomposition parts = r.decomposition.value_or(metrics::GospaDecomposition{});
    scores_.add(set.time, {r.gospa, r.gospa_pow_p, r.ospa, parts.localisation, parts.missed, parts.false_tracks,
                           double(truths), double(tracks), double(truths - detected), double(tracks - detected)});
  }

  std::unique_ptr<RunResult> end_run() override { return scores_.end_run(); }
  void merge(RunResult& result) override { scores_.merge(result); }

  void finish(Summary& s, const FinishContext&) override {
    const bool parts = gospa_.alpha() == 2.0;
    const std::array<std::string, kValues> units = this->units();
    // Without alpha = 2 there is no decomposition: its three metrics and columns are left out, not NaN.
    const auto has = [parts](int i) { return parts || i < 3 || i > 5; };
    scores_.publish_means(s, kNames, units, has);
    scores_.publish_counts(s);
    s.notes.push_back(
        "GOSPA (c = " + number_text::general(gospa_.cutoff(), 6) + " m, p = " + number_text::general(gospa_.order(), 6) +
        ", alpha = " + number_text::general(gospa_.alpha(), 6) + ") per TrackSet against the truths of exactly its time; " +
        "gospa: mean over a run's steps of d, then over runs; gospa_pow_p: the same of d^p" +
        (parts ? ", = gospa_localisation + gospa_missed + gospa_false (means of the p-th-power parts)" : "") +
        "; missed_targets / false_tracks: per step, truths / tracks without a partner closer than c");
    scores_.note_left_out(s);
    if (const auto* by_time = scores_.by_time())
      s.series.push_back(by_time->series(
          "gospa",
          "per time step, means over the runs with a track set at that step: GOSPA, its p-th power and "
          "parts (alpha = 2), OSPA, truths, tracks, missed targets, false tracks",
          kNames, units, has));
  }

 private:
  std::array<std::string, kValues> units() const {
    const std::string unit_p = scoring::pow_p_unit(gospa_.order());
    return {"m", unit_p, "m", unit_p, unit_p, unit_p, "", "", "", ""};
  }

  metrics::Gospa gospa_;
  scoring::TrackSetScores<kValues> scores_;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sink.gospa";
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
  d.params = scoring::cutoff_order_params();
  d.params.push_back(ParamSpec::real("alpha", dim::none, "alpha in (0, 2]; 2 gives the localisation / missed / false parts")
                         .def("2")
                         .positive()
                         .at_most(2));
  scoring::declare_track_set_scores(d);
  d.create = [](const Params& p) { return std::make_unique<GospaSink>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sink.gospa", trackflow::register_components)
