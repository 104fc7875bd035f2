// Purpose: Scan — one look of one sensor: its frame, 0..N detections, whether it looked at all, and what it knows of its clutter.
#pragma once

#include <trackflow/items.hpp>

#include <cmath>
#include <limits>
#include <span>

namespace trackflow {

// The part of measurement space a look covered, in the SensorFrame's measurement coordinates
// (spherical: range m, azimuth and elevation rad; Cartesian: x, y, z m). Clutter is spread over
// it and a tracker's false-alarm density is its count over its volume.
struct SurveillanceRegion {
  bool known = false;
  double lo[3] = {0.0, 0.0, 0.0};
  double hi[3] = {0.0, 0.0, 0.0};
  int dim = 3;  // 2: a surveillance radar's range-azimuth, or planar x-y
  double volume() const {
    double v = 1.0;
    for (int i = 0; i < dim; ++i) v *= hi[i] - lo[i];
    return v;
  }
};

// One look of one sensor (ItemKind::Scan). An empty `detections` means the sensor looked and saw
// nothing, which a tracker must tell from not having looked (valid = false: not locked, coast).
// The detections are owned by the emitting node and valid only during the delivery.
struct Scan {
  double time = 0.0;
  bool valid = true;
  SensorFrame sensor;
  std::span<const Detection> detections;
  SurveillanceRegion region;
  // Expected false detections per unit volume of `region` (e.g. per m rad rad); NaN: not known.
  double clutter_density = std::numeric_limits<double>::quiet_NaN();
  // The probability that a target in the region gives a detection, when the sensor states it; NaN: not known.
  double detection_probability = std::numeric_limits<double>::quiet_NaN();
};

// One detection of a scan as the single-detection Measurement an estimator takes (no allocation:
// the value and covariance are fixed-capacity).
inline void to_measurement(const Scan& s, const Detection& d, Measurement& m) {
  static_cast<SensorFrame&>(m) = s.sensor;
  static_cast<Detection&>(m) = d;
  m.time = s.time;
  m.valid = true;
}

}  // namespace trackflow
