// Purpose: tracker.multi — a multi-target tracker composed of parts: per scan it predicts every track, lets the associator give detections to tracks, updates (each track's own adapters around its updates), confirms and deletes (initiator, deleter), starts tracks from what no track took (initiator), and publishes one TrackSet.
#include "association/gating.hpp"
#include "association/scan_check.hpp"
#include "memory/grow.hpp"

#include <trackflow/component.hpp>
#include <trackflow/error.hpp>
#include <trackflow/estimate_state.hpp>
#include <trackflow/estimator.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/run_result_codec.hpp>
#include <trackflow/track_adapters.hpp>
#include <trackflow/tracker.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace trackflow {
namespace {

// Per run, summed over the ensemble.
struct TrackerRunResult final : RunResult {
  std::uint64_t scans = 0, scans_not_looked = 0, scans_skipped = 0, detections = 0, updates = 0,
                updates_refused = 0, started = 0, start_failed = 0, confirmed = 0, deleted = 0, deleted_non_finite = 0,
                track_limit_refused = 0, confirmed_track_scans = 0, deleted_by_adapter = 0, weighted_updates = 0,
                weighted_candidates = 0, exact_clusters = 0, approximate_clusters = 0, unconverged_clusters = 0;
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.scans, r.scans_not_looked, r.scans_skipped, r.detections, r.updates, r.updates_refused, r.started,
      r.start_failed, r.confirmed, r.deleted, r.deleted_non_finite, r.track_limit_refused, r.confirmed_track_scans,
      r.deleted_by_adapter, r.weighted_updates, r.weighted_candidates, r.exact_clusters,
      r.approximate_clusters, r.unconverged_clusters);
  }
};

// One track: its estimator (a clone of the configured one), its own adapters over that estimator
// (none when the tracker has no `adapters:`), what it publishes, and its history. Both live on the
// heap, so they stay put when the slot moves; a reused slot reuses them.
struct Track final : TrackContext {
  std::unique_ptr<Estimator> estimator;
  std::unique_ptr<TrackAdapters> adapters;
  TrackEstimate published;
  PredictedMeasurement predicted;
  bool can_predict = false;
  int looks = 0;
  std::uint64_t history = 0;
  double peak_score = 0.0;  // the largest track score so far (published.score is the current one)
  double last_time = 0.0;
  // Warnings of the estimator go to the tracker, which reports the first of each run.
  std::vector<std::string>* warnings = nullptr;

  void warn(const std::string& message) override {
    if (warnings) warnings->push_back(who + ": " + message);
  }
  void count(int) override {}
  void annotate(int, double) override {}

  TrackView view() const {
    TrackView v;
    v.id = published.id;
    v.status = published.status;
    v.hits = published.hits;
    v.misses = published.misses;
    v.looks = looks;
    v.history = history;
    v.score = published.score;
    v.peak_score = peak_score;
    v.existence = published.existence;
    v.estimator = estimator.get();
    v.predicted = can_predict ? &predicted : nullptr;
    return v;
  }
};

void clear_innovation(Estimate& e) {
  e.updated = false;
  e.nis = 0.0;
  e.innovation.resize(0);
  e.innovation_covariance.resize(0, 0);
}

bool finite(const Estimate& e) {
  return std::isfinite(e.state.sum() + e.covariance.sum() + e.enu.sum() + e.enu_covariance.sum());
}

class MultiTracker final : public Component, public FieldListCodec<TrackerRunResult> {
 public:
  MultiTracker(std::string node, std::unique_ptr<Estimator> prototype, std::vector<NestedComponent> adapters,
               std::unique_ptr<Associator> associator, std::unique_ptr<Initiator> initiator,
               std::unique_ptr<Deleter> deleter, int max_tracks, std::string estimator_type)
      : node_(std::move(node)),
        prototype_(std::move(prototype)),
        adapters_(std::move(adapters)),
        associator_(std::move(associator)),
        initiator_(std::move(initiator)),
        deleter_(std::move(deleter)),
        max_tracks_(max_tracks),
        probabilistic_(associator_->probabilistic()),
        adapters_who_("tracker.multi (node '" + node_ + "', estimator " + estimator_type + ")") {
    // Refused now, at the offending entry's line, rather than at the first track: the adapters'
    // needs against the estimator's noise (each track's is a clone of the prototype's).
    if (!adapters_.empty()) {
      const TrackAdapters check(adapters_, *prototype_, adapters_who_);
    }
  }

  void start_run(const RunContext& ctx) override {
    ctx_ = ctx;
    diag_ = ctx.diagnostics;
    run_ = TrackerRunResult{};
    // The last run's slots become spares: their estimators' storage serves this run's tracks.
    for (Track& t : tracks_) spare_.push_back(std::move(t));
    tracks_.clear();
    next_id_ = 1;
    has_time_ = false;
    warnings_.clear();
    warned_ = false;
    initiator_->reset();
  }

  void on_scan(const Scan& s, int) override {
    if (has_time_ && s.time < last_time_) {
      ++run_.scans_skipped;
      if (diag_) diag_->skip(node_, "scan at t=" + std::to_string(s.time) + " s is older than the previous one");
      return;
    }
    has_time_ = true;
    last_time_ = s.time;
    ++run_.scans;
    if (!s.valid) {  // the sensor did not look: no information, nothing missed
      ++run_.scans_not_looked;
      publish(s.time);
      return;
    }
    check(s);
    run_.detections += s.detections.size();
    predict(s);
    associate(s);
    update(s);
    manage();
    initiate(s);
    publish(s.time);
    report_warnings();
  }

  std::unique_ptr<RunResult> end_run() override { return std::make_unique<TrackerRunResult>(run_); }
  void merge(RunResult& result) override {
    const auto& r = static_cast<const TrackerRunResult&>(result);
    ++runs_;
    TrackerRunResult::fields(total_, [&](auto&... t) {
      TrackerRunResult::fields(r, [&](const auto&... x) { ((t += x), ...); });
    });
  }
  void finish(Summary& s, const FinishContext&) override {
    const double runs = runs_ ? static_cast<double>(runs_) : 1.0;
    s.metric("scans", static_cast<double>(total_.scans));
    s.metric("tracks_started_per_run", static_cast<double>(total_.started) / runs);
    s.metric("tracks_confirmed_per_run", static_cast<double>(total_.confirmed) / runs);
    s.metric("tracks_deleted_per_run", static_cast<double>(total_.deleted) / runs);
    s.metric("confirmed_tracks_per_scan",
             total_.scans ? static_cast<double>(total_.confirmed_track_scans) / static_cast<double>(total_.scans) : 0.0);
    s.metric("updates", static_cast<double>(total_.updates));
    if (total_.updates_refused) s.metric("updates_refused", static_cast<double>(total_.updates_refused));
    if (total_.start_failed) s.metric("starts_failed", static_cast<double>(total_.start_failed));
    if (total_.scans_not_looked) s.metric("scans_not_looked", static_cast<double>(total_.scans_not_looked));
    if (total_.scans_skipped) s.metric("scans_skipped", static_cast<double>(total_.scans_skipped));
    if (total_.deleted_non_finite) s.metric("deleted_non_finite", static_cast<double>(total_.deleted_non_finite));
    if (total_.deleted_by_adapter) s.metric("deleted_by_adapter", static_cast<double>(total_.deleted_by_adapter));
    if (probabilistic_ && total_.exact_clusters + total_.approximate_clusters > 0) {
      // How the associator computed its probabilities, per look (JPDA: exact or approximate per cluster).
      const double scans = total_.scans ? static_cast<double>(total_.scans) : 1.0;
      s.metric("exact_clusters_per_scan", static_cast<double>(total_.exact_clusters) / scans);
      s.metric("approximate_clusters_per_scan", static_cast<double>(total_.approximate_clusters) / scans);
      if (total_.unconverged_clusters) s.metric("unconverged_clusters", static_cast<double>(total_.unconverged_clusters));
    }
    if (probabilistic_)  // how many detections a combined update mixes, on average
      s.metric("candidates_per_update", total_.weighted_updates ? static_cast<double>(total_.weighted_candidates) /
                                                                       static_cast<double>(total_.weighted_updates)
                                                                 : 0.0);
    if (total_.track_limit_refused) {
      s.metric("starts_refused_at_max_tracks", static_cast<double>(total_.track_limit_refused));
      s.notes.push_back(std::to_string(total_.track_limit_refused) + " track start(s) refused: max_tracks (" +
                        std::to_string(max_tracks_) + ") tracks were alive");
    }
  }

 private:
  void check(const Scan& s) {
    association::check_scan(s, *prototype_, m_, "tracker.multi (node '" + node_ + "')");
  }

  int dimension(const SensorFrame& f, const Detection& d) const {
    const int positions = position_values(f.frame);
    switch (prototype_->measurement_spec().range_rate) {
      case RangeRateUse::Use: return positions + 1;
      case RangeRateUse::Auto: return d.has_range_rate ? positions + 1 : positions;
      case RangeRateUse::Ignore: break;
    }
    return positions;
  }

  // The estimator's R from detection d (its leading dim x dim block).
  void set_R(Estimator& e, const Detection& d, int dim) const {
    MeasCov& R = e.measurement_noise();
    R = d.covariance.topLeftCorner(dim, dim);
  }

  // Every track to the scan's time, and its predicted measurement with the scan's R (that of its
  // first detection: a sensor reports one R per look; an empty scan needs none).
  void predict(const Scan& s) {
    views_.clear();
    for (Track& t : tracks_) {
      rebind(t);  // the slot may have moved since the last scan
      const double T = s.time - t.last_time;
      t.time = s.time;
      if (T > 0.0) t.estimator->predict(T);
      t.last_time = s.time;
      t.can_predict = false;
      if (!s.detections.empty()) {
        const Detection& d = s.detections.front();
        set_R(*t.estimator, d, dimension(s.sensor, d));
        t.can_predict = t.estimator->predict_measurement(s.sensor, t.estimator->measurement_noise(), t.predicted);
      }
      views_.push_back(t.view());
    }
  }

  void associate(const Scan& s) {
    memory::assign_grown(assigned_, tracks_.size(), -1);
    memory::assign_grown(taken_, s.detections.size(), char{0});
    if (tracks_.empty()) return;
    if (probabilistic_) return associate_probabilities(s);  // also without detections: existence decays
    if (s.detections.empty()) return;
    associator_->associate(views_, s, assigned_);
    for (size_t i = 0; i < assigned_.size(); ++i) {
      const int j = assigned_[i];
      if (j < 0) continue;
      if (j >= static_cast<int>(s.detections.size()) || taken_[static_cast<size_t>(j)] || !views_[i].predicted)
        throw std::logic_error("tracker.multi (node '" + node_ + "'): the associator gave detection " + std::to_string(j) +
                            " of " + std::to_string(s.detections.size()) +
                            " to a track that cannot take it, or to two tracks (a bug in that plugin)");
      taken_[static_cast<size_t>(j)] = 1;
    }
  }

  // A probabilistic associator's answer, checked (a part that breaks the contract is a bug): every
  // candidate a detection of the scan, given to a track that can take one, with probabilities in
  // [0, 1] summing with none to 1. A detection is the tracks' (not the initiator's) when its total
  // probability exceeds the associator's initiation threshold.
  void associate_probabilities(const Scan& s) {
    const int n = static_cast<int>(tracks_.size()), m = static_cast<int>(s.detections.size());
    probabilities_.clear(n);
    associator_->associate_probabilities(views_, s, probabilities_);
    run_.exact_clusters += static_cast<std::uint64_t>(std::max(0, probabilities_.exact_clusters));
    run_.approximate_clusters += static_cast<std::uint64_t>(std::max(0, probabilities_.approximate_clusters));
    run_.unconverged_clusters += static_cast<std::uint64_t>(std::max(0, probabilities_.unconverged_clusters));
    memory::assign_grown(detection_share_, s.detections.size(), 0.0);
    auto bug = [&](const std::string& what) {
      return std::logic_error("tracker.multi (node '" + node_ + "'): the associator's probabilities " + what +
                              " (a bug in that plugin)");
    };
    if (probabilities_.tracks() != n) throw bug("are for another number of tracks");
    for (int i = 0; i < n; ++i) {
      double sum = probabilities_.none(i);
      if (!(sum >= 0.0 && sum <= 1.0)) throw bug("give track " + std::to_string(i) + " a none-probability outside [0, 1]");
      for (const AssociationProbabilities::Entry& e : probabilities_.of(i)) {
        if (e.detection < 0 || e.detection >= m || !views_[static_cast<size_t>(i)].predicted || !(e.probability >= 0.0) ||
            !(e.probability <= 1.0))
          throw bug("give detection " + std::to_string(e.detection) + " of " + std::to_string(m) + " to track " +
                    std::to_string(i) + " with probability " + std::to_string(e.probability));
        sum += e.probability;
        detection_share_[static_cast<size_t>(e.detection)] += e.probability;
      }
      if (std::fabs(sum - 1.0) > 1e-9) throw bug("of track " + std::to_string(i) + " sum to " + std::to_string(sum));
      const double r = probabilities_.existence(i);
      if (!std::isnan(r)) {
        if (!(r >= 0.0 && r <= 1.0)) throw bug("give track " + std::to_string(i) + " an existence of " + std::to_string(r));
        tracks_[static_cast<size_t>(i)].published.existence = r;
      }
    }
    for (int j = 0; j < m; ++j)
      if (detection_share_[static_cast<size_t>(j)] > probabilities_.initiation_threshold) taken_[static_cast<size_t>(j)] = 1;
  }

  // Track i's combined update with its candidates (Estimator::update_weighted); the track score's
  // increment of the look is that of the mixture: dL = ln(1 - P_D + P_D sum_j N(nu_j; 0, S) / beta_FA)
  // over the candidates (IPDA's likelihood ratio, Musicki, Evans & Stankovic 1994, with P_G = 1 as
  // for a hard association's miss), NaN when the scan states no P_D or clutter density.
  bool update_weighted(Track& t, int i, const Scan& s) {
    const std::span<const AssociationProbabilities::Entry> entries = probabilities_.of(i);
    candidates_.clear();
    candidate_probabilities_.clear();
    int dim = -1;
    double likelihood_sum = 0.0;
    const bool gate = t.can_predict && gate_.set(t.predicted, s.sensor.frame);
    for (const AssociationProbabilities::Entry& e : entries) {
      if (!(e.probability > 0.0)) continue;
      const Detection& d = s.detections[static_cast<size_t>(e.detection)];
      const int k = dimension(s.sensor, d);
      if (dim < 0) dim = k;
      if (k != dim) continue;  // a detection without the range rate the others have: not mixed with them
      candidates_.emplace_back();
      to_measurement(s, d, candidates_.back());
      candidate_probabilities_.push_back(e.probability);
      if (gate) likelihood_sum += std::exp(gate_.log_likelihood(gate_.nis(d.value)));
    }
    const double pd = s.detection_probability, density = s.clutter_density;
    double dL = std::numeric_limits<double>::quiet_NaN();
    if (candidates_.empty()) {
      if (pd >= 0.0 && pd <= 1.0) dL = track_score::miss(pd);
    } else if (gate && pd > 0.0 && pd <= 1.0 && density > 0.0) {
      dL = std::log(1.0 - pd + pd * likelihood_sum / density);
    }
    bool used = false;
    if (!candidates_.empty()) {
      used = t.estimator->update_weighted(candidates_, candidate_probabilities_, probabilities_.none(i), dim);
      ++(used ? run_.updates : run_.updates_refused);
      if (used) {
        ++run_.weighted_updates;
        run_.weighted_candidates += candidates_.size();
      }
    }
    double& L = t.published.score;
    L += dL;
    t.peak_score = std::isnan(L) ? L : std::max(t.peak_score, L);
    return used;
  }

  void update(const Scan& s) {
    if (probabilistic_) {
      for (size_t i = 0; i < tracks_.size(); ++i) {
        Track& t = tracks_[i];
        ++t.looks;
        clear_innovation(t.published.estimate);
        const bool used = update_weighted(t, static_cast<int>(i), s);
        t.history = (t.history << 1) | (used ? 1u : 0u);
        if (used) {
          ++t.published.hits;
          t.published.misses = 0;
        } else {
          ++t.published.misses;
        }
        views_[i] = t.view();
      }
      return;
    }
    for (size_t i = 0; i < tracks_.size(); ++i) {
      Track& t = tracks_[i];
      ++t.looks;
      bool used = false;
      // This scan's update, or none: a coasting track publishes no innovation of an earlier scan.
      clear_innovation(t.published.estimate);
      if (assigned_[i] >= 0) {
        const Detection& d = s.detections[static_cast<size_t>(assigned_[i])];
        const int dim = dimension(s.sensor, d);
        to_measurement(s, d, m_);
        set_R(*t.estimator, d, dim);
        if (t.adapters) t.adapters->before_update(m_, dim);
        used = t.estimator->update(m_, dim);
        ++(used ? run_.updates : run_.updates_refused);
        if (t.adapters) after_update(t, m_, s.time, true);
      }
      t.history = (t.history << 1) | (used ? 1u : 0u);
      add_score(t, s, used ? &s.detections[static_cast<size_t>(assigned_[i])] : nullptr);
      if (used) {
        ++t.published.hits;
        t.published.misses = 0;
      } else {
        ++t.published.misses;
      }
      views_[i] = t.view();
    }
  }

  // The look's track-score increment (tracker.hpp, track_score) with the scan's P_D and
  // false-alarm density: a detection used is scored against the predicted measurement the
  // associator saw (z^, S of this scan), a look without one as a miss. P_G = 1: the tracker does
  // not know the associator's gate. A scan that states neither value makes the score NaN, for good.
  void add_score(Track& t, const Scan& s, const Detection* used) {
    const double pd = s.detection_probability, density = s.clutter_density;
    double dL = std::numeric_limits<double>::quiet_NaN();
    if (!used) {
      if (pd >= 0.0 && pd <= 1.0) dL = track_score::miss(pd);
    } else if (t.can_predict && gate_.set(t.predicted, s.sensor.frame) && pd > 0.0 && pd <= 1.0 && density > 0.0) {
      dL = track_score::hit(pd, density, gate_.nis(used->value), t.predicted.log_det_S, gate_.dim());
    }
    double& L = t.published.score;
    L += dL;
    t.peak_score = std::isnan(L) ? L : std::max(t.peak_score, L);
  }

  // Tentative tracks confirmed or failed (the initiator), confirmed ones coasting or dropped (the deleter).
  void manage() {
    for (size_t i = 0; i < tracks_.size(); ++i) {
      TrackEstimate& p = tracks_[i].published;
      const TrackView& v = views_[i];
      if (tracks_[i].adapters && tracks_[i].adapters->restart_requested()) {
        // An adapter asked to forget the track (Filter::restart_track): a tracker deletes it.
        p.status = TrackStatus::Deleted;
        ++run_.deleted_by_adapter;
      } else if (p.status == TrackStatus::Tentative) {
        if (initiator_->confirmed(v)) {
          p.status = TrackStatus::Confirmed;
          ++run_.confirmed;
        } else if (initiator_->failed(v)) {
          p.status = TrackStatus::Deleted;
        }
      } else if (deleter_->drop(v)) {
        p.status = TrackStatus::Deleted;
      } else {
        p.status = p.misses > 0 ? TrackStatus::Coasting : TrackStatus::Confirmed;
      }
      if (p.status == TrackStatus::Deleted) ++run_.deleted;
    }
  }

  void initiate(const Scan& s) {
    unassigned_.clear();
    for (size_t j = 0; j < s.detections.size(); ++j)
      if (!taken_[j]) unassigned_.push_back(static_cast<int>(j));
    starts_.clear();
    initiator_->initiate(s, unassigned_, starts_);
    for (const TrackStart& st : starts_) {
      if (st.second < 0 || st.second >= static_cast<int>(s.detections.size()))
        throw std::logic_error("tracker.multi (node '" + node_ + "'): the initiator started a track from detection " +
                            std::to_string(st.second) + " of " + std::to_string(s.detections.size()) +
                            " (a bug in that plugin)");
      if (alive() >= max_tracks_) {
        ++run_.track_limit_refused;
        continue;
      }
      Track& t = new_track();
      t.estimator->reset();
      // A reused slot starts clean: nothing of the track that held it before (this run's or an
      // earlier run's, which differs with the thread count) may reach the new track's estimates.
      t.published = TrackEstimate{};
      t.predicted = PredictedMeasurement{};
      t.can_predict = false;
      if (t.adapters) t.adapters->start_track(ctx_);
      const bool one_point = st.velocity_sigma > 0.0;
      bool formed = false;
      if (one_point) {  // the current detection alone, at rest with the initiator's velocity prior
        const Detection& d = s.detections[static_cast<size_t>(st.second)];
        to_measurement(s, d, m_);
        t.time = s.time;
        const int dim = dimension(s.sensor, d);
        set_R(*t.estimator, d, dim);
        if (t.adapters) t.adapters->before_update(m_, dim);
        formed = t.estimator->initiate_one_point(m_, dim, st.velocity_sigma);
        if (t.adapters) after_update(t, m_, s.time, formed);
      } else {
        t.time = st.first.time;
        const int dim1 = dimension(st.first, st.first);
        set_R(*t.estimator, st.first, dim1);
        if (t.adapters) t.adapters->before_update(st.first, dim1);
        formed = t.estimator->initiate(st.first, dim1);
        if (t.adapters) after_update(t, st.first, st.first.time, formed);
      }
      if (!formed && !one_point) {
        const Detection& d = s.detections[static_cast<size_t>(st.second)];
        to_measurement(s, d, m_);
        t.time = s.time;
        const int dim2 = dimension(s.sensor, d);
        set_R(*t.estimator, d, dim2);
        if (t.adapters) t.adapters->before_update(m_, dim2);
        formed = t.estimator->initiate(m_, dim2);
        if (t.adapters) after_update(t, m_, s.time, formed);
      }
      if (!formed) {
        ++run_.start_failed;
        // Back to the spares, estimator and adapters kept: a failed start allocates nothing next time.
        spare_.push_back(std::move(tracks_.back()));
        tracks_.pop_back();
        continue;
      }
      ++run_.started;
      t.published.id = next_id_++;
      t.published.status = TrackStatus::Tentative;
      t.published.hits = one_point ? 1 : 2;
      t.published.misses = 0;
      t.published.score = st.score;
      t.published.existence = st.existence;
      t.peak_score = st.score;
      t.looks = one_point ? 1 : 2;
      t.history = one_point ? 0b1 : 0b11;
      t.last_time = s.time;
      const std::uint32_t origin = s.detections[static_cast<size_t>(st.second)].origin;
      t.published.estimate.target = one_point || st.first.origin == origin ? origin : kOriginUnknown;
    }
  }

  // The adapters' after_update with the track's estimate from measurement m at `time` (as a
  // single-track node publishes it: the state once initialised, otherwise flagged uninitialised).
  // A non-finite state is not shown to them: the track is deleted when it is published.
  void after_update(Track& t, const Measurement& m, double time, bool initialised) {
    Estimate& e = t.published.estimate;
    if (initialised) {
      t.estimator->fill(e);
      e.time = time;
      e.initialised = true;
      if (!finite(e)) return;
    } else {
      set_uninitialised(e, time);
    }
    t.adapters->after_update(m, e);
  }

  int alive() const {
    int n = 0;
    for (const Track& t : tracks_) n += t.published.status != TrackStatus::Deleted;
    return n;
  }

  // A slot for a new track at the end (ids grow, so the list stays in id order); a slot is reused
  // with its estimator's storage once the population is steady.
  Track& new_track() {
    if (spare_.empty()) {
      tracks_.emplace_back();
      Track& fresh = tracks_.back();
      fresh.estimator = prototype_->clone();
      if (!adapters_.empty()) fresh.adapters = std::make_unique<TrackAdapters>(adapters_, *fresh.estimator, adapters_who_);
      fresh.who = "tracker.multi (node '" + node_ + "') track";  // once per slot: a reused one keeps it
      fresh.warnings = &warnings_;
    } else {
      tracks_.push_back(std::move(spare_.back()));
      spare_.pop_back();
    }
    Track& t = tracks_.back();
    rebind(t);
    return t;
  }

  // The estimator reports to its track's context, which lives in a slot that moves when the list changes.
  void rebind(Track& t) {
    t.estimate = &t.published.estimate;
    t.estimator->bind(t);
  }

  // Each track's estimate at time t; the deleted ones published once, then their slots freed.
  void publish(double t) {
    set_.clear();
    std::uint64_t confirmed = 0;
    for (Track& tr : tracks_) {
      Estimate& e = tr.published.estimate;
      tr.estimator->fill(e);
      e.time = t;
      e.initialised = true;
      if (tr.published.status != TrackStatus::Deleted && !finite(e)) {
        tr.published.status = TrackStatus::Deleted;
        ++run_.deleted;
        ++run_.deleted_non_finite;
        warnings_.push_back("track " + std::to_string(tr.published.id) + ": the state came out non-finite at t=" +
                            std::to_string(t) + " s; deleted");
      }
      if (tr.published.status == TrackStatus::Deleted && !finite(e)) set_uninitialised(e, t);
      confirmed += tr.published.status == TrackStatus::Confirmed || tr.published.status == TrackStatus::Coasting;
      set_.push_back(tr.published);
    }
    run_.confirmed_track_scans += confirmed;
    out.emit(TrackSet{t, set_});
    // Deleted slots go to the spares in one pass (an erase per deletion would shift the whole
    // tail each time: quadratic in the population, and a slot is kilobytes).
    std::size_t kept = 0;
    for (std::size_t i = 0; i < tracks_.size(); ++i) {
      if (tracks_[i].published.status == TrackStatus::Deleted) {
        spare_.push_back(std::move(tracks_[i]));
      } else {
        if (kept != i) tracks_[kept] = std::move(tracks_[i]);
        ++kept;
      }
    }
    tracks_.erase(tracks_.begin() + static_cast<std::ptrdiff_t>(kept), tracks_.end());
  }

  void report_warnings() {
    if (!warnings_.empty() && !warned_ && diag_)
      diag_->warn(node_, warnings_.front() + (warnings_.size() > 1 ? " (further warnings of this run not shown)" : ""));
    warned_ = warned_ || !warnings_.empty();
    warnings_.clear();
  }

  std::string node_;
  std::unique_ptr<Estimator> prototype_;
  std::vector<NestedComponent> adapters_;  // each track's adapters, as configured
  std::unique_ptr<Associator> associator_;
  std::unique_ptr<Initiator> initiator_;
  std::unique_ptr<Deleter> deleter_;
  int max_tracks_ = 0;
  bool probabilistic_ = false;  // the associator gives probabilities: combined updates
  std::string adapters_who_;
  RunContext ctx_;  // this run's, for each new track's adapters
  Diagnostics* diag_ = nullptr;
  TrackerRunResult run_, total_;
  std::uint64_t runs_ = 0;
  std::vector<Track> tracks_, spare_;
  std::vector<TrackView> views_;
  std::vector<int> assigned_, unassigned_;
  std::vector<char> taken_;
  AssociationProbabilities probabilities_;
  std::vector<double> detection_share_, candidate_probabilities_;
  std::vector<Measurement> candidates_;
  std::vector<TrackStart> starts_;
  association::PredictedGate gate_;
  std::vector<TrackEstimate> set_;
  std::vector<std::string> warnings_;
  bool warned_ = false;
  Measurement m_;
  std::uint64_t next_id_ = 1;
  double last_time_ = 0.0;
  bool has_time_ = false;
};

std::unique_ptr<Component> create(const Params& p) {
  const NestedComponent& estimator_entry = p.component("estimator");
  std::unique_ptr<Estimator> estimator = estimator_entry.create_estimator();
  auto associator = make_part<Associator>(p.component("associator"), "an associator");
  auto initiator = make_part<Initiator>(p.component("initiator"), "an initiator");
  if (initiator->one_point_starts() && !estimator->starts_from_one_point())
    throw ConfigError("the initiator " + p.component("initiator").type + " starts tracks from one point, which " +
                          estimator_entry.type + " cannot (it offers no Estimator::initiate_one_point): start "
                          "tracks from two points, or take an estimator that starts from one",
                      estimator_entry.type_where, p.node());
  auto deleter = make_part<Deleter>(p.component("deleter"), "a deleter");
  const bool existence_read = initiator->reads_existence() || deleter->reads_existence();
  if (existence_read && !associator->keeps_existence()) {
    const bool by_initiator = initiator->reads_existence();
    const char* part = by_initiator ? "initiator" : "deleter";
    throw ConfigError("the " + std::string(part) + " " + p.component(part).type +
                          " decides by each track's existence probability, which the associator " +
                          p.component("associator").type +
                          " does not keep: take assoc.jpda or assoc.pda with survival_probability (JIPDA, IPDA)",
                      p.component(part).type_where, p.node());
  }
  if (associator->probabilistic()) {
    if (!estimator->takes_weighted_updates())
      throw ConfigError("the associator " + p.component("associator").type +
                            " gives association probabilities, so each track is updated with all its candidate "
                            "detections at once (Estimator::update_weighted), which " + estimator_entry.type +
                            " cannot: take filter.kalman, filter.ekf, filter.ukf or filter.imm",
                        estimator_entry.type_where, p.node());
    if (!p.components("adapters").empty())
      throw p.error("adapters", "per-track adapters see one detection per update; the associator " +
                                    p.component("associator").type +
                                    " updates a track with several at once (probabilistic association): not supported");
  }
  return std::make_unique<MultiTracker>(p.node(), std::move(estimator), p.components("adapters"), std::move(associator),
                                        std::move(initiator), std::move(deleter),
                                        static_cast<int>(p.integer("max_tracks")), estimator_entry.type);
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "tracker.multi";
  d.kind = ComponentKind::Tracker;
  d.summary = "Multi-target tracker composed of an estimator per track, an associator, an initiator and a deleter; "
              "one TrackSet per scan";
  d.doc =
      "Per scan (Stone Soup's MultiTargetTracker): every track is predicted to the scan's time and gives its "
      "predicted measurement (z^, S, log det S; the scan's R is its first detection's); the associator gives "
      "detections to tracks; each track updates with its detection or misses; the initiator confirms tentative "
      "tracks or fails them, the deleter drops confirmed ones; the initiator starts tracks from the detections no "
      "track took; the set of all tracks is published (a deleted track once, with status deleted). Track ids are "
      "unique in a run and never reused. A scan with valid: false (the sensor did not look) changes nothing. A track "
      "whose state comes out non-finite is deleted and counted. Each track keeps its score L, the log-likelihood "
      "ratio of target against false alarms (Blackman & Popoli 1999, sec. 6.2), published as the track's score: it "
      "starts at the initiator's value (0 by default) and adds per look ln(P_D/beta_FA) + ln N(nu; 0, S) for a "
      "detection used, ln(1 - P_D) for a miss, with the scan's P_D and clutter density beta_FA (NaN when the scan "
      "states them not); init.score and delete.score read it. The estimator is any filter type with a per-track "
      "estimator (filter.kalman, filter.ekf, filter.ukf, filter.imm, ...), with that filter's parameters. Adapters "
      "(adapters: [{type: adapt.innovation_r, ...}]) run per track: every track has its own instances, restarted "
      "with the configured noise when the track starts, called around each of its updates (and initiating "
      "detections) with its detection and estimate, retuning that track's estimator's noise and covariance only; "
      "their annotations are on the track's estimate. What they need is checked against the estimator before "
      "anything runs. Gating and the track score use the detection's own R: an adapter sees a detection only once "
      "the associator gave it to the track. See docs/multi-target.md.";
  d.accepts = mask(ItemKind::Scan);
  d.produces = mask(ItemKind::Tracks);
  d.params = {
      ParamSpec::component("estimator", {ComponentKind::Filter},
                           "each track's estimator: a filter type and its parameters, e.g. { type: filter.kalman, q: 1 m2/s3 }")
          .req(),
      ParamSpec::component("associator", {ComponentKind::Associator}, "data association, e.g. { type: assoc.gnn }").req(),
      ParamSpec::component("initiator", {ComponentKind::Initiator}, "track initiation and confirmation, e.g. { type: init.m_of_n }")
          .req(),
      ParamSpec::component("deleter", {ComponentKind::Deleter}, "deletion of confirmed tracks, e.g. { type: delete.misses }").req(),
      ParamSpec::component_list("adapters", {ComponentKind::Adapter},
                                "adapters run per track, each track with its own instances (as `attach_to:` on a "
                                "single-track filter), e.g. [{ type: adapt.innovation_r, window: 20 }]; none by default")
          .def("[]"),
      ParamSpec::integer("max_tracks", "at most this many tracks alive; further starts are refused and counted")
          .def("10000")
          .at_least(1),
  };
  d.create = create;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("tracker.multi", trackflow::register_components)
