// Purpose: a shape-preserving piecewise-cubic Hermite interpolant (Hyman-filtered spline slopes, Fritsch-Carlson region).
#pragma once

#include "cubic_spline.hpp"

#include <cstddef>
#include <vector>

namespace trackflow::sim {

// Piecewise cubic Hermite through (x_i, y_i) with knot slopes d_i, monotone on every interval:
// where the data rise (fall) between two knots, the interpolant rises (falls) too, and it never
// leaves [min(y_i, y_i+1), max(y_i, y_i+1)] on that interval. The slopes start from a C² cubic
// spline's and are limited as Hyman (1983) does: d_i = 0 where the secants on either side differ
// in sign or one is zero (a local extremum of the data, or a flat step), otherwise d_i keeps the
// secants' sign and |d_i| <= 3 min(|s_i-1|, |s_i|) (the square inside Fritsch & Carlson's 1980
// monotonicity region). Where no slope needs limiting the result IS the spline (a cubic is fixed
// by its end values and slopes), so it stays C² there; next to a limited knot it is C¹ (the
// second derivative jumps). End slopes are limited to [0, 3 |s|] in the sign of their secant.
class MonotoneCubic {
 public:
  MonotoneCubic() = default;
  // x strictly increasing, at least two points (as CubicSpline); the spline's end conditions
  // give the starting slopes.
  MonotoneCubic(std::vector<double> x, std::vector<double> y, SplineEnd start, SplineEnd end);

  SplinePoint at(double x) const;  // no allocation; outside [x_0, x_n] the end pieces extrapolate
  const std::vector<double>& slopes() const { return d_; }
  // Knots whose spline slope was changed by the limiter (for tests and documentation).
  const std::vector<std::size_t>& limited_knots() const { return limited_; }

 private:
  std::vector<double> x_, y_, d_;
  std::vector<std::size_t> limited_;
};

}  // namespace trackflow::sim
