// Purpose: the per-estimate annotation channels sink.metrics follows over time (what the filter's adapters publish: grades, adapted sigmas) and their per-step sums.
#pragma once

#include <trackflow/items.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace trackflow::metrics {

inline constexpr int kMaxAnnotations = trackflow::kMaxAnnotations;

// The only place that knows where an estimate's annotations live: Estimate::annotations, in the
// order of the names the filter's input announces (InputInfo::annotations, "<adapter>.<name>").
class AnnotationChannels {
 public:
  AnnotationChannels() = default;
  explicit AnnotationChannels(std::vector<std::string> names) : names_(std::move(names)) {
    if (names_.size() > static_cast<size_t>(kMaxAnnotations)) names_.resize(static_cast<size_t>(kMaxAnnotations));
  }

  int count() const { return static_cast<int>(names_.size()); }
  const std::string& name(int c) const { return names_[static_cast<size_t>(c)]; }
  std::string unit(int) const { return {}; }  // as the adapter publishes it (see its describe)

  // values[0..count()): the estimate's value of each channel, NaN where it carries none.
  // Single precision: kept for every estimate of a run in flight, and grades or adapted
  // sigmas need no more.
  void read(const Estimate& e, float* values) const {
    for (int c = 0; c < count() && c < kMaxAnnotations; ++c)
      values[c] = c < e.annotation_count ? static_cast<float>(e.annotations[c]) : std::numeric_limits<float>::quiet_NaN();
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
