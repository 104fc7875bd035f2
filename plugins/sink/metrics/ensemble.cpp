// Purpose: sink.metrics' run-ordered accumulation and the ensemble report (RMSE, bias, ANEES, ANIS with chi-square bands).
#include "ensemble.hpp"

#include "scoring/chi_square_band.hpp"
#include "scoring/consistency_test.hpp"

#include <trackflow/number_text.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>
#include <iterator>
#include <string>

namespace trackflow::metrics {

namespace {

constexpr std::size_t kNoStep = static_cast<std::size_t>(-1);

// The binary search of find_step, out of line: the two likely places are checked inline (twice
// per record, every run), where a call for every record cost more than the checks.
[[gnu::noinline]] std::size_t search_step(const StepList& steps, long long key) {
  const auto it = std::lower_bound(steps.begin(), steps.end(), key,
                                   [](const std::pair<long long, StepSums>& s, long long k) { return s.first < k; });
  return it != steps.end() && it->first == key ? static_cast<std::size_t>(it - steps.begin()) : kNoStep;
}
// Index of the step `key` in `steps`, or kNoStep. Records come in time order, so the step is
// nearly always the previous record's (`cursor`) or the next; otherwise a binary search.
inline std::size_t find_step(const StepList& steps, long long key, std::size_t cursor) {
  const std::size_t n = steps.size();
  if (cursor < n && steps[cursor].first == key) return cursor;
  if (cursor + 1 < n && steps[cursor + 1].first == key) return cursor + 1;
  return search_step(steps, key);
}

// Adds the keys in `missing` (any order, repeats allowed) as empty steps, keeping key order: one
// merge of two sorted lists, so a run with new steps costs linear time wherever they fall.
void insert_steps(StepList& steps, std::vector<long long>& missing) {
  std::sort(missing.begin(), missing.end());
  missing.erase(std::unique(missing.begin(), missing.end()), missing.end());
  if (steps.empty() || missing.front() > steps.back().first) {
    for (long long k : missing) steps.emplace_back(k, StepSums{});
    return;
  }
  StepList merged;
  merged.reserve(steps.size() + missing.size());
  std::size_t i = 0;
  for (long long k : missing) {
    while (i < steps.size() && steps[i].first < k) merged.push_back(std::move(steps[i++]));
    merged.emplace_back(k, StepSums{});
  }
  while (i < steps.size()) merged.push_back(std::move(steps[i++]));
  steps.swap(merged);
}

}  // namespace

void Ensemble::add_bins(const std::vector<SeriesBin>& run_bins, long long width) {
  if (width > bin_width) {
    if (bin_width > 0) coarsen(bins, width);
    bin_width = width;
  }
  const std::vector<SeriesBin>* from = &run_bins;
  if (width < bin_width) {
    bin_scratch_ = run_bins;
    coarsen(bin_scratch_, bin_width);
    from = &bin_scratch_;
  }
  // Both lists are in key order: one merge (a run's bins usually are the ensemble's, in order).
  std::vector<SeriesBin> merged;
  std::size_t i = 0;
  bool in_place = true;
  for (const SeriesBin& b : *from) {
    while (i < bins.size() && bins[i].key < b.key) ++i;
    if (i == bins.size() || bins[i].key != b.key) {
      in_place = false;
      break;
    }
  }
  if (in_place) {
    i = 0;
    for (const SeriesBin& b : *from) {
      while (bins[i].key < b.key) ++i;
      add_step_sums(bins[i].sums, b.sums);
    }
  } else {
    merged.reserve(bins.size() + from->size());
    i = 0;
    for (const SeriesBin& b : *from) {
      while (i < bins.size() && bins[i].key < b.key) merged.push_back(bins[i++]);
      if (i < bins.size() && bins[i].key == b.key) {
        merged.push_back(bins[i++]);
      } else {
        merged.emplace_back().key = b.key;
      }
      add_step_sums(merged.back().sums, b.sums);
    }
    while (i < bins.size()) merged.push_back(bins[i++]);
    bins.swap(merged);
  }
  while (bins.size() > kMaxSeriesBins) {
    bin_width *= 2;
    coarsen(bins, bin_width);
  }
}

void Ensemble::add(const MetricsRunResult& run) {
  ++runs;
  runs_with_truth += run.had_truth ? 1 : 0;
  before_window += run.before_window;
  non_finite += run.non_finite;
  unmatched += run.unmatched;
  not_positive_definite += run.not_positive_definite;
  measurement_sq_error += run.measurement_sq_error;
  measurements_matched += run.measurements_matched;
  measurements_unmatched += run.measurements_unmatched;
  if (run.sums.used) add_sums(run.sums);
  if (run.series_bin_width > 0) add_bins(run.series_bins, run.series_bin_width);
  // Steps this run reaches for the first time are created before anything is added, so every
  // step's sums grow in run order and, within a run, in record order (estimates, then
  // measurements), as with a map.
  missing_.clear();
  std::size_t cursor = 0;
  for (const EstimateRecord& r : run.records) {
    const std::size_t i = find_step(steps, r.key, cursor);
    if (i == kNoStep)
      missing_.push_back(r.key);
    else
      cursor = i;
  }
  cursor = 0;
  for (const MeasurementRecord& m : run.measurement_records) {
    const std::size_t i = find_step(steps, m.key, cursor);
    if (i == kNoStep)
      missing_.push_back(m.key);
    else
      cursor = i;
  }
  if (!missing_.empty()) insert_steps(steps, missing_);
  cursor = 0;
  for (const EstimateRecord& r : run.records) {
    cursor = find_step(steps, r.key, cursor);
    StepSums& s = steps[cursor].second;
    if (!s.has_time) {
      s.time = r.time;
      s.has_time = true;
    }
    ++s.published;
    s.initialised += r.initialised ? 1 : 0;
    s.updated += r.updated ? 1 : 0;
    if (r.initialised) s.annotations.add(r.annotation, annotation_channels);
    if (!r.scored) continue;
    ++estimates;
    ++s.estimates;
    if (r.matched) {
      ++s.matched;
      for (int i = 0; i < 6; ++i) {
        s.sq[i] += r.error(i) * r.error(i);
        s.sum[i] += r.error(i);
      }
    }
    if (r.has_nees) {
      ++s.nees_count;
      s.nees += r.nees;
      s.nees_position += r.nees_position;
    }
    if (r.nis_dof > 0) {
      ++s.nis_count;
      s.nis_dof += static_cast<std::uint64_t>(r.nis_dof);
      s.nis += r.nis;
      nis_dof_min = std::min(nis_dof_min, r.nis_dof);
      nis_dof_max = std::max(nis_dof_max, r.nis_dof);
      for (int i = 0; i < r.nis_dof; ++i) {
        innovation_sum[i] += r.innovation(i);
        ++innovation_count[i];
      }
    }
  }
  cursor = 0;
  for (const MeasurementRecord& m : run.measurement_records) {
    cursor = find_step(steps, m.key, cursor);
    StepSums& s = steps[cursor].second;
    if (!s.has_time) {
      s.time = m.time;
      s.has_time = true;
    }
    ++s.measurements;
    s.measurement_sq += m.sq_error;
  }
}

void Ensemble::add_sums(const RunSums& r) {
  summed_steps_differ = summed_steps_differ || (summed && (r.fingerprint != summed_fingerprint || r.steps != summed_steps));
  if (!summed) {
    summed_fingerprint = r.fingerprint;
    summed_steps = r.steps;
  }
  summed = true;
  summed_steps = std::max(summed_steps, r.steps);  // the most of one run, when the runs differ
  summed_anis += r.anis_sum;
  summed_nis_steps += r.nis_steps;
  summed_nis_steps_in_band += r.nis_steps_in_band;
  summed_inverse_dof += r.inverse_dof;
  summed_nis_dof += r.nis_dof;
  summed_nis_count += r.nis_count;
  estimates += r.scored;
  nis_dof_min = std::min(nis_dof_min, r.nis_dof_min);
  nis_dof_max = std::max(nis_dof_max, r.nis_dof_max);
  for (int i = 0; i < kMaxMeasDim; ++i) {
    innovation_sum[i] += r.innovation_sum[i];
    innovation_count[i] += r.innovation_count[i];
  }
}

namespace {

std::string count_text(std::uint64_t n, const char* what) {
  return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
}

std::string seconds_text(double v) {
  return number_text::general(v, 6) + " s";  // printf's "%g s"
}

// Never lets a NaN or infinity reach the summary: it becomes a note instead.
void put(Summary& s, const std::string& name, double v, const char* unit = "") {
  if (std::isfinite(v))
    s.metric(name, v, unit);
  else
    s.notes.push_back(name + " not reported: its value is not finite (a diverged estimate?)");
}
void put_band(Summary& s, const std::string& name, double v, Band b, double confidence) {
  if (std::isfinite(v) && std::isfinite(b.lo) && std::isfinite(b.hi))
    s.metric_band(name, v, b.lo, b.hi, confidence);
  else
    s.notes.push_back(name + " not reported: its value is not finite (a diverged estimate?)");
}

// The consistency tests of a per-step series (consistency_test.hpp), reported as `name` (the
// time average, with the band of `nu` degrees of freedom when nu > 0 and the band has power) and
// `name`_steps_in_band (the fraction of the `steps` inside their own band, with its binomial
// acceptance for `effective` independent steps when that has power).
void report_tests(Summary& s, const std::string& name, double average, double nu, std::size_t steps,
                  std::uint64_t in_band, double effective, double confidence) {
  const Band band = chi_square_band(nu > 0.0 ? nu : 1.0, confidence);
  if (nu > 0.0 && band_has_power(band)) {
    put_band(s, name, average, band, confidence);
  } else {
    put(s, name, average);
    if (nu > 0.0)
      s.notes.push_back(name + ": no band: " + number_text::general(nu, 4) +
                        " degrees of freedom are too few to tell a covariance wrong by a factor of 2 (the band "
                        "would be [" + number_text::general(band.lo, 4) + ", " + number_text::general(band.hi, 4) +
                        "])");
  }
  const double fraction = static_cast<double>(in_band) / static_cast<double>(steps);
  const double accept = binomial_acceptance(effective, confidence, confidence);
  const std::string fraction_name = name + "_steps_in_band";
  if (effective >= kMinEffectiveSteps) {
    if (std::isfinite(fraction)) s.metric_band(fraction_name, fraction, accept, 1.0, confidence);
  } else {
    put(s, fraction_name, fraction);
    s.notes.push_back(fraction_name + ": no acceptance: " + number_text::general(effective, 4) +
                      " independent steps are too few for the per-step test (at least " +
                      number_text::general(kMinEffectiveSteps, 4) + ")");
  }
}

// Mean over steps of the per-step average NIS, tested two ways (report_tests): innovations of a
// consistent filter are white (Bar-Shalom, Li & Kirubarajan 2001 §5.4.2), so every step counts
// as independent. Runs without a per-step table (RunSums) get the time average's band only.
void report_anis(const Ensemble& e, const ReportOptions& opt, Summary& s) {
  double total = 0.0;
  std::uint64_t n = 0, in_band = 0;
  std::vector<double> dof;
  std::map<std::uint64_t, Band> bands;  // quantiles are costly; steps share few dof values
  auto step = [&](const StepSums& st) {
    if (st.nis_count == 0) return;
    const double anis_k = st.nis / static_cast<double>(st.nis_dof);
    auto it = bands.find(st.nis_dof);
    if (it == bands.end())
      it = bands.emplace(st.nis_dof, chi_square_band(static_cast<double>(st.nis_dof), opt.confidence)).first;
    in_band += anis_k >= it->second.lo && anis_k <= it->second.hi ? 1 : 0;
    dof.push_back(static_cast<double>(st.nis_dof));
    total += anis_k;
    ++n;
  };
  // A run without truth keeps its steps as series bins (one step each up to kMaxSeriesBins; a
  // bin of several is one chi-square value of their summed dof, so the tests hold for bins too).
  if (e.bin_width > 0) {
    for (const SeriesBin& b : e.bins) step(b.sums);
  } else {
    for (const auto& [key, st] : e.steps) step(st);
  }
  const bool rows = n > 0;
  // Runs without a step table (RunSums): the mean over runs and steps of each run's step value,
  // which is the mean over steps of the ensemble's when all runs share their steps.
  if (e.summed) {
    if (!rows) {
      in_band = 0;
      dof.clear();
    }
    total = e.summed_anis;
    n = e.summed_nis_steps;
    if (n && e.summed_steps_differ)
      s.notes.push_back("anis: the runs differ in their time steps or innovation dimensions, and a streaming run "
                        "without truth keeps no per-step table, so anis is the mean over every run's steps (steps: "
                        "the most of one run)");
  }
  if (n == 0) {
    s.notes.push_back("anis not reported: no updated estimate carries an innovation");
    return;
  }
  if (e.nis_dof_min != e.nis_dof_max)
    s.notes.push_back("anis: innovation dimension varies between " + std::to_string(e.nis_dof_min) + " and " +
                      std::to_string(e.nis_dof_max) + "; each step's band uses its own");
  const double average = total / static_cast<double>(n);
  if (e.summed && !rows) {
    // No step table (series: false): the average of every run's step values (white when
    // consistent), of nu = n^2 / sum(1 / dof) as time_average_dof counts it; the per-step test is
    // over each run's steps against their one-run band (the same tests as the table's for one run).
    if (e.runs > 1)
      s.notes.push_back("anis_steps_in_band: the fraction of every run's steps inside their one-run band (a "
                        "streaming run without truth keeps no per-step table of the ensemble)");
    const double steps = static_cast<double>(n);
    report_tests(s, "anis", average, steps * steps / e.summed_inverse_dof * 1.0, n, e.summed_nis_steps_in_band, steps,
                 opt.confidence);
    return;
  }
  const double steps = static_cast<double>(dof.size());
  report_tests(s, "anis", average, time_average_dof(dof, steps), dof.size(), in_band, steps, opt.confidence);
}

void report_errors(const Ensemble& e, Summary& s, double& position_rmse) {
  std::uint64_t matched = 0;
  double sq[6] = {}, sum[6] = {};
  double max_rms = 0.0;
  for (const auto& [key, st] : e.steps) {
    if (st.matched == 0) continue;
    matched += st.matched;
    for (int i = 0; i < 6; ++i) {
      sq[i] += st.sq[i];
      sum[i] += st.sum[i];
    }
    max_rms = std::max(max_rms, std::sqrt((st.sq[0] + st.sq[1] + st.sq[2]) / static_cast<double>(st.matched)));
  }
  if (matched == 0) {
    s.notes.push_back("error metrics not reported: no estimate could be matched to truth" +
                      std::string(e.estimates ? " (all are outside the truth's time span)" : " (no estimates)"));
    return;
  }
  const double N = static_cast<double>(matched);
  position_rmse = std::sqrt((sq[0] + sq[1] + sq[2]) / N);
  put(s, "position_rmse", position_rmse, "m");
  put(s, "position_rmse_x", std::sqrt(sq[0] / N), "m");
  put(s, "position_rmse_y", std::sqrt(sq[1] / N), "m");
  put(s, "position_rmse_z", std::sqrt(sq[2] / N), "m");
  put(s, "velocity_rmse", std::sqrt((sq[3] + sq[4] + sq[5]) / N), "m/s");
  put(s, "velocity_rmse_x", std::sqrt(sq[3] / N), "m/s");
  put(s, "velocity_rmse_y", std::sqrt(sq[4] / N), "m/s");
  put(s, "velocity_rmse_z", std::sqrt(sq[5] / N), "m/s");
  put(s, "mean_error_x", sum[0] / N, "m");
  put(s, "mean_error_y", sum[1] / N, "m");
  put(s, "mean_error_z", sum[2] / N, "m");
  put(s, "max_position_error_rms", max_rms, "m");
}

// ANEES_k = (sum over runs of NEES at step k) / (n M_k); reported is its mean over steps, without
// a band, and the per-step test (report_tests). Estimation errors are correlated in time, so the
// per-step test counts the effective number of independent steps of the ANEES_k series
// (consistency_test.hpp, reported as anees_effective_steps). The mean gets no band: its variance
// needs that correlation too, and on 600 steps the estimate of it is too loose for a 95 % band
// (the quickstart's band so made was missed on 3 of seeds 1-10 by a consistent filter).
void report_nees(const Ensemble& e, const ReportOptions& opt, Summary& s) {
  double total = 0.0, total_position = 0.0;
  std::uint64_t in_band = 0, in_band_position = 0;
  std::vector<double> anees, anees_position;
  std::map<std::uint64_t, std::pair<Band, Band>> band_for_runs;  // quantiles are costly; steps share few M_k
  for (const auto& [key, st] : e.steps) {
    if (st.nees_count == 0) continue;
    const double m = static_cast<double>(st.nees_count);
    const double anees_k = st.nees / (6.0 * m), position_k = st.nees_position / (3.0 * m);
    auto it = band_for_runs.find(st.nees_count);
    if (it == band_for_runs.end())
      it = band_for_runs
               .emplace(st.nees_count, std::pair{chi_square_band(6.0 * m, opt.confidence),
                                                 chi_square_band(3.0 * m, opt.confidence)})
               .first;
    in_band += anees_k >= it->second.first.lo && anees_k <= it->second.first.hi ? 1 : 0;
    in_band_position += position_k >= it->second.second.lo && position_k <= it->second.second.hi ? 1 : 0;
    anees.push_back(anees_k);
    anees_position.push_back(position_k);
    total += anees_k;
    total_position += position_k;
  }
  if (anees.empty()) {
    s.notes.push_back(e.not_positive_definite
                          ? "anees not reported: no matched estimate has a positive-definite covariance"
                          : "anees not reported: no estimate could be matched to truth");
    return;
  }
  const double n = static_cast<double>(anees.size());
  const double effective = effective_sample_size(anees), effective_position = effective_sample_size(anees_position);
  report_tests(s, "anees", total / n, 0.0, anees.size(), in_band, effective, opt.confidence);
  report_tests(s, "anees_position", total_position / n, 0.0, anees.size(), in_band_position, effective_position,
               opt.confidence);
  put(s, "anees_effective_steps", effective);
  if (e.not_positive_definite)
    s.notes.push_back("anees: left out " + count_text(e.not_positive_definite, "matched estimate") +
                      " whose covariance is not positive definite");
}

void report_measurements(const Ensemble& e, Summary& s, double position_rmse) {
  if (e.measurements_matched == 0) {
    s.notes.push_back("measurement_position_rmse not reported: no measurement could be matched to truth" +
                      std::string(e.measurements_unmatched ? " (outside its time span, or truth holds several targets)"
                                                           : " (no valid measurements)"));
    return;
  }
  const double rmse = std::sqrt(e.measurement_sq_error / static_cast<double>(e.measurements_matched));
  put(s, "measurement_position_rmse", rmse, "m");
  if (position_rmse >= 0.0 && rmse > 0.0)
    put(s, "rmse_ratio", position_rmse / rmse);
  else if (position_rmse >= 0.0)
    s.notes.push_back("rmse_ratio not reported: the measurement position RMSE is zero");
  if (e.measurements_unmatched)
    s.notes.push_back("measurement_position_rmse: " + count_text(e.measurements_unmatched, "measurement") +
                      " could not be matched to truth");
}

}  // namespace

void report(const Ensemble& e, const ReportOptions& opt, Summary& s) {
  if (e.runs == 0) {
    s.notes.push_back("no runs were merged: nothing to report");
    return;
  }
  const bool truth_mode = opt.truth_input || e.runs_with_truth > 0;
  std::uint64_t steps = 0;
  for (const auto& [key, st] : e.steps) steps += (truth_mode ? st.matched : st.estimates) > 0 ? 1 : 0;
  if (e.summed && !truth_mode) steps = e.summed_steps;

  if (truth_mode) {
    double position_rmse = -1.0;
    report_errors(e, s, position_rmse);
    report_nees(e, opt, s);
    report_anis(e, opt, s);
    if (opt.measurement_input) report_measurements(e, s, position_rmse);
    put(s, "estimates", static_cast<double>(e.estimates));
    put(s, "unmatched_estimates", static_cast<double>(e.unmatched));
    if (e.unmatched)
      s.notes.push_back(count_text(e.unmatched, "estimate") +
                        " lie outside the truth's time span and are left out of the error metrics");
  } else {
    s.notes.push_back("no truth input: only innovation statistics are reported (errors and NEES need truth)");
    report_anis(e, opt, s);
    for (int i = 0; i < kMaxMeasDim; ++i)
      if (e.innovation_count[i])
        put(s, "mean_innovation_" + std::to_string(i), e.innovation_sum[i] / static_cast<double>(e.innovation_count[i]));
    put(s, "estimates", static_cast<double>(e.estimates));
  }
  put(s, "runs", static_cast<double>(e.runs));
  put(s, "steps", static_cast<double>(steps));
  if (e.before_window)
    s.notes.push_back("left out " + count_text(e.before_window, "estimate") + " earlier than the first estimate + " +
                      "skip_initial (" + seconds_text(opt.skip_initial) + ")");
  if (e.non_finite)
    s.notes.push_back("left out " + count_text(e.non_finite, "estimate") + " with a non-finite state (diverged filter)");
}

}  // namespace trackflow::metrics
