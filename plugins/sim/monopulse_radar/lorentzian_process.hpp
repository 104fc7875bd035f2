// Purpose: exact samplers of processes with a Lorentzian spectrum S(f) ~ 1/(B^2 + f^2) (paper 003 eq 3-10, 3-15) at arbitrary sample times: the Gaussian AR(1) (Ornstein-Uhlenbeck) and the DAR(1) renewal process for any marginal.
#pragma once

#include <trackflow/rng.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace trackflow::sim {

// A spectrum proportional to 1/(B^2 + f^2) (B the half-power bandwidth, Hz) is the Fourier transform of
// the autocorrelation exp(-2 pi B |tau|): correlation time 1/(2 pi B). Between two samples dt apart
// the correlation coefficient is therefore
inline double lorentzian_correlation(double bandwidth, double dt) {
  return std::exp(-2.0 * std::numbers::pi * bandwidth * dt);
}

// Gaussian process with unit variance and the Lorentzian spectrum, sampled exactly (no discretisation
// error) at any spacing: g <- rho g + sqrt(1 - rho^2) w, w ~ N(0, 1), started from its stationary
// distribution. This is the AR(1) shaping filter of a first-order spectrum.
class GaussMarkov {
 public:
  void start(Rng& rng) { value_ = rng.normal(); }
  void advance(double rho, Rng& rng) { value_ = rho * value_ + std::sqrt(std::max(0.0, 1.0 - rho * rho)) * rng.normal(); }
  double value() const { return value_; }

 private:
  double value_ = 0.0;
};

// DAR(1) (Jacobs & Lewis 1978): keep the previous value with probability rho, otherwise draw a fresh one
// from the marginal. Its marginal is exactly the one drawn from, whatever that is, and its
// autocorrelation is exactly rho^n = exp(-2 pi B n dt): a Lorentzian spectrum for a non-Gaussian
// marginal, which a linear filter applied to non-Gaussian samples cannot give (it drives the marginal
// toward a Gaussian). Returns true when the value was renewed; one uniform is drawn per step.
inline bool dar1_renew(double rho, Rng& rng) { return rng.uniform() >= rho; }

}  // namespace trackflow::sim
