// Purpose: the slope limiter and the Hermite evaluation of the shape-preserving cubic.
#include "monotone_cubic.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace trackflow::sim {

MonotoneCubic::MonotoneCubic(std::vector<double> x, std::vector<double> y, SplineEnd start, SplineEnd end)
    : x_(std::move(x)), y_(std::move(y)) {
  const CubicSpline spline(x_, y_, start, end);  // validates the knots
  const size_t n = x_.size();
  d_.resize(n);
  for (size_t i = 0; i < n; ++i) d_[i] = spline.at(x_[i]).first;
  std::vector<double> secant(n - 1);
  for (size_t i = 0; i + 1 < n; ++i) secant[i] = (y_[i + 1] - y_[i]) / (x_[i + 1] - x_[i]);
  // Limits slope d to [0, 3 min |s|] in the common sign of the secants `s`; 0 when they disagree.
  auto limit = [](double d, double left, double right) {
    if (left * right <= 0.0) return 0.0;
    const double bound = 3.0 * std::min(std::abs(left), std::abs(right));
    if (left > 0.0) return std::clamp(d, 0.0, bound);
    return std::clamp(d, -bound, 0.0);
  };
  for (size_t i = 0; i < n; ++i) {
    const double left = i == 0 ? secant[0] : secant[i - 1];
    const double right = i + 1 == n ? secant[n - 2] : secant[i];
    const double limited = limit(d_[i], left, right);
    if (limited != d_[i]) {
      limited_.push_back(i);
      d_[i] = limited;
    }
  }
}

SplinePoint MonotoneCubic::at(double t) const {
  const auto above = std::upper_bound(x_.begin(), x_.end(), t);
  const size_t i = std::clamp<size_t>(static_cast<size_t>(above - x_.begin()), 1, x_.size() - 1) - 1;
  const double h = x_[i + 1] - x_[i];
  const double u = (t - x_[i]) / h;
  // Hermite basis in u on [0, 1] and its derivatives (d/dt = (1/h) d/du).
  const double u2 = u * u, u3 = u2 * u;
  const double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
  const double d00 = 6 * u2 - 6 * u, d10 = 3 * u2 - 4 * u + 1, d01 = -6 * u2 + 6 * u, d11 = 3 * u2 - 2 * u;
  const double s00 = 12 * u - 6, s10 = 6 * u - 4, s01 = -12 * u + 6, s11 = 6 * u - 2;
  const double y0 = y_[i], y1 = y_[i + 1], m0 = d_[i] * h, m1 = d_[i + 1] * h;
  return {h00 * y0 + h10 * m0 + h01 * y1 + h11 * m1, (d00 * y0 + d10 * m0 + d01 * y1 + d11 * m1) / h,
          (s00 * y0 + s10 * m0 + s01 * y1 + s11 * m1) / (h * h)};
}

}  // namespace trackflow::sim
