// Purpose: sink.track_quality — how well a tracker's tracks follow the truths over time: completeness, spuriousness, identity swaps, track breaks, establishment time, tracks never on a target, SIAP positional and velocity accuracy.
#include "memory/grow.hpp"
#include "scoring/gospa.hpp"
#include "scoring/track_set_sink.hpp"
#include "scoring/track_set_steps.hpp"

#include <trackflow/number_text.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/tracks.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace trackflow {
namespace {

// Sums of one run (and, merged, of all runs).
struct QualityRunResult final : RunResult {
  std::uint64_t steps = 0;
  std::uint64_t truth_steps = 0, tracked_truth_steps = 0;  // completeness = tracked / truth steps
  std::uint64_t track_steps = 0, spurious_track_steps = 0;  // spuriousness = spurious / track steps
  std::uint64_t id_swaps = 0, breaks = 0;
  std::uint64_t targets = 0, targets_established = 0;
  double establishment_time_sum = 0.0;  // over the established targets
  std::uint64_t tracks = 0, tracks_never_on_a_target = 0;
  // SIAP accuracy over the truth-track pairs (their count: tracked_truth_steps): sums of the
  // Euclidean position error and of its square; the same of the velocity error over the pairs
  // whose velocity error is finite (velocity_pairs; a position is checked, a velocity is not).
  double position_error_sum = 0.0, position_error_sq_sum = 0.0;
  std::uint64_t velocity_pairs = 0;
  double velocity_error_sum = 0.0, velocity_error_sq_sum = 0.0;
  std::uint64_t non_finite = 0, unscored_truth_steps = 0, steps_without_truth = 0, ids_out_of_range = 0;
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.steps, r.truth_steps, r.tracked_truth_steps, r.track_steps, r.spurious_track_steps, r.id_swaps, r.breaks,
      r.targets, r.targets_established, r.establishment_time_sum, r.tracks, r.tracks_never_on_a_target,
      r.position_error_sum, r.position_error_sq_sum, r.velocity_pairs, r.velocity_error_sum, r.velocity_error_sq_sum,
      r.non_finite, r.unscored_truth_steps, r.steps_without_truth, r.ids_out_of_range);
  }
};

// What is kept per truth target and per track id within a run (indexed by id: simulations and
// trackers number them densely from 0 and 1).
struct TargetState {
  bool seen = false, established = false, tracked_last_step = false;
  double first_time = 0.0;
  std::uint64_t last_track = 0;  // id of the last track that followed it (0: none yet)
};
struct TrackState {
  bool seen = false, on_a_target = false;
};

// Ids beyond this are refused per item (counted): a vector indexed by id must stay bounded.
constexpr std::uint64_t kMaxId = 1u << 24;

class TrackQualitySink final : public Component, public FieldListCodec<QualityRunResult> {
 public:
  explicit TrackQualitySink(const Params& p)
      : gospa_(p.real("cutoff"), 2.0, 2.0), steps_in_(p), planar_(steps_in_.planar()) {
    steps_in_.refuse_ids_from(kMaxId);
  }

  void set_inputs(const std::vector<InputInfo>& inputs) override {
    scoring::check_track_set_inputs(inputs, "sink.track_quality");
  }

  void start_run(const RunContext&) override {
    run_ = QualityRunResult{};
    targets_.clear();
    track_state_.clear();
    steps_in_.start_run();
  }

  void on_truth(const Truth& t, int) override { steps_in_.on_truth(t); }

  // Truths and tracks come from scoring::TrackSetSteps: the truths of the set's time, the tracks of
  // the chosen statuses, both with their ids.
  void on_tracks(const TrackSet& set, int) override {
    if (!steps_in_.on_tracks(set)) return;
    const std::span<const std::uint64_t> truth_ids = steps_in_.truth_ids(), track_ids = steps_in_.track_ids();
    // Which track follows which truth: GOSPA's optimal assignment, pairs closer than the cut-off.
    const metrics::GospaResult g = steps_in_.score([this](auto truth, auto tracks) { return gospa_.evaluate(truth, tracks); });
    ++run_.steps;
    run_.truth_steps += truth_ids.size();
    run_.track_steps += track_ids.size();
    memory::assign_grown(track_on_target_, track_ids.size(), char{0});
    for (std::size_t i = 0; i < truth_ids.size(); ++i) {
      TargetState& ts = target(truth_ids[i]);
      if (!ts.seen) {
        ts.seen = true;
        ts.first_time = set.time;
        ++run_.targets;
      }
      const int j = g.track_for_truth[i];
      if (j < 0) {
        if (ts.tracked_last_step) ++run_.breaks;  // it had a track at its previous step
        ts.tracked_last_step = false;
        continue;
      }
      const std::uint64_t id = track_ids[static_cast<std::size_t>(j)];
      track_on_target_[static_cast<std::size_t>(j)] = 1;
      ++run_.tracked_truth_steps;
      if (!ts.established) {
        ts.established = true;
        ++run_.targets_established;
        run_.establishment_time_sum += set.time - ts.first_time;
      }
      if (ts.last_track != 0 && ts.last_track != id) ++run_.id_swaps;
      ts.last_track = id;
      ts.tracked_last_step = true;
      add_pair_errors(i, static_cast<std::size_t>(j));
    }
    for (std::size_t j = 0; j < track_ids.size(); ++j) {
      TrackState& tr = track(track_ids[j]);
      if (!tr.seen) {
        tr.seen = true;
        ++run_.tracks;
      }
      if (track_on_target_[j]) tr.on_a_target = true;
      else ++run_.spurious_track_steps;
    }
  }

  // SIAP positional and velocity accuracy terms of truth i paired with track j: Euclidean errors in
  // x-y-z, or in x-y with dimensions: 2 (docs/multi-target-metrics.md, SIAP accuracy).
  void add_pair_errors(std::size_t i, std::size_t j) {
    const Vec3 dp = steps_in_.track_positions()[j] - steps_in_.truth_positions()[i];
    const Vec3 dv = steps_in_.track_velocities()[j] - steps_in_.truth_velocities()[i];
    const double ep = planar_ ? dp.head<2>().norm() : dp.norm();
    const double ev = planar_ ? dv.head<2>().norm() : dv.norm();
    run_.position_error_sum += ep;
    run_.position_error_sq_sum += ep * ep;
    if (!std::isfinite(ev)) return;  // a tracker's non-finite velocity: left out of velocity accuracy
    ++run_.velocity_pairs;
    run_.velocity_error_sum += ev;
    run_.velocity_error_sq_sum += ev * ev;
  }

  std::unique_ptr<RunResult> end_run() override {
    steps_in_.end_run();
    const scoring::TrackSetCounts& c = steps_in_.counts();
    run_.non_finite = c.non_finite_truths + c.non_finite_tracks;
    run_.ids_out_of_range = c.ids_out_of_range;
    run_.unscored_truth_steps = c.unscored_truth_steps;
    run_.steps_without_truth = c.steps_without_truth;
    for (const TrackState& tr : track_state_)
      if (tr.seen && !tr.on_a_target) ++run_.tracks_never_on_a_target;
    return std::make_unique<QualityRunResult>(run_);
  }

  void merge(RunResult& result) override {
    const auto& r = static_cast<const QualityRunResult&>(result);
    ++runs_;
    QualityRunResult::fields(total_, [&](auto&... t) {
      QualityRunResult::fields(r, [&](const auto&... x) { ((t += x), ...); });
    });
  }

  void finish(Summary& s, const FinishContext&) override {
    const QualityRunResult& t = total_;
    const double runs = runs_ ? static_cast<double>(runs_) : 1.0;
    auto ratio = [](double a, double b) { return b > 0.0 ? a / b : 0.0; };
    s.metric("completeness", ratio(double(t.tracked_truth_steps), double(t.truth_steps)));
    s.metric("spuriousness", ratio(double(t.spurious_track_steps), double(t.track_steps)));
    s.metric("id_swaps_per_run", double(t.id_swaps) / runs);
    s.metric("track_breaks_per_run", double(t.breaks) / runs);
    s.metric("targets_per_run", double(t.targets) / runs);
    s.metric("targets_established", ratio(double(t.targets_established), double(t.targets)));
    if (t.targets_established) s.metric("establishment_time", t.establishment_time_sum / double(t.targets_established), "s");
    s.metric("tracks_per_run", double(t.tracks) / runs);
    s.metric("tracks_never_on_a_target", ratio(double(t.tracks_never_on_a_target), double(t.tracks)));
    // SIAP accuracies: pooled over all pairs of all steps and runs; none without a pair.
    if (t.tracked_truth_steps) {
      const double pairs = double(t.tracked_truth_steps);
      s.metric("position_accuracy", t.position_error_sum / pairs, "m");
      s.metric("position_accuracy_rms", std::sqrt(t.position_error_sq_sum / pairs), "m");
    }
    if (t.velocity_pairs) {
      const double pairs = double(t.velocity_pairs);
      s.metric("velocity_accuracy", t.velocity_error_sum / pairs, "m/s");
      s.metric("velocity_accuracy_rms", std::sqrt(t.velocity_error_sq_sum / pairs), "m/s");
    }
    s.metric("scored_steps", double(t.steps));
    s.metric("unscored_truth_steps", double(t.unscored_truth_steps));
    s.metric("steps_without_truth", double(t.steps_without_truth));
    if (t.non_finite) s.metric("non_finite_positions", double(t.non_finite));
    if (t.ids_out_of_range) s.metric("ids_out_of_range", double(t.ids_out_of_range));
    s.notes.push_back(
        "a truth is followed at a step by the track GOSPA's optimal assignment pairs it with (closer than c = " +
        number_text::general(gospa_.cutoff(), 6) +
        " m); completeness: followed truth-steps / truth-steps; spuriousness: track-steps following no truth / "
        "track-steps; an id swap: a truth followed by a track other than the last one that followed it; a break: a "
        "followed truth not followed at its next step; establishment time: from a truth's first step to its first "
        "followed one (the established ones); position_accuracy, velocity_accuracy: SIAP's mean Euclidean error "
        "of the followed truth-steps (position in " + std::string(planar_ ? "x-y" : "x-y-z") +
        "), _rms their root mean square");
    if (t.velocity_pairs < t.tracked_truth_steps)
      s.notes.push_back(std::to_string(t.tracked_truth_steps - t.velocity_pairs) +
                        " followed truth-steps with a non-finite track velocity were left out of velocity_accuracy");
    if (t.non_finite || t.ids_out_of_range)
      s.notes.push_back("left out: " + std::to_string(t.non_finite) + " non-finite positions, " +
                        std::to_string(t.ids_out_of_range) + " ids of 2^24 or more");
  }

 private:
  TargetState& target(std::uint64_t id) {
    if (id >= targets_.size()) {
      memory::reserve_grown(targets_, static_cast<std::size_t>(id) + 1);
      targets_.resize(static_cast<std::size_t>(id) + 1);
    }
    return targets_[static_cast<std::size_t>(id)];
  }
  TrackState& track(std::uint64_t id) {
    if (id >= track_state_.size()) {
      memory::reserve_grown(track_state_, static_cast<std::size_t>(id) + 1);
      track_state_.resize(static_cast<std::size_t>(id) + 1);
    }
    return track_state_[static_cast<std::size_t>(id)];
  }

  metrics::Gospa gospa_;
  scoring::TrackSetSteps steps_in_;
  const bool planar_;
  QualityRunResult run_, total_;
  std::uint64_t runs_ = 0;
  std::vector<TargetState> targets_;
  std::vector<TrackState> track_state_;
  std::vector<char> track_on_target_;
};

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "sink.track_quality";
  d.kind = ComponentKind::Sink;
  d.summary = "Track quality over time: completeness, spuriousness, identity swaps, track breaks, establishment time, SIAP accuracy";
  d.doc =
      "Inputs: a tracker's track sets and truth, e.g. inputs: [tracker, scenario]. At each TrackSet the truths of "
      "exactly its time are paired with the tracks of the chosen statuses by GOSPA's optimal assignment (pairs "
      "closer than cutoff; docs/multi-target-metrics.md): a truth so paired is followed by that track at that step. "
      "Over a run, per truth target and per track id: completeness = followed truth-steps / truth-steps; "
      "spuriousness = track-steps following no truth / track-steps; id_swaps_per_run: times a truth is followed by "
      "a track other than the last one that followed it (CLEAR MOT's identity switches, Bernardin and Stiefelhagen "
      "2008); track_breaks_per_run: times a followed truth is not followed at its next step while it still exists; "
      "establishment_time: mean time from a truth's first step to its first followed one, over the truths ever "
      "followed (targets_established: their fraction); tracks_never_on_a_target: fraction of the track ids that "
      "never followed a truth; position_accuracy and velocity_accuracy (SIAP, Votruba et al. 2001 as in Stone "
      "Soup's SIAPMetrics): mean Euclidean position and velocity error (m, m/s; x-y only with dimensions: 2) of "
      "the followed truth-steps' truth-track pairs, _rms their root mean square, none without a pair (SIAP's "
      "ambiguity is 1 by construction of the one-to-one pairs: not published). Sums are pooled over runs (ratios of sums). Truth and track ids index per-run "
      "tables: ids of 2^24 or more are left out and counted. Identical for any --threads and under MPI.";
  d.params = {
      ParamSpec::real("cutoff", dim::length, "a track farther than this from a truth does not follow it").req().positive(),
  };
  for (ParamSpec& spec : scoring::track_set_params()) d.params.push_back(std::move(spec));
  d.accepts = ItemKind::Tracks | ItemKind::Truth;
  d.min_inputs = 2;
  d.max_inputs = -1;
  d.produces = 0;
  d.create = [](const Params& p) { return std::make_unique<TrackQualitySink>(p); };
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("sink.track_quality", trackflow::register_components)
