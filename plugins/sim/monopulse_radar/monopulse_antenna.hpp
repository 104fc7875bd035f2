// Purpose: the four-horn amplitude-comparison monopulse antenna of paper 003 (eq 2-1..2-12): horn patterns, sum and difference channels, error signal d/S, its slope and the non-linear angle it reports.
#pragma once

namespace trackflow::sim {

// Angles here are in beamwidths (an angle divided by the 3 dB beamwidth), as in Sherman & Barton's
// AN/FPS-16 model the paper takes its constants from.
struct MonopulseGeometry {
  double beamwidth_constant = 1.19;  // k_theta: V(0.5) = 1/sqrt(2), the 3 dB point at half a beamwidth
  double squint = 0.358;             // theta_sq, beamwidths
};

// One horn's voltage pattern at a radial offset x (beamwidths) from its own axis, eq 2-1:
// V(x) = cos(pi k x) / (1 - (2 k x)^2), V(0) = 1. The removable singularity at 2kx = 1 (V = pi/4)
// is evaluated by its series, so V is smooth everywhere.
double horn_pattern(double x, double k);
// dV/dx, for the slope at boresight and its test.
double horn_pattern_derivative(double x, double k);

struct MonopulseChannels {
  double sum = 0.0;        // S = (A + B + C + D) / 2                 (eq 2-10)
  double azimuth = 0.0;    // d_az = ((C + D) - (A + B)) / 2          (eq 2-11)
  double elevation = 0.0;  // d_el = ((A + C) - (B + D)) / 2          (eq 2-12)
};

// The four horns A..D sit at (theta, phi) = (+sq, -sq), (+sq, +sq), (-sq, -sq), (-sq, +sq): eq 2-6..2-9
// evaluate each at the radial distance sqrt((theta -+ sq)^2 + (phi +- sq)^2) from the target's offset
// (theta azimuth, phi elevation, beamwidths from boresight).
class FourHornMonopulse {
 public:
  explicit FourHornMonopulse(MonopulseGeometry g = {});

  MonopulseChannels channels(double theta, double phi) const;
  // Error signals d_az/S and d_el/S (dimensionless). With the paper's horn labels they fall as the
  // offset grows (a target toward +theta is nearer A and B), so the slope below is negative.
  void error_signals(double theta, double phi, double& e_az, double& e_el) const;
  // d(d_az/S)/d theta at boresight, per beamwidth: V'(r0) / (sqrt(2) V(r0)), r0 = sqrt(2) sq (derived in
  // docs/filters.md); the same for elevation by symmetry. About -1.049 for the AN/FPS-16 constants.
  double slope() const { return slope_; }
  // The offset the receiver reports: the error signals divided by the boresight slope, the linear
  // inversion every monopulse processor applies. Equal to the true offset at boresight; off boresight
  // the pattern's curvature makes it differ (the non-linear error).
  void reported_offset(double theta, double phi, double& u_az, double& u_el) const;

  const MonopulseGeometry& geometry() const { return g_; }

 private:
  MonopulseGeometry g_;
  double slope_ = 0.0;
};

}  // namespace trackflow::sim
