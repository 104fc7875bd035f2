// Purpose: kinematic motion models (constant velocity, constant acceleration) with fixed-size F and Q.
#pragma once

#include <Eigen/Core>

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
};

using ConstantVelocity = KinematicModel<2>;
using ConstantAcceleration = KinematicModel<3>;

}  // namespace trackflow
