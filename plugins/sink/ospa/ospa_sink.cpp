// Purpose: sink.ospa — OSPA of Schuhmacher, Vo and Vo (2008) between truth and a tracker's track sets, with its localisation and cardinality terms, per scan, Monte Carlo means and a per-step series.
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

constexpr int kValues = 6;
using Values = std::array<double, kValues>;
// Per scored TrackSet, in this order (counts as doubles).
constexpr std::array<const char*, kValues> kNames = {"ospa",   "ospa_pow_p", "ospa_localisation", "ospa_cardinality",
                                                     "truths", "tracks"};

// OSPA's optimal assignment is GOSPA's (for any alpha: the penalty of the left-over elements does
// not depend on the assignment), so metrics::Gospa scores it; alpha is not used here. Each
// TrackSet is scored on arrival against the truths of its time (scoring::TrackSetScores).
class OspaSink final : public Component, public FieldListCodec<scoring::StepRunResult<kValues>> {
 public:
  explicit OspaSink(const Params& p) : ospa_(p.real("cutoff"), p.real("order")), scores_(p) {}

  void set_inputs(const std::vector<InputInfo>& inputs) override { scoring::check_track_set_inputs(inputs, "sink.ospa"); }
  void start_run(const RunContext&) override { scores_.start_run(); }
  void on_truth(const Truth& t, int) override { scores_.on_truth(t); }

  void on_tracks(const TrackSet& set, int) override {
    if (!scores_.on_tracks(set)) return;
    const metrics::GospaResult r = scores_.score([this](auto truth, auto tracks) { return ospa_.evaluate(truth, tracks); });
    scores_.add(set.time, {r.ospa, r.ospa_localisation + r.ospa_cardinality, r.ospa_localisation, r.ospa_cardinality,
                           double(scores_.steps().truths()), double(scores_.steps().tracks())});
  }

  std::unique_ptr<RunResult> end_run() override { return scores_.end_run(); }
  void merge(RunResult& result) override { scores_.merge(result); }

  void finish(Summary& s, const FinishContext&) override {
    const std::string unit_p = scoring::pow_p_unit(ospa_.order());
    const std::array<std::string, kValues> units = {"m", unit_p, unit_p, unit_p, "", ""};
    const auto all = [](int) { return true; };
    scores_.publish_means(s, kNames, units, all);
    scores_.publish_counts(s);
    s.notes.push_back("OSPA (c = " + number_text::general(ospa_.cutoff(), 6) + " m, p = " +
                      number_text::general(ospa_.order(), 6) +
                      ") per TrackSet against the truths of exactly its time; ospa: mean over a run's steps of d, "
                      "then over runs; ospa_pow_p: the same of d^p, = ospa_localisation + ospa_cardinality (the "
                      "two terms of d^p, each divided by the larger set's size)");
    scores_.note_left_out(s);
    if (const auto* by_time = scores_.by_time())
      s.series.push_back(by_time->series("ospa",
                                         "per time step, means over the runs with a track set at that step: OSPA, "
                                         "its p-th power and its localisation and cardinality terms, truths, tracks",
                                         kNames, units, all));
  }

 private:
  metrics::Gospa ospa_;
  scoring::TrackSetScores<kValues> scores_;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sink.ospa";
  d.summary = "OSPA (localisation / cardinality terms) of a tracker's track sets against truth";
  d.doc =
      "Inputs: a tracker's track sets and truth, e.g. inputs: [tracker, scenario]. Each TrackSet is scored on "
      "arrival against the truths whose time equals its time exactly (they arrive first, in time order): OSPA "
      "d_p^(c) of Schuhmacher, Vo and Vo (IEEE Trans. Signal Processing 56(8), 2008), "
      "( (min_pi sum_{i<=m} min(c, d(x_i, y_pi(i)))^p + c^p (n - m)) / n )^(1/p) for m = min(|X|, |Y|), "
      "n = max(|X|, |Y|); 0 when both sets are empty, c when exactly one is. Tracks of the chosen statuses "
      "(initialised, finite positions), in x-y-z or x-y (dimensions: 2); the same pairing of track sets and "
      "truths as sink.gospa (steps_without_truth, unscored_truth_steps). Per run: means over its scored steps; "
      "metrics are the means of those over runs: ospa (of d), ospa_pow_p (of d^p), ospa_localisation and "
      "ospa_cardinality (the two terms of d^p, each divided by n, summing to ospa_pow_p; the paper's components "
      "are their p-th roots), truths and tracks per step, and a 95 % Student-t interval of the run means of ospa "
      "(ospa_ci95_lo/hi, two runs or more). Series `ospa`: the same per time step over runs. "
      "docs/multi-target-metrics.md.";
  d.params = scoring::cutoff_order_params();
  scoring::declare_track_set_scores(d);
  d.create = [](const Params& p) { return std::make_unique<OspaSink>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sink.ospa", trackflow::register_components)
