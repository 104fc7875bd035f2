// Purpose: validated, non-overlapping time windows [start, end) from Records parameters (mode and invalid schedules).
#pragma once

#include <trackflow/items.hpp>
#include <trackflow/params.hpp>

#include <optional>
#include <string>
#include <vector>

namespace trackflow::sim {

struct TimeWindow {
  double start = 0.0, end = 0.0;  // s; the window holds start <= t < end
  MeasMode mode = MeasMode::Unknown;
  // σ's that replace the noise model's inside this window (mode_schedule only).
  std::optional<double> sigma_range, sigma_azimuth, sigma_elevation, sigma_range_rate;
};

class TimeWindows {
 public:
  TimeWindows() = default;
  // Reads the Records parameter `name` (absent: no windows). Refuses end <= start and
  // overlapping windows, naming the entries. `with_mode`: records carry mode and σ overrides.
  TimeWindows(const Params& p, const std::string& name, bool with_mode);

  // The window containing t, or null. No allocation: a binary search over the sorted windows.
  const TimeWindow* find(double t) const;
  bool empty() const { return windows_.empty(); }

 private:
  std::vector<TimeWindow> windows_;  // sorted by start
};

}  // namespace trackflow::sim
