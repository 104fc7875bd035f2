// Purpose: kinematic motion models (constant velocity, constant acceleration, Singer) with fixed-size F and Q.
#pragma once

#include <trackflow/items.hpp>

#include <Eigen/Core>

#include <array>
#include <cmath>

namespace trackflow {

// State layout shared by all Cartesian kinematic models: per-axis blocks
// [x, vx(, ax), y, vy(, ay), z, vz(, az)], ENU axes. `Order` is the number of states per
// axis: 2 = constant velocity, 3 = constant acceleration.
template <int Order>
struct KinematicModel {
  static_assert(Order == 2 || Order == 3);
  static constexpr int kOrder = Order;
  static constexpr int kDim = 3 * Order;
  using State = Eigen::Matrix<double, kDim, 1>;
  using Matrix = Eigen::Matrix<double, kDim, kDim>;
  using AxisMatrix = Eigen::Matrix<double, Order, Order>;

  // Names and units of the state components (adapters, sinks).
  static StateLayout state_layout() {
    static constexpr StateComponent kCv[] = {{"x", "m"}, {"vx", "m/s"}, {"y", "m"},
                                             {"vy", "m/s"}, {"z", "m"}, {"vz", "m/s"}};
    static constexpr StateComponent kCa[] = {{"x", "m"},  {"vx", "m/s"}, {"ax", "m/s2"}, {"y", "m"}, {"vy", "m/s"},
                                             {"ay", "m/s2"}, {"z", "m"}, {"vz", "m/s"}, {"az", "m/s2"}};
    if constexpr (Order == 2)
      return {kCv, kDim};
    else
      return {kCa, kDim};
  }

  static constexpr int position_index(int axis) { return axis * Order; }
  static constexpr int velocity_index(int axis) { return axis * Order + 1; }
  static Eigen::Vector3d position(const State& x) {
    return {x(position_index(0)), x(position_index(1)), x(position_index(2))};
  }
  static Eigen::Vector3d velocity(const State& x) {
    return {x(velocity_index(0)), x(velocity_index(1)), x(velocity_index(2))};
  }

  // Per-axis transition: exact for the polynomial model.
  static AxisMatrix axis_transition(double T) {
    AxisMatrix F = AxisMatrix::Identity();
    F(0, 1) = T;
    if constexpr (Order == 3) {
      F(0, 2) = 0.5 * T * T;
      F(1, 2) = T;
    }
    return F;
  }

  // Continuous white noise on the highest derivative with spectral density q, integrated
  // over T. Order 2 (CWNA, Bar-Shalom et al. 2001 eq 6.2.2-12): q [[T^3/3, T^2/2], [T^2/2, T]],
  // q in m^2/s^3. Order 3 (Wiener-process acceleration, paper 000 eq 3.19):
  // q [[T^5/20, T^4/8, T^3/6], [T^4/8, T^3/3, T^2/2], [T^3/6, T^2/2, T]], q in m^2/s^5.
  static AxisMatrix axis_noise_continuous(double T, double q) {
    AxisMatrix Q;
    const double T2 = T * T, T3 = T2 * T;
    if constexpr (Order == 2) {
      Q << T3 / 3, T2 / 2, T2 / 2, T;
    } else {
      const double T4 = T3 * T, T5 = T4 * T;
      Q << T5 / 20, T4 / 8, T3 / 6, T4 / 8, T3 / 3, T2 / 2, T3 / 6, T2 / 2, T;
    }
    return q * Q;
  }

  // Discrete white noise on the highest derivative, piecewise constant over each interval
  // with variance sigma^2 (DWNA for Order 2, Bar-Shalom eq 6.3.2-4: sigma_a^2 G G',
  // G = [T^2/2, T]; DWPA for Order 3, G = [T^2/2, T, 1]).
  static AxisMatrix axis_noise_discrete(double T, double sigma) {
    Eigen::Matrix<double, Order, 1> G;
    if constexpr (Order == 2) {
      G << T * T / 2, T;
    } else {
      G << T * T / 2, T, 1.0;
    }
    return sigma * sigma * G * G.transpose();
  }

  static void transition(double T, Matrix& F) {
    F.setZero();
    const AxisMatrix A = axis_transition(T);
    for (int a = 0; a < 3; ++a) F.template block<Order, Order>(a * Order, a * Order) = A;
  }
  // F x without forming F.
  static void propagate(double T, State& x) {
    for (int a = 0; a < 3; ++a) {
      const int i = a * Order;
      if constexpr (Order == 3) {
        x(i) += T * x(i + 1) + 0.5 * T * T * x(i + 2);
        x(i + 1) += T * x(i + 2);
      } else {
        x(i) += T * x(i + 1);
      }
    }
  }
  static void block_diagonal(const AxisMatrix& A, Matrix& Q) {
    Q.setZero();
    for (int a = 0; a < 3; ++a) Q.template block<Order, Order>(a * Order, a * Order) = A;
  }
  // P <- F P F' using the structure of F (identity plus T-multiples of the next derivative in
  // each axis block): row operations for F P, then the same on columns for (F P) F'. About
  // 10x fewer multiplications than two dense products; the result equals F P F' up to rounding.
  static void propagate_covariance(double T, Matrix& P) {
    const double h = 0.5 * T * T;
    for (int a = 0; a < 3; ++a) {
      const int i = a * Order;
      if constexpr (Order == 3) {
        P.row(i) += T * P.row(i + 1) + h * P.row(i + 2);
        P.row(i + 1) += T * P.row(i + 2);
      } else {
        P.row(i) += T * P.row(i + 1);
      }
    }
    for (int a = 0; a < 3; ++a) {
      const int i = a * Order;
      if constexpr (Order == 3) {
        P.col(i) += T * P.col(i + 1) + h * P.col(i + 2);
        P.col(i + 1) += T * P.col(i + 2);
      } else {
        P.col(i) += T * P.col(i + 1);
      }
    }
  }
};

using ConstantVelocity = KinematicModel<2>;
using ConstantAcceleration = KinematicModel<3>;

namespace detail {
constexpr double factorial(int n) {
  double f = 1.0;
  for (int i = 2; i <= n; ++i) f *= i;
  return f;
}
inline constexpr int kSingerSeriesTerms = 18;
// Singer's e^{As} b = [s^2 phi_2(alpha s), s phi_1(alpha s), phi_0(alpha s)]' = s^m_i sum_k (-alpha s)^k/(k+m_i)!
// with m = (2, 1, 0); integrating the products over [0, T] gives
// Q_ij = T^(m_i+m_j+1) sum_n (-x)^n c_ij[n],  c_ij[n] = sum_{k<=n} 1/((k+m_i)! (n-k+m_j)!) / (n+m_i+m_j+1),
// stored for (i, j) = 00, 01, 02, 11, 12, 22.
constexpr std::array<std::array<double, kSingerSeriesTerms>, 6> singer_series_coefficients() {
  std::array<std::array<double, kSingerSeriesTerms>, 6> c{};
  constexpr int m[3] = {2, 1, 0};
  int ij = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j, ++ij)
      for (int n = 0; n < kSingerSeriesTerms; ++n) {
        double inner = 0.0;
        for (int k = 0; k <= n; ++k) inner += 1.0 / (factorial(k + m[i]) * factorial(n - k + m[j]));
        c[ij][n] = inner / (n + m[i] + m[j] + 1);
      }
  return c;
}
inline constexpr auto kSingerSeries = singer_series_coefficients();
}  // namespace detail

// Singer (1970) model: per axis [p, v, a] with the layout and index helpers of
// ConstantAcceleration, but the acceleration is a first-order Markov process
//   da/dt = -alpha a + w,  E[w(t) w(s)] = 2 alpha sigma^2 delta(t - s),
// i.e. stationary acceleration std sigma (sigma_m, m/s2) and correlation time 1/alpha (s).
// Source: R. A. Singer, "Estimating optimal tracking filter performance for manned maneuvering
// targets", IEEE Trans. AES-6(4), 1970 (transition and the q11..q33 closed form of Q); restated
// in X. R. Li & V. P. Jilkov, "Survey of maneuvering target tracking, Part I", IEEE Trans. AES
// 39(4), 2003, §IV.A. Limits: alpha -> 0 with q = 2 alpha sigma^2 fixed gives the
// Wiener-process-acceleration CA model (ConstantAcceleration::axis_noise_continuous(T, q));
// alpha -> inf with q = 2 sigma^2 / alpha fixed makes the acceleration white, and the (p, v)
// block tends to the CV model with intensity q.
struct SingerModel {
  using AxisMatrix = Eigen::Matrix3d;
  double alpha = 1.0;  // 1/s
  double sigma = 1.0;  // m/s2

  // Exact e^{A T}, A = [[0,1,0],[0,0,1],[0,0,-alpha]]:
  // [[1, T, (aT - 1 + e^-aT)/a^2], [0, 1, (1 - e^-aT)/a], [0, 0, e^-aT]].
  AxisMatrix axis_transition(double T) const { return axis_transition(alpha, T); }
  // Exact discrete noise 2 alpha sigma^2 * integral_0^T e^{As} b b' e^{A's} ds, b = [0, 0, 1]'.
  AxisMatrix axis_noise(double T) const { return (2.0 * alpha * sigma * sigma) * noise_per_psd(alpha, T); }

  static AxisMatrix axis_transition(double alpha, double T) {
    const double x = alpha * T;
    AxisMatrix F = AxisMatrix::Identity();
    F(0, 1) = T;
    F(0, 2) = T * T * phi(2, x);
    F(1, 2) = T * phi(1, x);
    F(2, 2) = std::exp(-x);
    return F;
  }

  // The integral per unit spectral density of w (Singer's q_ij; multiply by 2 alpha sigma^2).
  // The closed form cancels catastrophically for small x = alpha T: q11's bracket is O(x^5) built
  // from O(1) terms, so its relative error is ~1e-16/x^5 (1e-6 at x = 0.01, 10 % at x = 1e-3).
  // Below kSeriesLimit the Taylor series in x is used instead (entire; kSeriesTerms terms reach
  // double precision for x < 0.5, where the closed form loses < 1e-13).
  static AxisMatrix noise_per_psd(double alpha, double T) {
    const double x = alpha * T;
    AxisMatrix Q;
    if (x < kSeriesLimit) {
      constexpr int m[3] = {2, 1, 0};
      int ij = 0;
      for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j, ++ij) {
          double sum = 0.0;  // Horner in -x
          for (int n = kSeriesTerms - 1; n >= 0; --n) sum = sum * -x + detail::kSingerSeries[ij][n];
          Q(i, j) = Q(j, i) = std::pow(T, m[i] + m[j] + 1) * sum;
        }
      return Q;
    }
    const double e = std::exp(-x), e2 = e * e, x2 = x * x, x3 = x2 * x;
    const double a2 = alpha * alpha, a3 = a2 * alpha, a4 = a3 * alpha, a5 = a4 * alpha;
    Q(0, 0) = (1 - e2 + 2 * x + 2 * x3 / 3 - 2 * x2 - 4 * x * e) / (2 * a5);
    Q(0, 1) = Q(1, 0) = (e2 + 1 - 2 * e + 2 * x * e - 2 * x + x2) / (2 * a4);
    Q(0, 2) = Q(2, 0) = (1 - e2 - 2 * x * e) / (2 * a3);
    Q(1, 1) = (4 * e - 3 - e2 + 2 * x) / (2 * a3);
    Q(1, 2) = Q(2, 1) = (e2 + 1 - 2 * e) / (2 * a2);
    Q(2, 2) = (1 - e2) / (2 * alpha);
    return Q;
  }

  static constexpr double kSeriesLimit = 0.5;
  static constexpr int kSeriesTerms = detail::kSingerSeriesTerms;

  // phi_m(x) = sum_k (-x)^k / (k+m)!, m = 0, 1, 2: e^-x, (1 - e^-x)/x, (x - 1 + e^-x)/x^2.
  static double phi(int m, double x) {
    if (m == 0) return std::exp(-x);
    if (x >= kSeriesLimit) {
      const double em1 = std::expm1(-x);
      return m == 1 ? -em1 / x : (x + em1) / (x * x);
    }
    double sum = 0.0;
    for (int k = kSeriesTerms - 1; k >= 0; --k) sum = sum * -x + 1.0 / detail::factorial(k + m);
    return sum;
  }
};

}  // namespace trackflow
