// Purpose: the checks a tracker makes of each scan before its estimators see it — the frame and tilt the estimator takes, the estimator's own checks, and every detection's size and finiteness — one DataError text for every tracker.
#pragma once

#include <trackflow/error.hpp>
#include <trackflow/estimator.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/scan.hpp>

#include <string>

namespace trackflow::association {

// A scan the estimator cannot take is a data error (the wiring was checked before the run; the
// values are the data's). `who` names the tracker, e.g. "tracker.multi (node 'mtt')"; `scratch`
// holds the scan's first detection for the estimator's own checks (Estimator::check): what they
// test is the sensor's (a 2-D radar's tilt, say), which the scan's detections share.
inline void check_scan(const Scan& s, Estimator& estimator, Measurement& scratch, const std::string& who) {
  const MeasurementSpec& spec = estimator.measurement_spec();
  if (!(spec.frames & mask(s.sensor.frame)))
    throw DataError(who + ": its estimator takes " + frame_names(spec.frames) + " detections, but the scan at t=" +
                    std::to_string(s.time) + " s is " + to_string(s.sensor.frame));
  if (!s.sensor.sensor_level && !spec.tilted_sensors)
    throw DataError(who + ": the scan at t=" + std::to_string(s.time) +
                    " s comes from a tilted sensor, which its estimator does not turn into");
  if (!s.detections.empty()) {
    to_measurement(s, s.detections.front(), scratch);
    estimator.check(scratch);
  }
  for (const Detection& d : s.detections) {
    const int n = static_cast<int>(d.value.size());
    if (n != position_values(s.sensor.frame) + (d.has_range_rate ? 1 : 0) || d.covariance.rows() != n ||
        d.covariance.cols() != n || !d.value.allFinite() || !d.covariance.allFinite())
      throw DataError(who + ": a detection of the scan at t=" + std::to_string(s.time) + " s has " + std::to_string(n) +
                      " values and a " + std::to_string(d.covariance.rows()) + "x" + std::to_string(d.covariance.cols()) +
                      " covariance, or non-finite ones");
  }
}

}  // namespace trackflow::association
