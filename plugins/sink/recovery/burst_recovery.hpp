// Purpose: per-run burst recovery statistics from a filter's position errors: samples to return within a threshold, peak error, RMSE outside bursts.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace trackflow::recovery {

// Bursts of `length` samples starting at `offset`, `offset + period`, ... — sim.radar's shot-noise
// schedule, counted in samples of the run from 0.
struct BurstSchedule {
  long long length = 10, period = 4000, offset = 4000;
  bool in_burst(long long k) const { return k >= offset && (k - offset) % period < length; }
};

struct Settings {
  BurstSchedule bursts;
  double threshold = 1.0;      // m: "recovered" means a position error at most this
  long long hold = 1;          // ... for this many consecutive samples
  long long exclude_after = 0; // samples after each burst also left out of the RMSE
};

// One sample of the filter's output: its position error against truth, or +inf when there is
// none to judge (not initialised, not matched to truth, or not finite).
struct Sample {
  double error = std::numeric_limits<double>::infinity();
  bool scored = false;  // counts in the RMSE outside bursts (matched, finite, after the transient)
};

struct BurstOutcome {
  long long samples = 0;   // from the first sample after the burst to the start of the holding streak
  bool recovered = false;  // false: censored at the next burst or the end of the run
  double peak_error = 0.0; // largest error from the burst's start until recovery (or censoring)
};

struct RunStats {
  std::vector<BurstOutcome> bursts;
  double sq_error = 0.0;  // outside bursts and their exclude_after tails
  std::uint64_t count = 0;
};

// Bursts whose first post-burst sample lies beyond the run are not counted. A burst is judged
// up to the next burst's start (or the run's end): recovery must begin early enough for the
// whole holding streak to fit.
inline RunStats evaluate(const std::vector<Sample>& samples, const Settings& s) {
  RunStats out;
  const long long n = static_cast<long long>(samples.size());
  const BurstSchedule& b = s.bursts;
  for (long long start = b.offset; start < n; start += b.period) {
    const long long first = start + b.length;          // first sample after the burst
    if (first >= n) break;
    const long long limit = std::min(n, start + b.period);  // the next burst begins here
    BurstOutcome o;
    for (long long k = start; k < first; ++k) o.peak_error = std::max(o.peak_error, samples[k].error);
    long long streak = 0;
    long long k = first;
    for (; k < limit; ++k) {
      streak = samples[k].error <= s.threshold ? streak + 1 : 0;
      if (streak == 0) o.peak_error = std::max(o.peak_error, samples[k].error);
      if (streak == s.hold) break;
    }
    if (k < limit) {
      o.recovered = true;
      o.samples = k - s.hold + 1 - first;
    } else {
      o.samples = limit - first;
    }
    out.bursts.push_back(o);
  }
  for (long long k = 0; k < n; ++k) {
    if (!samples[k].scored) continue;
    bool excluded = false;
    if (k >= b.offset) {
      const long long phase = (k - b.offset) % b.period;
      excluded = phase < b.length + s.exclude_after;
    }
    if (excluded) continue;
    out.sq_error += samples[k].error * samples[k].error;
    ++out.count;
  }
  return out;
}

}  // namespace trackflow::recovery
