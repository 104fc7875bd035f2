// Purpose: the Swerling fluctuation's time stepping (per look or per scan) and its CDF.
#include "rcs_fluctuation.hpp"

#include <cmath>
#include <limits>

namespace trackflow::sim {

double rcs_cdf(double x, int components) {
  if (!(x > 0.0)) return 0.0;
  if (components == 2) return -std::expm1(-x);  // 1 - e^{-x}
  // Gamma(2, 1/2): 1 - (1 + 2x) e^{-2x}
  return 1.0 - (1.0 + 2.0 * x) * std::exp(-2.0 * x);
}

void RcsFluctuation::start(double t, Rng& rng) {
  for (int i = 0; i < components(); ++i) g_[i].start(rng);
  last_time_ = t;
  scan_start_ = t;
  scan_ = 0;
  update_factor();
}

void RcsFluctuation::advance(double t, Rng& rng) {
  double evaluate_at = t;
  if (holds_per_scan()) {
    const long long scan = static_cast<long long>(std::floor((t - scan_start_) / scan_period_));
    if (scan <= scan_) return;  // same scan: the value holds
    scan_ = scan;
    evaluate_at = scan_start_ + static_cast<double>(scan) * scan_period_;
  }
  const double dt = evaluate_at - last_time_;
  if (dt != last_dt_) {  // fixed-rate looks: the exponential once
    rho_ = lorentzian_correlation(bandwidth_, dt);
    last_dt_ = dt;
  }
  for (int i = 0; i < components(); ++i) g_[i].advance(rho_, rng);
  last_time_ = evaluate_at;
  update_factor();
}

void RcsFluctuation::update_factor() {
  if (case_ == SwerlingCase::Constant) {
    x_ = 1.0;
    return;
  }
  const int n = components();
  double s = 0.0;
  for (int i = 0; i < n; ++i) s += g_[i].value() * g_[i].value();
  x_ = s / n;
}

double RcsFluctuation::uniform() const {
  if (case_ == SwerlingCase::Constant) return std::numeric_limits<double>::quiet_NaN();
  return rcs_cdf(x_, components());
}

}  // namespace trackflow::sim
