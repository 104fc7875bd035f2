// Purpose: an interpolating C² cubic spline of one variable with natural or clamped ends, and its first two derivatives.
#pragma once

#include <vector>

namespace trackflow::sim {

// End condition of a cubic spline: natural (second derivative 0) or clamped (first derivative given).
struct SplineEnd {
  bool clamped = false;
  double slope = 0.0;  // clamped only

  static SplineEnd natural() { return {}; }
  static SplineEnd clamped_to(double s) { return {true, s}; }
};

struct SplinePoint {
  double value, first, second;  // y, dy/dx, d²y/dx²
};

// Passes through every (x_i, y_i); value, first and second derivatives are continuous at the
// knots (third derivative piecewise constant). Outside [x_0, x_n] the end pieces extrapolate.
class CubicSpline {
 public:
  CubicSpline() = default;
  // x strictly increasing, at least two points; throws std::invalid_argument otherwise.
  CubicSpline(std::vector<double> x, std::vector<double> y, SplineEnd start, SplineEnd end);

  SplinePoint at(double x) const;  // no allocation
  const std::vector<double>& knots() const { return x_; }

 private:
  std::vector<double> x_, y_, m_;  // m_: second derivative at each knot
};

}  // namespace trackflow::sim
