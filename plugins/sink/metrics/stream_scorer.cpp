// Purpose: sink.metrics' streaming path (stream_scorer.hpp): estimates scored when their truth is certain, measurements when truth and window start are, truth dropped once no lookup can reach it.
#include "stream_scorer.hpp"

#include "record_scoring.hpp"
#include "scoring/chi_square_band.hpp"
#include "scoring/truth_match.hpp"

#include <algorithm>
#include <cmath>

namespace trackflow::metrics {

namespace {

constexpr std::size_t kPruneAt = 4096;  // truth samples kept before dropping the unreachable ones

std::uint64_t mix(std::uint64_t h, std::uint64_t v) {  // splitmix64 of the running hash and a value
  std::uint64_t z = h ^ (v + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2));
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

}  // namespace

void StreamScorer::configure(const StreamOptions& o, const AnnotationChannels* channels) {
  opt_ = o;
  channels_ = channels;
}

void StreamScorer::start_run() {
  if (!run_count_++) {  // sized once, in the instance that runs (not the aggregating one)
    if (opt_.truth_input) truth_.reserve(2 * kPruneAt);
    pending_.reserve(64);
    pending_measurements_.reserve(64);
    before_start_.reserve(64);
  }
  run_ = std::make_unique<MetricsRunResult>();
  if (!opt_.sums_only) run_->records.reserve(records_reserve_);
  if (opt_.sums_only && opt_.series) run_->series_bins.reserve(bins_reserve_);
  // The series' measurement records likewise: grown from empty in every run, they were the hot
  // path's only allocations (and copies) after the first run.
  if (opt_.series) run_->measurement_records.reserve(measurement_records_reserve_);
  truth_.clear();
  latest_truth_ = -kInf;
  truth_seen_ = truth_unordered_ = false;
  start_known_ = false;
  start_ = 0.0;
  first_measurement_ = kInf;
  last_estimate_ = last_measurement_ = -kInf;
  estimate_seen_ = measurement_seen_ = false;
  holding_ = false;
  pending_.clear();
  pending_measurements_.clear();
  before_start_.clear();
  estimate_cursor_ = measurement_cursor_ = cursor_base_ = nullptr;
  step_open_ = false;
  bin_step_open_ = false;
}

void StreamScorer::on_truth(const Truth& t) {
  truth_seen_ = true;
  if (std::isnan(t.time) || t.time < latest_truth_)
    truth_unordered_ = true;
  else
    latest_truth_ = t.time;
  insert_truth(truth_, t);
  drain(false);
  prune_truth();
}

// Mirrors the stored path's on_estimate (which estimates are kept, same_time: last's
// replacement) and its end_run loop (window, non-finite, scoring), item by item.
void StreamScorer::on_estimate(const Estimate& e) {
  if (std::isfinite(e.time)) {
    last_estimate_ = e.time;
    estimate_seen_ = true;
  }
  if (!e.initialised && !opt_.series) return;
  if (!opt_.last_at_time) {
    commit(e);
    return;
  }
  if (holding_ && std::abs(e.time - held_.time) <= opt_.tolerance) {
    held_ = e;
    return;
  }
  if (holding_) commit(held_);
  held_ = e;
  holding_ = true;
}

void StreamScorer::commit(const Estimate& e) {
  MetricsRunResult& r = *run_;
  // Times never decrease, so the first initialised estimate is the earliest (as window_start finds).
  if (e.initialised && !start_known_ && !std::isnan(e.time)) set_start(e.time + opt_.skip_initial);
  if (!std::isfinite(e.time)) {
    if (e.initialised) ++r.non_finite;
    return;
  }
  const long long key = round_key(e.time / opt_.tolerance);
  EstimateRecord* rec = nullptr;
  StepSums* bin = nullptr;  // sums_only with series: what Ensemble::add would add for a record
  if (!opt_.sums_only) {
    rec = &r.records.emplace_back();
    rec->key = key;
    rec->time = e.time;
    rec->initialised = e.initialised;
    rec->updated = e.initialised && e.updated;
  } else if (opt_.series) {
    bin = &series_bin(r.series_bins, r.series_bin_width, key);
    if (!bin_step_open_ || key != bin_step_key_) {
      ++bin->run_steps;
      bin_step_open_ = true;
      bin_step_key_ = key;
    }
    if (!bin->has_time) {
      bin->time = e.time;
      bin->has_time = true;
    }
    ++bin->published;
    bin->initialised += e.initialised ? 1 : 0;
    bin->updated += e.initialised && e.updated ? 1 : 0;
  }
  if (!e.initialised) return;
  if (rec && opt_.series) channels_->read(e, rec->annotation);
  if (bin) {
    float annotation[kMaxAnnotations];
    channels_->read(e, annotation);
    bin->annotations.add(annotation, channels_->count());
  }
  if (e.time + opt_.tolerance < start_) {
    ++r.before_window;
    return;
  }
  if (!all_finite(e.enu)) {
    ++r.non_finite;
    return;
  }
  if (opt_.sums_only) {  // no truth input: every scored estimate is unmatched, as in the stored path
    add_to_step(key, e.updated, e.nis, e.innovation);
    ++r.unmatched;
    if (bin) {
      ++bin->estimates;
      const int m = static_cast<int>(e.innovation.size());
      if (e.updated && m > 0 && std::isfinite(e.nis)) {
        ++bin->nis_count;
        bin->nis_dof += static_cast<std::uint64_t>(m);
        bin->nis += e.nis;
      }
    }
    return;
  }
  score_innovation(*rec, e.updated, e.nis, e.innovation);
  const std::size_t index = r.records.size() - 1;
  if (pending_.empty() && score(index, e.time, e.target, e.enu, e.enu_covariance, false)) return;
  PendingEstimate& p = pending_.push();
  p.record = index;
  p.time = e.time;
  p.target = e.target;
  p.enu = e.enu;
  p.covariance = e.enu_covariance;
  r.pending_high_water = std::max<std::uint64_t>(r.pending_high_water, pending_.size());
}

bool StreamScorer::score(std::size_t record, double time, std::uint32_t target, const Vec6& enu,
                         const Mat6& covariance, bool all) {
  Vec6 truth;
  const Lookup found = lookup(target, false, time, truth, all, estimate_cursor_);
  if (found == Lookup::Wait) return false;
  if (found == Lookup::Unmatched)
    ++run_->unmatched;
  else
    score_error(run_->records[record], enu, covariance, truth, *run_);
  return true;
}

// truth_at(t) once it can no longer change (`all`: the run has ended), else Wait. Samples come
// in time order, so none can arrive within t + tolerance once the target's own samples are past
// it (a lookup reads no sample later than the first one past t + tolerance), and none can beat a
// sample within tolerance that is at least as close as the latest sample is far. With one target
// in the truth so far, an estimate of another id is matched to it only if no second target ever
// comes: it waits for the end of the run. Measurements are matched to a single target only (with
// several they are unmatched). One search per call: the position of the last lookup (`cursor`,
// these times never decrease) is where truth_at starts.
StreamScorer::Lookup StreamScorer::lookup(std::uint32_t target, bool measurement, double t, Vec6& state, bool all,
                                          const Truth*& cursor) {
  if (!opt_.truth_input) return Lookup::Unmatched;  // no truth ever: truth_at of nothing
  const bool single = single_target(truth_);
  if (measurement && !single) return Lookup::Unmatched;
  if (!all && latest_truth_ < t - opt_.tolerance) return Lookup::Wait;  // the usual case: its truth is next
  if (!all && (truth_unordered_ || truth_.empty() || (single && target != truth_.front().target && !measurement)))
    return Lookup::Wait;
  if (truth_.data() != cursor_base_) {  // reallocated: no position to start from
    cursor_base_ = truth_.data();
    estimate_cursor_ = measurement_cursor_ = nullptr;
  }
  const TruthSpan span = truth_for(truth_, measurement ? 0 : target);
  const Truth** from = truth_unordered_ ? nullptr : &cursor;
  if (all) return truth_at(span, t, opt_.tolerance, state, from) ? Lookup::Matched : Lookup::Unmatched;
  if (span.begin == span.end) return Lookup::Wait;
  const double lo = t - opt_.tolerance, hi = t + opt_.tolerance;
  const Truth* it = cursor;
  if (it && it >= span.begin && it <= span.end && (it == span.begin || (it - 1)->time < lo)) {
    while (it != span.end && it->time < lo) ++it;
  } else {
    it = std::lower_bound(span.begin, span.end, lo, [](const Truth& x, double v) { return x.time < v; });
  }
  cursor = it;
  if ((single ? latest_truth_ : (span.end - 1)->time) <= hi) {
    if (it == span.end || it->time > hi) return Lookup::Wait;
    double best = std::abs(it->time - t);
    for (const Truth* q = it + 1; q != span.end && q->time <= hi; ++q) best = std::min(best, std::abs(q->time - t));
    if (!(latest_truth_ - t >= best)) return Lookup::Wait;
  }
  // `it` is where truth_at (from `cursor`) would start: its answer from there, without its search.
  return truth_from(span, it, t, opt_.tolerance, state) ? Lookup::Matched : Lookup::Unmatched;
}

void StreamScorer::on_measurement(double time, const Vec3& position) {
  if (!std::isnan(time)) first_measurement_ = std::min(first_measurement_, time);
  if (std::isfinite(time)) {
    last_measurement_ = time;
    measurement_seen_ = true;
  }
  // Without estimates the window starts at the first measurement (the earliest: time order).
  if (!opt_.estimate_input && !start_known_ && !std::isnan(time)) set_start(time + opt_.skip_initial);
  PendingMeasurement& p = pending_measurements_.push();
  p.time = time;
  p.position = position;
  drain(false);
}

// Scores what waits, in arrival order, while its truth is final (`all`: the run has ended).
void StreamScorer::drain(bool all) {
  // In batches: scoring between the filter's steps costs more than a short loop over a batch
  // (the quickstart: pipeline / plain loop 0.56 scoring each at once, 0.61 in batches of 64).
  if (!all && pending_.size() < kBatch && pending_measurements_.size() < kBatch) return;
  while (!pending_.empty()) {
    const PendingEstimate& p = pending_.front();
    if (!score(p.record, p.time, p.target, p.enu, p.covariance, all)) break;
    pending_.pop();
  }
  while (!pending_measurements_.empty()) {
    const PendingMeasurement& m = pending_measurements_.front();
    Vec6 truth;
    // A time that is not finite never matches (truth_at), whatever truth comes.
    const Lookup found = std::isfinite(m.time) ? lookup(0, true, m.time, truth, all, measurement_cursor_)
                                               : Lookup::Unmatched;
    if (found == Lookup::Wait) break;
    const bool matched = found == Lookup::Matched;
    window({m.time, matched, matched ? (m.position - truth.head<3>()).squaredNorm() : 0.0});
    pending_measurements_.pop();
  }
}

void StreamScorer::set_start(double start) {
  start_known_ = true;
  start_ = start;
  for (const ScoredMeasurement& m : before_start_) window(m);
  before_start_.clear();
}

void StreamScorer::window(const ScoredMeasurement& m) {
  if (!start_known_) {
    before_start_.push_back(m);
    return;
  }
  if (m.time + opt_.tolerance < start_) return;
  add_measurement(*run_, m.time, m.matched, m.sq, opt_.tolerance, opt_.series);
}

// One target, in time order: every later lookup is at or after the earliest time still waiting
// (or the latest seen, inputs being time-ordered), so samples before the one bracketing it are
// dropped, in blocks. Several targets or disordered truth keep everything.
void StreamScorer::prune_truth() {
  if (truth_.size() < kPruneAt || truth_unordered_ || !single_target(truth_)) return;
  double need = kInf;
  if (opt_.estimate_input) {
    if (!estimate_seen_) return;
    need = std::min(need, pending_.empty() ? last_estimate_ : pending_.front().time);
  }
  if (opt_.measurement_input) {
    if (!measurement_seen_) return;
    need = std::min(need, pending_measurements_.empty() || !std::isfinite(pending_measurements_.front().time)
                              ? last_measurement_
                              : pending_measurements_.front().time);
  }
  const double lo = need - opt_.tolerance;
  const auto it = std::lower_bound(truth_.begin(), truth_.end(), lo, [](const Truth& s, double v) { return s.time < v; });
  const auto drop = it - truth_.begin() - 1;  // keeps the sample before, for interpolation
  if (drop < static_cast<std::ptrdiff_t>(kPruneAt / 2)) return;
  truth_.erase(truth_.begin(), truth_.begin() + drop);
  estimate_cursor_ = measurement_cursor_ = nullptr;  // the samples moved
}

void StreamScorer::add_to_step(long long key, bool updated, double nis, const MeasVec& innovation) {
  RunSums& s = run_->sums;
  if (!step_open_ || key != step_key_) {
    close_step();
    step_open_ = true;
    step_key_ = key;
    step_nis_ = 0.0;
    step_dof_ = step_count_ = 0;
  }
  ++s.scored;
  const int m = static_cast<int>(innovation.size());
  if (!(updated && m > 0 && std::isfinite(nis))) return;
  step_nis_ += nis;
  step_dof_ += static_cast<std::uint64_t>(m);
  ++step_count_;
  s.nis_dof_min = std::min(s.nis_dof_min, m);
  s.nis_dof_max = std::max(s.nis_dof_max, m);
  for (int i = 0; i < m; ++i) {
    s.innovation_sum[i] += innovation(i);
    ++s.innovation_count[i];
  }
}

// A step of a sums_only run ends: the value the ensemble's step would add for this run alone.
void StreamScorer::close_step() {
  if (!step_open_) return;
  RunSums& s = run_->sums;
  ++s.steps;
  if (step_count_) {
    const double anis = step_nis_ / static_cast<double>(step_dof_);
    s.anis_sum += anis;
    s.inverse_dof += 1.0 / static_cast<double>(step_dof_);
    ++s.nis_steps;
    const Band& band = one_run_band(step_dof_);
    s.nis_steps_in_band += anis >= band.lo && anis <= band.hi ? 1 : 0;
    s.nis_dof += step_dof_;
    s.nis_count += step_count_;
  }
  s.fingerprint = mix(mix(s.fingerprint, static_cast<std::uint64_t>(step_key_)), step_dof_);
  step_open_ = false;
}

// The chi-square band of one step's summed innovation dimensions, cached: a quantile costs
// microseconds and a run's steps share a few dimensions.
const Band& StreamScorer::one_run_band(std::uint64_t dof) {
  for (const auto& [d, band] : bands_)
    if (d == dof) return band;
  return bands_.emplace_back(dof, chi_square_band(static_cast<double>(dof), opt_.confidence)).second;
}

std::unique_ptr<MetricsRunResult> StreamScorer::end_run() {
  if (holding_) commit(held_);
  holding_ = false;
  drain(true);  // the run's truth is complete: what still waits is final now
  if (!start_known_) set_start(first_measurement_ + opt_.skip_initial);
  MetricsRunResult& r = *run_;
  if (!single_target(truth_)) {  // measurements carry a sensor, not a target
    r.measurements_unmatched += r.measurements_matched;
    r.measurements_matched = 0;
    r.measurement_sq_error = 0.0;
    r.measurement_records.clear();
  }
  if (opt_.sums_only) {
    close_step();
    r.sums.used = true;
  }
  r.had_truth = truth_seen_;
  records_reserve_ = r.records.size();  // runs are usually of one length
  bins_reserve_ = r.series_bins.size();
  measurement_records_reserve_ = r.measurement_records.size();
  return std::move(run_);
}

}  // namespace trackflow::metrics
