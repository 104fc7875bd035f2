// Purpose: how one estimate's record is scored, shared by sink.metrics' stored path (end of run) and streaming path (as truth arrives), so both give the same bits.
#pragma once

#include "ensemble.hpp"
#include "scoring/nees.hpp"

#include <trackflow/items.hpp>

#include <cmath>

namespace trackflow::metrics {

// What needs no truth: the record is scored, and an updated estimate carries its innovation.
inline void score_innovation(EstimateRecord& rec, bool updated, double nis, const MeasVec& innovation) {
  rec.scored = true;
  const int m = static_cast<int>(innovation.size());
  if (updated && m > 0 && std::isfinite(nis)) {
    rec.nis_dof = m;
    rec.nis = nis;
    if (m == 3)  // the usual size, as a fixed-size copy (a run-time-sized one is a generic loop)
      rec.innovation.head<3>() = innovation.head<3>();
    else
      rec.innovation.head(m) = innovation;
  }
}

// std::llround(x), inline: a record's step key (time / tolerance) is rounded for every estimate
// and measurement, and the library call cost more than this. Below 2^52 the fraction x - trunc(x)
// is exact, so rounding half away from zero on it gives llround's result to the bit; larger
// values, infinities and NaN go to llround itself.
inline long long round_key(double x) {
  if (!(std::fabs(x) < 0x1p52)) return std::llround(x);
  long long r = static_cast<long long>(x);
  const double f = x - static_cast<double>(r);
  if (f >= 0.5)
    ++r;
  else if (f <= -0.5)
    --r;
  return r;
}

// Whether every element of a fixed-size matrix is finite: x * 0 is 0 for a finite x and NaN for an
// infinity or a NaN, so the products sum to 0 exactly when all are. The same answer as allFinite(),
// which for a Mat6 is 36 compare-and-branch pairs; this is a short vectorised sum.
template <class M>
inline bool all_finite(const M& a) {
  return (a.array() * 0.0).sum() == 0.0;
}

// A matched estimate: its error and (when the covariance allows) NEES and position NEES, from one
// factorisation of the covariance (nees.hpp).
inline void score_error(EstimateRecord& rec, const Vec6& enu, const Mat6& covariance, const Vec6& truth,
                        MetricsRunResult& r) {
  rec.matched = true;
  rec.error = enu - truth;
  double terms[6];
  if (all_finite(covariance) && nees_terms(covariance, rec.error, terms)) {
    rec.nees_position = terms[0] + terms[1] + terms[2];
    rec.nees = rec.nees_position + terms[3] + terms[4] + terms[5];
    rec.has_nees = std::isfinite(rec.nees) && std::isfinite(rec.nees_position);
  }
  if (!rec.has_nees) ++r.not_positive_definite;
}

// A measurement inside the window: into the run's baseline sums (and its record, for the series).
inline void add_measurement(MetricsRunResult& r, double time, bool matched, double sq, double tolerance,
                            bool series) {
  if (!matched) {
    ++r.measurements_unmatched;
    return;
  }
  r.measurement_sq_error += sq;
  ++r.measurements_matched;
  if (series) r.measurement_records.push_back({round_key(time / tolerance), time, sq});
}

}  // namespace trackflow::metrics
