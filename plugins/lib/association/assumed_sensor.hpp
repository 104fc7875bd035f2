// Purpose: the sensor model an associator assumes — P_D and the clutter density from its parameters when given (a mismatch study), else the scan's — declared and resolved the same way by every associator.
#pragma once

#include <trackflow/error.hpp>
#include <trackflow/params.hpp>
#include <trackflow/scan.hpp>

#include <cmath>
#include <limits>
#include <string>

namespace trackflow::association {

// What a scan is assumed to be: P_D (the parameter, else the scan's, else 0.9) and the false-alarm
// density per unit of Cartesian measurement space (the parameter, else the scan's; none is an error).
class AssumedSensor {
 public:
  static constexpr double kDefaultDetectionProbability = 0.9;

  AssumedSensor() = default;
  AssumedSensor(const Params& p, std::string who)
      : detection_probability_(p.real_or("detection_probability", std::numeric_limits<double>::quiet_NaN())),
        clutter_density_(p.real_or("clutter_density", std::numeric_limits<double>::quiet_NaN())),
        who_(std::move(who)) {}

  double detection_probability(const Scan& scan) const {
    return std::isfinite(detection_probability_) ? detection_probability_
           : std::isfinite(scan.detection_probability) ? scan.detection_probability
                                                        : kDefaultDetectionProbability;
  }
  // Throws DataError when neither the parameter nor the scan states a density.
  double clutter_density(const Scan& scan) const {
    const double lambda = std::isfinite(clutter_density_) ? clutter_density_ : scan.clutter_density;
    if (!(lambda > 0.0))
      throw DataError(who_ + ": the scan at t=" + std::to_string(scan.time) + " s states no clutter density; give clutter_density");
    return lambda;
  }

  // The two parameters, declared alike by every associator that takes them.
  static ParamSpec detection_probability_param() {
    return ParamSpec::real("detection_probability", Dimension{}, "assumed P_D (default: the scan's, else 0.9)")
        .positive()
        .at_most(1);
  }
  static ParamSpec clutter_density_param() {
    return ParamSpec::real("clutter_density", Dimension{-3, 0, 0, 0},
                           "assumed false detections per m3 of Cartesian measurement space (default: the scan's)")
        .positive();
  }

 private:
  double detection_probability_ = std::numeric_limits<double>::quiet_NaN();
  double clutter_density_ = std::numeric_limits<double>::quiet_NaN();
  std::string who_;
};

}  // namespace trackflow::association
