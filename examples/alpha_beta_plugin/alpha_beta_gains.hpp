// Purpose: α-β tracker algebra: gains from Kalata's tracking index and the steady-state covariance of one axis.
#pragma once

#include <cmath>

namespace alpha_beta {

struct Gains {
  double alpha = 0.5;
  double beta = 0.2;
};

// Kalata, P. R. (1984), "The tracking index: a generalized parameter for α-β and α-β-γ target
// trackers", IEEE Trans. Aerospace and Electronic Systems AES-20(2), 174-182.
// Tracking index Λ = σ_a T² / σ_w (σ_a: std of the piecewise-constant acceleration, σ_w: std
// of the position measurement). The steady-state Kalman gains of that (DWNA) model satisfy
//   Λ² = β² / (1 − α)   and   β = 2(2 − α) − 4 √(1 − α),
// i.e. with r = √(1 − α):  2r² − (4 + Λ) r + 2 = 0,  r = (4 + Λ − √(Λ² + 8Λ)) / 4,
//   α = 1 − r²,  β = 2 (1 − r)².
// The two roots of the quadratic multiply to 1, so r = 4 / (4 + Λ + √(Λ² + 8Λ)) gives the same
// root without the cancellation that the textbook form suffers at large Λ.
inline Gains gains_from_tracking_index(double lambda) {
  const double r = 4.0 / (4.0 + lambda + std::sqrt(lambda * lambda + 8.0 * lambda));
  return {1.0 - r * r, 2.0 * (1.0 - r) * (1.0 - r)};
}

// Steady-state covariance of one axis [position, velocity] after the update, and the steady
// innovation variance s, for measurement variance sigma2 and sampling interval T
// (Bar-Shalom, Li & Kirubarajan 2001, "Estimation with Applications to Tracking and
// Navigation", §6.5, the α-β filter for the discrete white-noise-acceleration model):
//   s   = σ² / (1 − α)                    (from α = p⁻₁₁ / s and s = p⁻₁₁ + σ²)
//   p11 = α σ²,   p12 = (β/T) σ²,   p22 = β (2α − β) / (2 (1 − α)) · σ² / T².
// p11 and p12 follow from P = (I − K H) P⁻ alone; p22 also uses the model's Q, so it is exact
// for gains on Kalata's curve above (the test checks all four against the Riccati recursion)
// and the textbook approximation for other (α, β).
struct AxisCovariance {
  double p11 = 0.0, p12 = 0.0, p22 = 0.0;
  double s = 0.0;
};

inline AxisCovariance steady_state_covariance(const Gains& g, double T, double sigma2) {
  AxisCovariance c;
  c.s = sigma2 / (1.0 - g.alpha);
  c.p11 = g.alpha * sigma2;
  c.p12 = g.beta / T * sigma2;
  c.p22 = g.beta * (2.0 * g.alpha - g.beta) / (2.0 * (1.0 - g.alpha)) * sigma2 / (T * T);
  return c;
}

// p11 p22 − p12² ≥ 0  ⇔  2α² + αβ − 2β ≥ 0  ⇔  β ≤ 2α² / (2 − α). At the bound the position
// and velocity errors are perfectly correlated and the covariance is singular; above it the
// formula above is not a covariance at all.
inline double max_beta_for_covariance(double alpha) { return 2.0 * alpha * alpha / (2.0 - alpha); }

// Squared correlation of position and velocity error, p12² / (p11 p22) = 2β(1 − α) / (α(2α − β)),
// independent of σ and T; 1 at the bound above. On Kalata's curve it equals r / (1 + r) ≤ 1/2.
inline double error_correlation_squared(const Gains& g) {
  return 2.0 * g.beta * (1.0 - g.alpha) / (g.alpha * (2.0 * g.alpha - g.beta));
}

// Gains whose steady-state covariance is positive definite with some room to spare: the
// correlation test also rejects β a rounding error below the bound, where the covariance
// would be singular in floating point.
inline bool has_steady_state_covariance(const Gains& g) {
  return g.beta < 2.0 * g.alpha && error_correlation_squared(g) < 1.0 - 1e-6;
}

}  // namespace alpha_beta
