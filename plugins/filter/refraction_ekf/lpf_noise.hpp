// Purpose: paper 004 §2.2 measurement-noise estimate: the residual of each channel after a first-order low-pass filter, its running variance, corrected for the share of white noise the residual keeps.
#pragma once

#include <cmath>

namespace trackflow::refraction_ekf {

// One channel. y_k = y_{k-1} + alpha (z_k - y_{k-1}), alpha = 1 - exp(-w_c T): the low-pass
// (cut-off w_c, paper: 100 rad/s). e_k = z_k - y_k is taken as noise (paper 004 §2.2). Its mean
// and variance are followed with exponential forgetting (time constant `window`), the mean
// removing the filter's lag on a ramp (e = v T (1 - alpha) / alpha for a slope v).
// The residual of white noise of variance sigma^2 is e_k = (1 - alpha)(z_k - y_{k-1}) with
// var(y) = alpha sigma^2 / (2 - alpha), so var(e) = kappa sigma^2, kappa = 2 (1 - alpha)^2 / (2 - alpha):
// the paper takes var(e) itself (kappa = 1), which holds only for T >> 1/w_c; with `correct`
// the estimate is var(e) / kappa. (At 40 Hz and 100 rad/s kappa = 0.0124: the raw residual
// variance is 80 times too small.) Angles are unwrapped against the filtered value.
class LowPassNoise {
 public:
  void reset() {
    started_ = false;
    samples_ = 0;
    mean_ = var_ = 0.0;
  }
  void add(double z, double T, double cutoff, double window, bool correct, bool angle) {
    if (!started_ || !(T > 0.0)) {
      y_ = z;
      started_ = true;
      return;
    }
    if (angle) z = y_ + std::remainder(z - y_, 2.0 * 3.14159265358979323846);
    const double alpha = 1.0 - std::exp(-cutoff * T);
    y_ += alpha * (z - y_);
    const double e = z - y_;
    const double beta = 1.0 - std::exp(-T / window);
    // Exponentially weighted mean and variance (West 1979), started from the first residual.
    if (samples_ == 0) {
      mean_ = e;
      var_ = 0.0;
    } else {
      const double d = e - mean_;
      mean_ += beta * d;
      var_ = (1.0 - beta) * (var_ + beta * d * d);
    }
    ++samples_;
    kappa_ = correct ? 2.0 * (1.0 - alpha) * (1.0 - alpha) / (2.0 - alpha) : 1.0;
  }
  long samples() const { return samples_; }
  double variance() const { return kappa_ > 0.0 ? var_ / kappa_ : var_; }

 private:
  bool started_ = false;
  long samples_ = 0;
  double y_ = 0.0, mean_ = 0.0, var_ = 0.0, kappa_ = 1.0;
};

}  // namespace trackflow::refraction_ekf
