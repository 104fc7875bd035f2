// Purpose: the stream bookkeeping shared by the sinks that score each TrackSet against the truths of exactly its time (sink.gospa, sink.ospa, sink.track_quality): truth batches, the selected track positions and velocities, the per-run counters, the run means with their Student-t interval, and the per-step means over runs.
#pragma once

#include "scoring/track_set_sink.hpp"

#include <trackflow/component.hpp>
#include <trackflow/params.hpp>
#include <trackflow/registry.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/series.hpp>
#include <trackflow/tracks.hpp>

#include <Eigen/Core>

#include <boost/math/distributions/students_t.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace trackflow::scoring {

// Per run: what was left out or could not be paired in time. A field record (run_result_codec.hpp).
struct TrackSetCounts {
  std::uint64_t non_finite_tracks = 0;     // selected tracks with a non-finite position: left out
  std::uint64_t non_finite_truths = 0;
  std::uint64_t unscored_truth_steps = 0;  // truth batches with no TrackSet at their time
  std::uint64_t steps_without_truth = 0;   // TrackSets with no truth at their time (scored against none)
  std::uint64_t before_window = 0;         // TrackSets left out by skip_initial
  std::uint64_t ids_out_of_range = 0;      // truths and tracks left out by TrackSetSteps::refuse_ids_from
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.non_finite_tracks, r.non_finite_truths, r.unscored_truth_steps, r.steps_without_truth, r.before_window,
      r.ids_out_of_range);
  }
  void add(const TrackSetCounts& o) {
    non_finite_tracks += o.non_finite_tracks;
    non_finite_truths += o.non_finite_truths;
    unscored_truth_steps += o.unscored_truth_steps;
    steps_without_truth += o.steps_without_truth;
    before_window += o.before_window;
    ids_out_of_range += o.ids_out_of_range;
  }
};

// Streams: truths of one time are kept until the next time's; each TrackSet is paired on arrival
// with the truths of exactly its time stamp (they arrive first, in time order). Reads the
// parameters of track_set_params(). Buffers keep their capacity between scans and runs. Each
// kept truth and track has its id (truth target, track id) and its velocity at the same index as
// its position (only the position is checked for finiteness).
class TrackSetSteps {
 public:
  explicit TrackSetSteps(const Params& p)
      : statuses_(parse_track_statuses(p)), planar_(planar_dimensions(p)), skip_initial_(p.real("skip_initial")) {}

  bool planar() const { return planar_; }
  // Truths and tracks with an id of `limit` or more are left out and counted (a sink that indexes
  // tables by id keeps them bounded); checked after finiteness.
  void refuse_ids_from(std::uint64_t limit) { id_limit_ = limit; }
  const TrackSetCounts& counts() const { return counts_; }

  void start_run() {
    counts_ = TrackSetCounts{};
    truth3_.clear();
    truth2_.clear();
    truth_ids_.clear();
    truth_vel_.clear();
    have_batch_ = batch_used_ = false;
    first_set_ = std::numeric_limits<double>::quiet_NaN();
  }

  void on_truth(const Truth& t) {
    if (!have_batch_ || t.time != batch_time_) {
      close_batch();
      have_batch_ = true;
      batch_used_ = false;
      batch_time_ = t.time;
      truth3_.clear();
      truth2_.clear();
      truth_ids_.clear();
      truth_vel_.clear();
    }
    if (!t.position.allFinite()) {
      ++counts_.non_finite_truths;
      return;
    }
    if (t.target >= id_limit_) {
      ++counts_.ids_out_of_range;
      return;
    }
    truth_ids_.push_back(t.target);
    truth3_.push_back(t.position);
    truth2_.push_back(t.position.head<2>());
    truth_vel_.push_back(t.velocity);
  }

  // true when `set` is to be scored: then truths() and tracks() hold its time's positions.
  bool on_tracks(const TrackSet& set) {
    if (std::isnan(first_set_)) first_set_ = set.time;
    const bool truth_now = have_batch_ && batch_time_ == set.time;
    if (truth_now) batch_used_ = true;
    if (set.time < first_set_ + skip_initial_) {
      ++counts_.before_window;
      return false;
    }
    track3_.clear();
    track2_.clear();
    track_ids_.clear();
    track_vel_.clear();
    for (const TrackEstimate& te : set.tracks) {
      if (!status_selected(statuses_, te.status) || !te.estimate.initialised) continue;
      const Vec3 pos = te.estimate.enu.head<3>();
      if (planar_ ? !pos.head<2>().allFinite() : !pos.allFinite()) {
        ++counts_.non_finite_tracks;
        continue;
      }
      if (te.id >= id_limit_) {
        ++counts_.ids_out_of_range;
        continue;
      }
      track_ids_.push_back(te.id);
      track3_.push_back(pos);
      track2_.push_back(pos.head<2>());
      track_vel_.push_back(te.estimate.enu.tail<3>());
    }
    if (!truth_now) {
      ++counts_.steps_without_truth;
      truth3_.clear();
      truth2_.clear();
      truth_ids_.clear();
      truth_vel_.clear();
    }
    return true;
  }

  // The run's last truth batch counted if no TrackSet used it.
  void end_run() {
    close_batch();
    have_batch_ = false;
  }

  std::size_t truths() const { return truth3_.size(); }
  std::size_t tracks() const { return track3_.size(); }
  std::span<const std::uint64_t> truth_ids() const { return truth_ids_; }
  std::span<const std::uint64_t> track_ids() const { return track_ids_; }
  // 3-D positions and velocities (ENU, m and m/s) whatever dimensions says; index as the ids.
  std::span<const Eigen::Vector3d> truth_positions() const { return truth3_; }
  std::span<const Eigen::Vector3d> track_positions() const { return track3_; }
  std::span<const Eigen::Vector3d> truth_velocities() const { return truth_vel_; }
  std::span<const Eigen::Vector3d> track_velocities() const { return track_vel_; }

  // f(truth positions, track positions) as spans of Eigen::Vector2d or Eigen::Vector3d, as dimensions asks.
  template <class F>
  auto score(F&& f) const {
    return planar_ ? f(std::span<const Eigen::Vector2d>(truth2_), std::span<const Eigen::Vector2d>(track2_))
                   : f(std::span<const Eigen::Vector3d>(truth3_), std::span<const Eigen::Vector3d>(track3_));
  }

 private:
  void close_batch() {
    if (have_batch_ && !batch_used_) ++counts_.unscored_truth_steps;
  }

  const std::uint8_t statuses_;
  const bool planar_;
  const double skip_initial_;
  TrackSetCounts counts_;
  std::vector<Eigen::Vector3d> truth3_, track3_, truth_vel_, track_vel_;
  std::vector<Eigen::Vector2d> truth2_, track2_;
  std::vector<std::uint64_t> truth_ids_, track_ids_;
  std::uint64_t id_limit_ = std::numeric_limits<std::uint64_t>::max();
  bool have_batch_ = false, batch_used_ = false;
  double batch_time_ = 0.0, first_set_ = 0.0;
};

// The counters over runs as metrics (after the node's own): runs_scored, scored_steps,
// non_finite_tracks, non_finite_truths (when any), unscored_truth_steps, steps_without_truth, and a
// note naming what was left out.
inline void publish_counts(Summary& s, std::uint64_t scored_runs, std::uint64_t steps, const TrackSetCounts& c) {
  s.metric("runs_scored", static_cast<double>(scored_runs));
  s.metric("scored_steps", static_cast<double>(steps));
  s.metric("non_finite_tracks", static_cast<double>(c.non_finite_tracks));
  if (c.non_finite_truths) s.metric("non_finite_truths", static_cast<double>(c.non_finite_truths));
  s.metric("unscored_truth_steps", static_cast<double>(c.unscored_truth_steps));
  s.metric("steps_without_truth", static_cast<double>(c.steps_without_truth));
}

inline void note_left_out(Summary& s, const TrackSetCounts& c) {
  if (c.non_finite_tracks || c.non_finite_truths)
    s.notes.push_back("positions that are not finite were left out of the sets: " +
                      std::to_string(c.non_finite_tracks) + " tracks, " + std::to_string(c.non_finite_truths) +
                      " truths");
  // The usual cause: truth of a time reaches the sink after the track set of that time, because its
  // source is declared after the scan source (sources tie at one time in declaration order).
  if (c.steps_without_truth && c.unscored_truth_steps)
    s.notes.push_back(std::to_string(c.steps_without_truth) + " track set(s) came before any truth of their time and " +
                      std::to_string(c.unscored_truth_steps) + " truth step(s) after their track set: if the truth "
                      "comes from its own source (a truth log), declare that source before the scan source");
}

// Means over runs of N per-run means, and a 95 % Student-t interval of the mean of the run means.
template <int N>
class RunMeans {
 public:
  // One run's sums over its `steps` scored steps (none: not counted).
  void add(const std::array<double, N>& sums, std::uint64_t steps) {
    if (!steps) return;
    ++runs_;
    const double n = static_cast<double>(steps);
    for (int i = 0; i < N; ++i) {
      sum_[i] += sums[i] / n;
      sq_[i] += (sums[i] / n) * (sums[i] / n);
    }
  }
  std::uint64_t runs() const { return runs_; }
  double mean(int i) const { return sum_[i] / static_cast<double>(runs_); }
  // Half-width of the interval around mean(i); two runs or more.
  double ci95_half(int i) const {
    const double runs = static_cast<double>(runs_);
    const double m = mean(i);
    const double var = std::max(0.0, (sq_[i] - runs * m * m) / (runs - 1.0));
    const boost::math::students_t t(runs - 1.0);
    return boost::math::quantile(boost::math::complement(t, 0.025)) * std::sqrt(var / runs);
  }

 private:
  std::uint64_t runs_ = 0;
  double sum_[N] = {}, sq_[N] = {};
};

// Per time step (keyed to the microsecond), sums over the runs that scored a set at that step of N
// values; published as a Series of their means with columns time, runs and the chosen values.
template <int N>
class StepMeans {
 public:
  bool empty() const { return steps_.empty(); }
  void add(double time, const std::array<double, N>& x) {
    Step& st = steps_[std::llround(time * 1e6)];
    st.time = time;
    ++st.runs;
    for (int i = 0; i < N; ++i) st.v[i] += x[i];
  }
  // Columns names[i] (unit units[i]) for the i where keep(i).
  template <class Keep>
  Series series(std::string name, std::string description, const std::array<const char*, N>& names,
                const std::array<std::string, N>& units, Keep keep) const {
    Series out;
    out.name = std::move(name);
    out.description = std::move(description);
    out.add_column("time", "s");
    out.add_column("runs");
    for (int i = 0; i < N; ++i)
      if (keep(i)) out.add_column(names[i], units[i]);
    out.values.reserve(steps_.size() * out.columns.size());
    for (const auto& [key, st] : steps_) {
      out.values.push_back(st.time);
      out.values.push_back(static_cast<double>(st.runs));
      for (int i = 0; i < N; ++i)
        if (keep(i)) out.values.push_back(st.v[i] / static_cast<double>(st.runs));
    }
    return out;
  }

 private:
  struct Step {
    double time = 0.0;
    std::uint64_t runs = 0;
    double v[N] = {};
  };
  std::map<long long, Step> steps_;
};

// One scored step: its time and the sink's N values.
template <int N>
struct TimedValues {
  double time = 0.0;
  std::array<double, N> v = {};
};

// A track-set sink's per-run result: sums over the scored steps, counts, and (when `series`) each
// step. A field record, so that FieldListCodec<StepRunResult<N>> is its codec under mpirun.
template <int N>
struct StepRunResult final : RunResult {
  std::uint64_t steps = 0;
  std::array<double, N> sum = {};
  TrackSetCounts counts;
  std::vector<TimedValues<N>> series;
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.steps, r.sum, r.counts, r.series);
  }
};

// Everything of a track-set sink but its metric, with N values per scored step: the pairing of
// sets with truths (TrackSetSteps), the run's sums, the merge into run means and per-step means.
// The sink forwards its stream calls here, scores a set with score() when on_tracks() says so,
// hands the step's values to add(), and publishes from means() and by_time() in finish().
// Reads the parameters of track_set_params() and `series`.
template <int N>
class TrackSetScores {
 public:
  using Values = std::array<double, N>;
  explicit TrackSetScores(const Params& p) : steps_in_(p), series_(p.boolean("series")) {}

  void start_run() {
    run_.steps = 0;
    run_.sum = {};
    run_.series.clear();  // keeps its capacity
    steps_in_.start_run();
  }
  void on_truth(const Truth& t) { steps_in_.on_truth(t); }
  bool on_tracks(const TrackSet& set) { return steps_in_.on_tracks(set); }
  const TrackSetSteps& steps() const { return steps_in_; }
  template <class F>
  auto score(F&& f) const {
    return steps_in_.score(std::forward<F>(f));
  }
  void add(double time, const Values& v) {
    ++run_.steps;
    for (int i = 0; i < N; ++i) run_.sum[i] += v[i];
    if (series_) run_.series.push_back({time, v});
  }
  std::unique_ptr<RunResult> end_run() {
    steps_in_.end_run();
    run_.counts = steps_in_.counts();
    return std::make_unique<StepRunResult<N>>(run_);
  }
  void merge(const RunResult& result) {
    const auto& r = static_cast<const StepRunResult<N>&>(result);
    counts_.add(r.counts);
    steps_ += r.steps;
    means_.add(r.sum, r.steps);
    for (const TimedValues<N>& g : r.series) by_time_.add(g.time, g.v);
  }

  const RunMeans<N>& means() const { return means_; }
  // The run means as metrics names[i] (unit units[i]) for the i where keep(i), the first followed
  // by its 95 % interval (<names[0]>_ci95_lo, _hi, in its unit; two runs or more). None without a
  // scored run.
  template <class Keep>
  void publish_means(Summary& s, const std::array<const char*, N>& names, const std::array<std::string, N>& units,
                     Keep keep) const {
    if (!means_.runs()) return;
    for (int i = 0; i < N; ++i) {
      if (!keep(i)) continue;
      const double mean = means_.mean(i);
      s.metric(names[static_cast<std::size_t>(i)], mean, units[static_cast<std::size_t>(i)]);
      if (i == 0 && means_.runs() >= 2) {
        const double half = means_.ci95_half(0);
        s.metric(std::string(names[0]) + "_ci95_lo", mean - half, units[0]);
        s.metric(std::string(names[0]) + "_ci95_hi", mean + half, units[0]);
      }
    }
  }
  // The per-step means, when `series` and any step was scored.
  const StepMeans<N>* by_time() const { return series_ && !by_time_.empty() ? &by_time_ : nullptr; }
  // The counters as metrics and the note on non-finite positions (publish_counts, note_left_out).
  void publish_counts(Summary& s) const { scoring::publish_counts(s, means_.runs(), steps_, counts_); }
  void note_left_out(Summary& s) const { scoring::note_left_out(s, counts_); }

 private:
  TrackSetSteps steps_in_;
  const bool series_;
  StepRunResult<N> run_;
  std::uint64_t steps_ = 0;
  TrackSetCounts counts_;
  RunMeans<N> means_;
  StepMeans<N> by_time_;
};

// The cut-off c and order p of a set metric (GOSPA, OSPA), the first parameters of its sink.
inline std::vector<ParamSpec> cutoff_order_params() {
  return {
      ParamSpec::real("cutoff", dim::length, "cut-off distance c").req().positive(),
      ParamSpec::real("order", dim::none, "order p, >= 1").def("2").at_least(1),
  };
}

// What a sink built on TrackSetScores declares after its own parameters: `series` and
// track_set_params(); inputs of track sets and truth (two or more); nothing produced.
inline void declare_track_set_scores(ComponentDecl& d) {
  d.params.push_back(ParamSpec::boolean("series", "publish the per-step series (kept per step in each run)").def("true"));
  for (ParamSpec& spec : track_set_params()) d.params.push_back(std::move(spec));
  d.kind = ComponentKind::Sink;
  d.accepts = ItemKind::Tracks | ItemKind::Truth;
  d.min_inputs = 2;
  d.max_inputs = -1;
  d.produces = 0;
}

// The unit of a p-th power of a distance: m for p = 1, m2 for p = 2, none otherwise.
inline std::string pow_p_unit(double order) { return order == 1.0 ? "m" : order == 2.0 ? "m2" : ""; }

}  // namespace trackflow::scoring
