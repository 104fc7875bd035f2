// Purpose: the tridiagonal solve for a cubic spline's knot curvatures and the piecewise-cubic evaluation.
#include "cubic_spline.hpp"

#include <algorithm>
#include <stdexcept>

namespace trackflow::sim {

CubicSpline::CubicSpline(std::vector<double> x, std::vector<double> y, SplineEnd start, SplineEnd end)
    : x_(std::move(x)), y_(std::move(y)) {
  const size_t n = x_.size();
  if (n < 2 || y_.size() != n) throw std::invalid_argument("a cubic spline needs at least two (x, y) pairs");
  for (size_t i = 1; i < n; ++i)
    if (!(x_[i] > x_[i - 1])) throw std::invalid_argument("cubic spline knots must be strictly increasing");
  // Continuity of the first derivative at each interior knot, in the knot curvatures m:
  // h_{i-1} m_{i-1} + 2 (h_{i-1} + h_i) m_i + h_i m_{i+1} = 6 (s_i - s_{i-1}), s_i the secant slopes,
  // plus one end condition per side. Diagonally dominant, so Thomas elimination needs no pivoting.
  std::vector<double> lower(n, 0.0), diag(n, 1.0), upper(n, 0.0), rhs(n, 0.0);
  auto h = [&](size_t i) { return x_[i + 1] - x_[i]; };
  auto secant = [&](size_t i) { return (y_[i + 1] - y_[i]) / h(i); };
  if (start.clamped) {
    diag[0] = 2 * h(0);
    upper[0] = h(0);
    rhs[0] = 6 * (secant(0) - start.slope);
  }
  for (size_t i = 1; i + 1 < n; ++i) {
    lower[i] = h(i - 1);
    diag[i] = 2 * (h(i - 1) + h(i));
    upper[i] = h(i);
    rhs[i] = 6 * (secant(i) - secant(i - 1));
  }
  if (end.clamped) {
    lower[n - 1] = h(n - 2);
    diag[n - 1] = 2 * h(n - 2);
    rhs[n - 1] = 6 * (end.slope - secant(n - 2));
  }
  for (size_t i = 1; i < n; ++i) {
    const double w = lower[i] / diag[i - 1];
    diag[i] -= w * upper[i - 1];
    rhs[i] -= w * rhs[i - 1];
  }
  m_.assign(n, 0.0);
  m_[n - 1] = rhs[n - 1] / diag[n - 1];
  for (size_t i = n - 1; i-- > 0;) m_[i] = (rhs[i] - upper[i] * m_[i + 1]) / diag[i];
}

SplinePoint CubicSpline::at(double t) const {
  const auto above = std::upper_bound(x_.begin(), x_.end(), t);
  const size_t i = std::clamp<size_t>(static_cast<size_t>(above - x_.begin()), 1, x_.size() - 1) - 1;
  const double h = x_[i + 1] - x_[i];
  const double a = (x_[i + 1] - t) / h, b = (t - x_[i]) / h;
  const double mi = m_[i], mj = m_[i + 1];
  return {a * y_[i] + b * y_[i + 1] + ((a * a * a - a) * mi + (b * b * b - b) * mj) * h * h / 6,
          (y_[i + 1] - y_[i]) / h + ((3 * b * b - 1) * mj - (3 * a * a - 1) * mi) * h / 6, a * mi + b * mj};
}

}  // namespace trackflow::sim
