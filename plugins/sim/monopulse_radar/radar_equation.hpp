// Purpose: the radar equation of paper 003 eq 4.1 (SNR of a skin echo) and the monopulse thermal angle noise it implies (the SNR law of paper 001 eq 6-8).
#pragma once

#include <cmath>
#include <numbers>

namespace trackflow::sim {

inline constexpr double kBoltzmann = 1.38e-23;  // J/K, as printed in paper 003

// Everything in linear SI units (W, K, Hz, m, m^2); gains and losses as power ratios.
struct RadarEquation {
  double peak_power = 500e3;          // P_t, W
  double antenna_gain = 12589.254;    // G (41 dB), used twice (transmit and receive)
  double wavelength = 0.0545;         // lambda, m
  double noise_temperature = 290.0;   // T_e, K
  double bandwidth = 8e6;             // B, Hz
  double noise_figure = 15.848932;    // F (12 dB)
  double losses = 1.0;                // L >= 1, divides the SNR (not in eq 4.1: 1 = none)
  double integration_gain = 1.0;      // pulses integrated per angle measurement (eq 4.1 is one pulse)

  // (SNR)_o = P_t G^2 lambda^2 sigma / ((4 pi)^3 k T_e B F R^4), times the integration gain, over losses.
  double snr(double rcs, double range) const {
    const double four_pi = 4.0 * std::numbers::pi;
    const double r2 = range * range;
    return peak_power * antenna_gain * antenna_gain * wavelength * wavelength * rcs * integration_gain /
           (four_pi * four_pi * four_pi * kBoltzmann * noise_temperature * bandwidth * noise_figure * losses * r2 * r2);
  }
};

// Thermal noise on a monopulse error signal d/S at signal-to-noise ratio `snr` (linear): zero-mean
// Gaussian with standard deviation 1/sqrt(2 SNR). Divided by the slope k_m (per beamwidth) it is an
// angle noise sigma = theta_B / (|k_m| sqrt(2 SNR)), paper 001 eq 6-8's law.
inline double error_signal_sigma(double snr) { return 1.0 / std::sqrt(2.0 * snr); }

}  // namespace trackflow::sim
