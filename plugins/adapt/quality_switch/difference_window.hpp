// Purpose: paper 000 eq 3.64 — the RMS of successive measurement differences over a sliding window of one channel.
#pragma once

#include <trackflow/geometry.hpp>

#include <cmath>
#include <vector>

namespace trackflow::adapt {

// RMSE_k = sqrt( Σ_{i=k-n+1..k} (z_i − z_{i-1})² / n ): the last n differences, so n + 1 samples.
// `wrap`: differences of an angle that lives on a circle (azimuth) are wrapped to (−π, π], so a
// track crossing the ±π seam does not look like a jump of 2π.
// `detrend`: the differences' mean over the window is removed first, sqrt(Σ (d_i − d̄)² / n), so
// a constant rate of change (the target's own motion) does not count as noise. Not in the
// paper; for white noise of variance σ², E[RMSE²] = 2σ² (first differences) and 2σ² (1 − 1/n²)
// (detrended), whatever the rate.
class DifferenceWindow {
 public:
  static constexpr int kMaxLength = 100000;

  explicit DifferenceWindow(int length = 10, bool wrap = false, bool detrend = false)
      : length_(length), wrap_(wrap), detrend_(detrend), differences_(static_cast<size_t>(length), 0.0) {}

  // Forgets the samples: the next sample starts a new window (no difference across the gap).
  void reset() {
    has_last_ = false;
    count_ = 0;
    next_ = 0;
  }

  void add(double z) {
    if (has_last_) {
      const double d = wrap_ ? wrap_angle(z - last_) : z - last_;
      differences_[static_cast<size_t>(next_)] = d;
      next_ = (next_ + 1) % length_;
      if (count_ < length_) ++count_;
    }
    last_ = z;
    has_last_ = true;
  }

  // True once the window holds `length` differences.
  bool full() const { return count_ == length_; }
  int differences() const { return count_; }
  int length() const { return length_; }

  // Over the differences held (all `length` of them once full). Summed afresh each time: a
  // burst of 10⁶σ leaving the window must not leave rounding residue in a running sum.
  double rms() const {
    if (count_ == 0) return 0.0;
    double mean = 0.0;
    if (detrend_) {
      for (int i = 0; i < count_; ++i) mean += differences_[static_cast<size_t>(i)];
      mean /= count_;
    }
    double sum = 0.0;
    for (int i = 0; i < count_; ++i) {
      const double d = differences_[static_cast<size_t>(i)] - mean;
      sum += d * d;
    }
    return std::sqrt(sum / count_);
  }

 private:
  int length_;
  bool wrap_, detrend_;
  std::vector<double> differences_;  // ring buffer, sized once
  int count_ = 0, next_ = 0;
  double last_ = 0.0;
  bool has_last_ = false;
};

// Paper 000 Table 1 graded against the reference mean M of the channel: BEST for
// RMSE ≤ normal_above·M, NORMAL up to worst_above·M, WORST beyond (defaults 1 and 2).
enum class Grade : int { Best = 0, Normal = 1, Worst = 2 };
inline constexpr int kGrades = 3;

inline Grade grade_of(double rms, double reference, double normal_above, double worst_above) {
  if (rms <= normal_above * reference) return Grade::Best;
  if (rms <= worst_above * reference) return Grade::Normal;
  return Grade::Worst;
}

inline const char* grade_name(Grade g) {
  switch (g) {
    case Grade::Best: return "best";
    case Grade::Normal: return "normal";
    case Grade::Worst: return "worst";
  }
  return "?";
}

}  // namespace trackflow::adapt
