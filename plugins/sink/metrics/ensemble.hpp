// Purpose: sink.metrics' per-run records and their run-ordered accumulation per time step.
#pragma once

#include "annotation_channels.hpp"
#include "step_sums.hpp"

#include <trackflow/component.hpp>
#include <trackflow/run_result_codec.hpp>

#include <cstdint>
#include <utility>
#include <vector>

namespace trackflow::metrics {

using InnovationVec = Eigen::Matrix<double, kMaxMeasDim, 1>;

// One estimate of one run. Every published estimate has a record (for the per-step fractions
// of runs initialised and updated); only `scored` ones enter the error metrics.
struct EstimateRecord {
  long long key = 0;        // llround(time / time_tolerance): the time step across runs
  double time = 0.0;
  bool initialised = false, updated = false;
  bool scored = false;      // initialised, finite and after first estimate + skip_initial
  float annotation[kMaxAnnotations] = {};  // AnnotationChannels::read, NaN: absent (float: kept per run)
  bool matched = false;     // a truth state exists at this time
  bool has_nees = false;    // matched and the covariance is positive definite
  Vec6 error = Vec6::Zero();  // estimate - truth, ENU [position; velocity]
  double nees = 0.0, nees_position = 0.0;
  int nis_dof = 0;          // innovation dimension; 0 when the estimate was not updated
  double nis = 0.0;
  InnovationVec innovation = InnovationVec::Zero();
  template <class Self, class F>
  static void fields(Self& e, F&& f) {
    f(e.key, e.time, e.initialised, e.updated, e.scored, e.annotation, e.matched, e.has_nees, e.error, e.nees,
      e.nees_position, e.nis_dof, e.nis, e.innovation);
  }
};

// A valid measurement of one run matched to truth (for the per-step measurement RMSE).
struct MeasurementRecord {
  long long key = 0;
  double time = 0.0;
  double sq_error = 0.0;
};

// A run's own sums for the one case that keeps nothing per step: a streaming run (time-ordered
// inputs) without truth and without series, e.g. a recorded log. Each step of the run adds its
// NIS / dof at once; the ensemble's ANIS is then their mean over runs and steps, equal to the mean
// over steps of the per-step ensemble mean when every run has the same steps and innovation
// dimensions (`fingerprint` tells) -- only the order of the sums differs (about 1e-16 relative).
struct RunSums {
  bool used = false;
  std::uint64_t scored = 0;      // scored estimates
  std::uint64_t steps = 0;       // time steps with a scored estimate
  std::uint64_t nis_steps = 0;   // time steps with an innovation
  double anis_sum = 0.0;         // sum over those steps of (sum of NIS) / (sum of dof)
  std::uint64_t nis_steps_in_band = 0;  // of those steps, inside their own one-run chi-square band
  double inverse_dof = 0.0;             // sum over those steps of 1 / (sum of dof): the average's band
  std::uint64_t nis_dof = 0, nis_count = 0;
  double innovation_sum[kMaxMeasDim] = {};
  std::uint64_t innovation_count[kMaxMeasDim] = {};
  int nis_dof_min = kMaxMeasDim + 1, nis_dof_max = 0;
  std::uint64_t fingerprint = 0;  // of every step's key, dof sum and whether it has a scored estimate
  template <class Self, class F>
  static void fields(Self& s, F&& f) {
    f(s.used, s.scored, s.steps, s.nis_steps, s.anis_sum, s.nis_steps_in_band, s.inverse_dof, s.nis_dof, s.nis_count, s.innovation_sum,
      s.innovation_count, s.nis_dof_min, s.nis_dof_max, s.fingerprint);
  }
};

struct MetricsRunResult final : RunResult {
  std::vector<EstimateRecord> records;
  std::vector<MeasurementRecord> measurement_records;
  bool had_truth = false;
  std::uint64_t before_window = 0;          // earlier than first estimate + skip_initial
  std::uint64_t non_finite = 0;             // estimates whose ENU state or time is not finite
  std::uint64_t unmatched = 0;              // outside the truth's time span (or no truth)
  std::uint64_t not_positive_definite = 0;  // matched, but NEES undefined
  // Measurement baseline of this run (a sum over one run is fixed by the run's own item order).
  double measurement_sq_error = 0.0;
  std::uint64_t measurements_matched = 0, measurements_unmatched = 0;
  RunSums sums;
  // Streaming runs without truth with series: the run's per-step series, binned (series_bin_width
  // time keys a bin; 0: not used, the series comes from `records`).
  std::vector<SeriesBin> series_bins;
  long long series_bin_width = 0;
  // Streaming runs: the most estimates that waited for their truth at once (tests, diagnostics).
  std::uint64_t pending_high_water = 0;
  // A run's records as bytes and back, exactly (mpirun: run_result_codec.hpp's FieldListCodec);
  // the estimate records go one by one with their own list, the measurement records as one block.
  template <class Self, class F>
  static void fields(Self& r, F&& f) {
    f(r.records, r.measurement_records, r.had_truth, r.before_window, r.non_finite, r.unmatched,
      r.not_positive_definite, r.measurement_sq_error, r.measurements_matched, r.measurements_unmatched, r.sums,
      r.series_bins, r.series_bin_width, r.pending_high_water);
  }
};


// The time steps in key order (as a std::map iterates them), in one array: a run's records find
// their step from the previous record's (records come in time order), with no tree to walk.
using StepList = std::vector<std::pair<long long, StepSums>>;

// Everything merge() accumulates; add() must be called in run order for reproducible sums.
struct Ensemble {
  StepList steps;
  std::uint64_t runs = 0, runs_with_truth = 0;
  std::uint64_t estimates = 0, before_window = 0, non_finite = 0, unmatched = 0, not_positive_definite = 0;
  double measurement_sq_error = 0.0;
  std::uint64_t measurements_matched = 0, measurements_unmatched = 0;
  double innovation_sum[kMaxMeasDim] = {};
  std::uint64_t innovation_count[kMaxMeasDim] = {};
  int nis_dof_min = kMaxMeasDim + 1, nis_dof_max = 0;
  int annotation_channels = 0;
  // Runs merged from RunSums (no per-step table): their sums in run order, and whether the runs'
  // step structures (RunSums::fingerprint) differ.
  bool summed = false, summed_steps_differ = false;
  double summed_anis = 0.0;
  std::uint64_t summed_steps = 0, summed_nis_steps = 0, summed_nis_dof = 0, summed_nis_count = 0;
  std::uint64_t summed_nis_steps_in_band = 0;
  double summed_inverse_dof = 0.0;
  std::uint64_t summed_fingerprint = 0;
  // The binned series of such runs (SeriesBin), merged in run order at the widest run's width.
  std::vector<SeriesBin> bins;
  long long bin_width = 0;

  void add(const MetricsRunResult& run);

 private:
  void add_sums(const RunSums& r);
  void add_bins(const std::vector<SeriesBin>& run_bins, long long width);
  std::vector<SeriesBin> bin_scratch_;
  std::vector<long long> missing_;  // add()'s scratch: keys of the run not yet in steps
};

struct ReportOptions {
  double confidence = 0.95;
  double skip_initial = 0.0;
  bool truth_input = false;        // a truth stream is wired (or arrived)
  bool measurement_input = false;  // a measurement stream is wired
};

void report(const Ensemble& e, const ReportOptions& opt, Summary& summary);

// The per-step ensemble series (one row per time step): RMSE, mean errors, ANEES and ANIS
// with their per-step chi-square bands, measurement RMSE, fractions of runs initialised and
// updated, and the per-step mean of each annotation channel that occurs.
Series ensemble_series(const Ensemble& e, const ReportOptions& opt, const AnnotationChannels& channels);

}  // namespace trackflow::metrics
