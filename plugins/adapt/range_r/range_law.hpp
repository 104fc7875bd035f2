// Purpose: paper 003's range-dependent angle noise variance R(r) = thermal part growing with range + glint part shrinking with it (Fig 29).
#pragma once

#include <algorithm>
#include <cmath>

namespace trackflow::adapt {

// R(r) = alpha (r / r0)^a + beta (r0 / r)^b, rad^2. With a = 4 the thermal part follows the radar
// equation (SNR ~ r^-4, angle variance ~ 1/SNR, eq 4.1); with b = 2 the glint part follows eq 3-11
// (angle = linear glint / r). alpha and beta are the two parts' variances at the reference range r0.
struct RangeLaw {
  double alpha = 0.0, beta = 0.0;  // rad^2
  double reference_range = 1.0;    // m
  double thermal_exponent = 4.0, glint_exponent = 2.0;
  double min_range = 1.0;          // m: closer ranges are evaluated here (the glint part diverges at 0)

  double thermal(double r) const { return alpha * power(clamp(r) / reference_range, thermal_exponent); }
  double glint(double r) const { return beta * power(reference_range / clamp(r), glint_exponent); }
  double variance(double r) const { return thermal(r) + glint(r); }
  // Where R is smallest: dR/dr = 0 at r0 (b beta / (a alpha))^(1 / (a + b)).
  double minimum_range() const {
    return reference_range * std::pow(glint_exponent * beta / (thermal_exponent * alpha), 1.0 / (thermal_exponent + glint_exponent));
  }

 private:
  double clamp(double r) const { return std::max(r, min_range); }
  // x^e; whole exponents (the usual 4 and 2) by multiplication, which is exact and cheap per update.
  static double power(double x, double e) {
    if (e == 2.0) return x * x;
    if (e == 4.0) return (x * x) * (x * x);
    if (e == 0.0) return 1.0;
    return std::pow(x, e);
  }
};

}  // namespace trackflow::adapt
