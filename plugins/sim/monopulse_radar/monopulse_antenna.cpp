// Purpose: evaluation of the four-horn monopulse model (eq 2-1..2-12) and its boresight slope.
#include "monopulse_antenna.hpp"

#include <cmath>
#include <numbers>

namespace trackflow::sim {
namespace {

constexpr double kPi = std::numbers::pi;
// Below this distance of y = 2kx from 1 the quotient is replaced by its series (error ~ e^4).
constexpr double kSeriesBand = 1e-4;

}  // namespace

double horn_pattern(double x, double k) {
  const double y = std::abs(2.0 * k * x);
  const double e = 1.0 - y;
  if (std::abs(e) < kSeriesBand) {
    // cos(pi y / 2) = sin(pi e / 2), 1 - y^2 = e (2 - e): V = (pi/2)(1 - (pi e)^2 / 24) / (2 - e) + O(e^4).
    return 0.5 * kPi * (1.0 - kPi * kPi * e * e / 24.0) / (2.0 - e);
  }
  return std::cos(0.5 * kPi * y) / (1.0 - y * y);
}

double horn_pattern_derivative(double x, double k) {
  // V = c(y) / q(y), y = 2kx, c = cos(pi y/2), q = 1 - y^2: dV/dy = (c' q - c q') / q^2.
  const double y = 2.0 * k * x;
  const double q = 1.0 - y * y;
  if (std::abs(std::abs(y) - 1.0) < 1e-3) {
    // Central difference across the removable singularity (the pattern is smooth there).
    const double h = 1e-5;
    return (horn_pattern(x + h, k) - horn_pattern(x - h, k)) / (2.0 * h);
  }
  const double c = std::cos(0.5 * kPi * y), dc = -0.5 * kPi * std::sin(0.5 * kPi * y);
  const double dq = -2.0 * y;
  return 2.0 * k * (dc * q - c * dq) / (q * q);
}

FourHornMonopulse::FourHornMonopulse(MonopulseGeometry g) : g_(g) {
  const double r0 = std::sqrt(2.0) * g_.squint;
  slope_ = horn_pattern_derivative(r0, g_.beamwidth_constant) / (std::sqrt(2.0) * horn_pattern(r0, g_.beamwidth_constant));
}

MonopulseChannels FourHornMonopulse::channels(double theta, double phi) const {
  const double sq = g_.squint, k = g_.beamwidth_constant;
  const double tm = theta - sq, tp = theta + sq, pm = phi - sq, pp = phi + sq;
  const double A = horn_pattern(std::sqrt(tm * tm + pp * pp), k);  // eq 2-6
  const double B = horn_pattern(std::sqrt(tm * tm + pm * pm), k);  // eq 2-7
  const double C = horn_pattern(std::sqrt(tp * tp + pp * pp), k);  // eq 2-8
  const double D = horn_pattern(std::sqrt(tp * tp + pm * pm), k);  // eq 2-9
  return {0.5 * (A + B + C + D), 0.5 * ((C + D) - (A + B)), 0.5 * ((A + C) - (B + D))};
}

void FourHornMonopulse::error_signals(double theta, double phi, double& e_az, double& e_el) const {
  const MonopulseChannels c = channels(theta, phi);
  e_az = c.azimuth / c.sum;
  e_el = c.elevation / c.sum;
}

void FourHornMonopulse::reported_offset(double theta, double phi, double& u_az, double& u_el) const {
  double e_az = 0.0, e_el = 0.0;
  error_signals(theta, phi, e_az, e_el);
  u_az = e_az / slope_;
  u_el = e_el / slope_;
}

}  // namespace trackflow::sim
