// Purpose: the per-estimate annotation channels sink.metrics follows over time (today the adapters' quality grades) and their per-step sums.
#pragma once

#include <trackflow/items.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace trackflow::metrics {

inline constexpr int kMaxAnnotations = 8;

// The only place that knows where an estimate's annotations live. Today they are the grades
// a quality adapter stamps in Estimate::quality[3]; when adapters publish named annotations,
// the constructor takes their names and read() looks them up, and nothing else changes.
class AnnotationChannels {
 public:
  AnnotationChannels() : names_{"quality_range", "quality_azimuth", "quality_elevation"} {}

  int count() const { return static_cast<int>(names_.size()); }
  const std::string& name(int c) const { return names_[static_cast<size_t>(c)]; }
  std::string unit(int) const { return {}; }  // grades are pure numbers (0 best, 1 normal, 2 worst)

  // values[0..count()): the estimate's value of each channel, NaN where it carries none.
  // Single precision: kept for every estimate of a run in flight, and grades or adapted
  // sigmas need no more.
  void read(const Estimate& e, float* values) const {
    for (int c = 0; c < count() && c < kMaxAnnotations; ++c)
      values[c] = e.quality[c] >= 0 ? static_cast<float>(e.quality[c]) : std::numeric_limits<float>::quiet_NaN();
  }

 private:
  std::vector<std::string> names_;
};

// Per-step sums of each channel over the runs that carry it (for the mean per step).
struct AnnotationSums {
  double sum[kMaxAnnotations] = {};
  std::uint32_t count[kMaxAnnotations] = {};

  void add(const float* values, int n) {
    for (int c = 0; c < n && c < kMaxAnnotations; ++c)
      if (std::isfinite(values[c])) {
        sum[c] += static_cast<double>(values[c]);
        ++count[c];
      }
  }
  double mean(int c) const {
    return count[c] ? sum[c] / static_cast<double>(count[c]) : std::numeric_limits<double>::quiet_NaN();
  }
};

}  // namespace trackflow::metrics
