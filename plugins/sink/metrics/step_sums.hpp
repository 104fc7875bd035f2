// Purpose: sink.metrics' sums of one time step over runs (StepSums) and the bounded, binned per-step series of a run without truth (SeriesBin).
#pragma once

#include "annotation_channels.hpp"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace trackflow::metrics {

struct StepSums {
  double time = 0.0;  // of the first run that reached this step
  bool has_time = false;
  std::uint64_t published = 0, initialised = 0, updated = 0;  // estimates of any kind
  AnnotationSums annotations;
  std::uint64_t measurements = 0;
  double measurement_sq = 0.0;
  std::uint64_t estimates = 0, matched = 0;  // scored estimates
  double sq[6] = {};   // sum of squared errors per ENU component
  double sum[6] = {};  // sum of errors (bias)
  std::uint64_t nees_count = 0;
  double nees = 0.0, nees_position = 0.0;
  std::uint64_t nis_count = 0, nis_dof = 0;
  double nis = 0.0;
  std::uint64_t run_steps = 0;  // (run, time step) pairs summed here: 1 per run and step (binned series)
};

// The per-step series of a run that keeps no per-estimate records (streaming, no truth: a
// recorded log) in bins of `width` time keys: bin key = floor(key / width) * width. A run starts
// at width 1 (one bin per time step, the step table's own rows) and doubles the width whenever
// it would hold more than kMaxSeriesBins, so a log of any length keeps a bounded series (issue 27:
// 10^6 rows scored in flat memory); the ensemble brings runs to the widest run's width.
struct SeriesBin {
  long long key = 0;
  StepSums sums;
};
inline constexpr std::size_t kMaxSeriesBins = 16384;

// A step's or a bin's sums added into another's (the bin keeps the earlier time).
inline void add_step_sums(StepSums& into, const StepSums& s) {
  if (!into.has_time && s.has_time) {
    into.time = s.time;
    into.has_time = true;
  }
  into.published += s.published;
  into.initialised += s.initialised;
  into.updated += s.updated;
  for (int c = 0; c < kMaxAnnotations; ++c) {
    into.annotations.sum[c] += s.annotations.sum[c];
    into.annotations.count[c] += s.annotations.count[c];
  }
  into.measurements += s.measurements;
  into.measurement_sq += s.measurement_sq;
  into.estimates += s.estimates;
  into.matched += s.matched;
  for (int i = 0; i < 6; ++i) {
    into.sq[i] += s.sq[i];
    into.sum[i] += s.sum[i];
  }
  into.nees_count += s.nees_count;
  into.nees += s.nees;
  into.nees_position += s.nees_position;
  into.nis_count += s.nis_count;
  into.nis_dof += s.nis_dof;
  into.nis += s.nis;
  into.run_steps += s.run_steps;
}

inline long long bin_key(long long key, long long width) {
  if (width <= 1) return key;
  long long q = key / width;
  if (key % width != 0 && key < 0) --q;  // floor, also before time 0
  return q * width;
}

// Merges neighbouring bins into bins of `width` (a multiple of their width), in place.
inline void coarsen(std::vector<SeriesBin>& bins, long long width) {
  std::size_t out = 0;
  for (std::size_t i = 0; i < bins.size(); ++i) {
    const long long k = bin_key(bins[i].key, width);
    if (out > 0 && bins[out - 1].key == k) {
      add_step_sums(bins[out - 1].sums, bins[i].sums);
    } else {
      if (out != i) bins[out] = bins[i];
      bins[out++].key = k;
    }
  }
  bins.resize(out);
}

// The bin of the time step `key` in a run's bins (keys never decrease), created when new;
// valid until the next call.
inline StepSums& series_bin(std::vector<SeriesBin>& bins, long long& width, long long key) {
  if (width < 1) width = 1;
  const long long k = bin_key(key, width);
  if (!bins.empty() && bins.back().key == k) return bins.back().sums;
  if (bins.size() >= kMaxSeriesBins) {
    while (bins.size() > kMaxSeriesBins / 2) {  // about half full afterwards: doublings stay rare
      width *= 2;
      coarsen(bins, width);
    }
    return series_bin(bins, width, key);
  }
  SeriesBin& b = bins.emplace_back();
  b.key = k;
  return b.sums;
}

}  // namespace trackflow::metrics
