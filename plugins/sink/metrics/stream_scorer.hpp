// Purpose: sink.metrics' streaming path: a run whose inputs are all time-ordered is scored as its items arrive, keeping only what still waits for truth.
#pragma once

#include "annotation_channels.hpp"
#include "ensemble.hpp"
#include "scoring/chi_square_band.hpp"

#include <trackflow/items.hpp>

#include <cstddef>
#include <limits>
#include <memory>
#include <vector>

namespace trackflow::metrics {

// A queue in one vector: popped items are dropped in blocks, so once the vector has grown to
// the longest wait of a run nothing is allocated any more.
template <class T>
class Fifo {
 public:
  void reserve(std::size_t n) { v_.reserve(n); }
  bool empty() const { return head_ == v_.size(); }
  std::size_t size() const { return v_.size() - head_; }
  T& front() { return v_[head_]; }
  const T& front() const { return v_[head_]; }
  void pop() { ++head_; }
  void clear() {
    v_.clear();
    head_ = 0;
  }
  T& push() {  // a new last item, to be filled in place (no temporary to copy)
    if (empty()) {
      clear();
    } else if (head_ >= 1024 && 2 * head_ >= v_.size()) {
      v_.erase(v_.begin(), v_.begin() + static_cast<std::ptrdiff_t>(head_));
      head_ = 0;
    }
    return v_.emplace_back();
  }

 private:
  std::vector<T> v_;
  std::size_t head_ = 0;
};

struct StreamOptions {
  double skip_initial = 0.0, tolerance = 1e-6;
  double confidence = 0.95;   // of the per-step bands (sums_only's steps in band)
  bool series = false;        // records of every estimate, uninitialised ones too (per-step series)
  bool last_at_time = false;  // same_time: last
  bool truth_input = false, estimate_input = false, measurement_input = false;
  // No truth input: the run keeps RunSums only, nothing per estimate, and with series its
  // per-step series in bounded bins (ensemble.hpp, SeriesBin).
  bool sums_only = false;
};

// Produces exactly the MetricsRunResult the stored path (metrics_sink.cpp) computes at the end
// of the run: the same records in the same order and the same sums in the same order. What
// makes that possible is the order: a later truth sample cannot come before the latest, so a
// lookup at t is final once the target's truth has passed t + tolerance (truth_match.hpp's
// rule looks no further), and the window's start is the first initialised estimate.
class StreamScorer {
 public:
  static constexpr std::size_t kBatch = 64;  // waiting items are scored once this many wait
  void configure(const StreamOptions& o, const AnnotationChannels* channels);
  void start_run();
  void on_truth(const Truth& t);
  void on_estimate(const Estimate& e);  // read in place; copied only while it waits for truth
  void on_measurement(double time, const Vec3& position);
  std::unique_ptr<MetricsRunResult> end_run();

 private:
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  struct PendingEstimate {
    // Filled in place by commit(): a user-provided constructor, so that Fifo::push's emplace_back()
    // does not zero its 46 words first (value-initialisation would).
    PendingEstimate() {}
    std::size_t record;
    double time;
    std::uint32_t target;
    Vec6 enu;
    Mat6 covariance;
  };
  struct PendingMeasurement {
    double time;
    Vec3 position;
  };
  struct ScoredMeasurement {  // matched against truth, waiting for the window's start
    double time;
    bool matched;
    double sq;
  };

  void commit(const Estimate& e);
  enum class Lookup { Wait, Unmatched, Matched };
  // Scores the record when its truth is final; false: it must wait.
  bool score(std::size_t record, double time, std::uint32_t target, const Vec6& enu, const Mat6& covariance, bool all);
  Lookup lookup(std::uint32_t target, bool measurement, double t, Vec6& state, bool all, const Truth*& cursor);
  void drain(bool all);
  void set_start(double start);
  void window(const ScoredMeasurement& m);
  void prune_truth();
  void add_to_step(long long key, bool updated, double nis, const MeasVec& innovation);
  void close_step();
  const Band& one_run_band(std::uint64_t dof);

  StreamOptions opt_;
  const AnnotationChannels* channels_ = nullptr;
  std::unique_ptr<MetricsRunResult> run_;
  std::size_t records_reserve_ = 1024;  // the previous run's record count
  std::size_t measurement_records_reserve_ = 1024;  // and measurement record count (series)
  std::size_t bins_reserve_ = 1024;                 // and series bin count (sums_only with series)
  std::uint64_t run_count_ = 0;

  // Truth of the run, sorted as insert_truth keeps it; with one target, only from what a lookup
  // can still reach.
  std::vector<Truth> truth_;
  double latest_truth_ = -kInf;
  bool truth_seen_ = false;
  bool truth_unordered_ = false;  // a sample earlier than the latest or without a time: wait for the end
  // Where the last estimate and measurement lookups ended (into truth_'s buffer `cursor_base_`).
  const Truth* estimate_cursor_ = nullptr;
  const Truth* measurement_cursor_ = nullptr;
  const Truth* cursor_base_ = nullptr;

  bool start_known_ = false;
  double start_ = 0.0;  // first initialised estimate + skip_initial
  double first_measurement_ = kInf;
  double last_estimate_ = -kInf, last_measurement_ = -kInf;
  bool estimate_seen_ = false, measurement_seen_ = false;

  Estimate held_;  // same_time: last: the latest estimate, until one at another time replaces it
  bool holding_ = false;

  Fifo<PendingEstimate> pending_;
  Fifo<PendingMeasurement> pending_measurements_;
  std::vector<ScoredMeasurement> before_start_;

  // sums_only: the time step being summed.
  bool step_open_ = false;
  long long step_key_ = 0;
  double step_nis_ = 0.0;
  std::uint64_t step_dof_ = 0, step_count_ = 0;
  // sums_only with series: the time step whose (run, step) pair was last counted in its bin.
  std::vector<std::pair<std::uint64_t, Band>> bands_;  // one_run_band's cache
  bool bin_step_open_ = false;
  long long bin_step_key_ = 0;
};

}  // namespace trackflow::metrics
