// Purpose: the state of a Cartesian radar estimator without its update (filter.ekf, filter.ukf, and each mode of filter.imm): settings, initialisation from converted points, the exact linear prediction, Estimate filling.
#pragma once

#include "cartesian_filter_settings.hpp"
#include "three_point_init.hpp"

#include <trackflow/estimate_state.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/items.hpp>
#include <trackflow/motion.hpp>
#include <trackflow/noise.hpp>

#include <Eigen/Core>

#include <utility>

namespace trackflow::cartesian_filter {

// State [x vx (ax) y vy (ay) z vz (az)], Order states per axis (motion.hpp layout), absolute ENU;
// the sensor is at rest at Measurement::sensor_position. The prediction is linear (F x,
// F P F' + Q): the motion models are linear in Cartesian coordinates, so any filter on this state
// predicts exactly this way. CartesianRadarEstimator makes it an SDK estimator; filter.imm
// holds one per mode.
template <int Order>
class CartesianRadarState {
 public:
  using Layout = KinematicModel<Order>;
  static constexpr int N = Layout::kDim;
  using StateN = typename Layout::State;
  using MatN = typename Layout::Matrix;
  using AxisMatrix = typename Layout::AxisMatrix;

  CartesianRadarState() : CartesianRadarState(Settings{}) {}
  explicit CartesianRadarState(Settings s) : s_(std::move(s)) {
    for (double& q : q_) q = s_.intensity;
    for (int a = 0; a < 3; ++a) {
      idx_[a] = Layout::position_index(a);
      idx_[a + 3] = Layout::velocity_index(a);
    }
  }

  const Settings& settings() const { return s_; }
  double last_interval() const { return last_T_; }

  // Start of a run: forget the track; true when it starts initialised (init: explicit).
  bool reset_state() {
    points_ = 0;
    planar_ = false;
    last_T_ = -1.0;
    if (s_.init != Settings::Init::Explicit) return false;
    x_.setZero();
    P_.setZero();
    for (int a = 0; a < 3; ++a) {
      x_(idx_[a]) = s_.p0(a);
      x_(idx_[a + 3]) = s_.v0(a);
      P_(idx_[a], idx_[a]) = s_.sp0 * s_.sp0;
      P_(idx_[a + 3], idx_[a + 3]) = s_.sv0 * s_.sv0;
      if constexpr (Order == 3) {
        x_(a * 3 + 2) = s_.a0(a);
        P_(a * 3 + 2, a * 3 + 2) = s_.sa0 * s_.sa0;
      }
    }
    return true;
  }

  // Predicts T > 0 seconds ahead. `same_model`: T equals last_interval() to the precision of the
  // time stamps (Estimator::same_interval), so F and Q computed for it are used again.
  void predict_state(double T, bool same_model) {
    if (!same_model) {  // fixed-rate data: F and the unit-intensity Q are computed once
      compute_axis_model(T);
      last_T_ = T;
    }
    for (int a = 0; a < 3; ++a) {
      const Eigen::Matrix<double, Order, 1> xa = axisF_ * x_.template segment<Order>(a * Order);
      x_.template segment<Order>(a * Order) = xa;
    }
    propagate_covariance();
    for (int a = 0; a < 3; ++a) {
      const double s = noise_scale(a);
      for (int j = 0; j < Order; ++j)
        for (int i = 0; i <= j; ++i) P_(a * Order + i, a * Order + j) += s * axisQ_(i, j);
    }
    for (int j = 0; j < N; ++j)
      for (int i = 0; i < j; ++i) P_(j, i) = P_(i, j);
  }

  // P <- F P F' (upper triangle) with F block-diagonal and each axis block upper triangular with
  // a unit diagonal except the last element: CV [[1, T], [0, 1]], CA and Singer
  // [[1, f01, f02], [0, 1, f12], [0, 0, f22]]. Row operations give F P, the same on the columns
  // of its upper triangle give F P F': 72 + 57 multiplications for CA instead of 9 dense 3x3x3
  // block products (486) (and no symmetrisation: the lower triangle is mirrored by the caller).
  void propagate_covariance() {
    const double f01 = axisF_(0, 1);
    double f02 = 0.0, f12 = 0.0, f22 = 1.0;
    if constexpr (Order == 3) {
      f02 = axisF_(0, 2);
      f12 = axisF_(1, 2);
      f22 = axisF_(2, 2);
    }
    for (int a = 0; a < 3; ++a) {
      const int i = a * Order;
      // Columns left of this axis's block are below the diagonal: the column pass never reads
      // them (it reads rows of its own block and above) and the caller mirrors the lower triangle.
      for (int c = i; c < N; ++c) {
        if constexpr (Order == 3) {
          P_(i, c) += f01 * P_(i + 1, c) + f02 * P_(i + 2, c);
          P_(i + 1, c) += f12 * P_(i + 2, c);
          P_(i + 2, c) *= f22;
        } else {
          P_(i, c) += f01 * P_(i + 1, c);
        }
      }
    }
    for (int b = 0; b < 3; ++b) {
      const int j = b * Order;
      if constexpr (Order == 3) {
        for (int r = 0; r <= j; ++r) P_(r, j) += f01 * P_(r, j + 1) + f02 * P_(r, j + 2);
        for (int r = 0; r <= j + 1; ++r) P_(r, j + 1) += f12 * P_(r, j + 2);
        for (int r = 0; r <= j + 2; ++r) P_(r, j + 2) *= f22;
      } else {
        for (int r = 0; r <= j; ++r) P_(r, j) += f01 * P_(r, j + 1);
      }
    }
  }

  void compute_axis_model(double T) {
    if constexpr (Order == 3) {
      if (s_.motion == Settings::Motion::Singer) {
        axisF_ = SingerModel::axis_transition(s_.singer_alpha, T);
        axisQ_ = (2.0 * s_.singer_alpha) * SingerModel::noise_per_psd(s_.singer_alpha, T);
        return;
      }
    }
    axisF_ = Layout::axis_transition(T);
    axisQ_ = s_.noise == Settings::Noise::Continuous ? Layout::axis_noise_continuous(T, 1.0)
                                                     : Layout::axis_noise_discrete(T, 1.0);
  }

  // axisQ_ is for unit intensity; q_ may be retuned by adapters between steps.
  double noise_scale(int axis) const {
    if (axis == 2 && planar_) return 0.0;  // a 2-D radar's track stays in the radar's horizontal plane
    return s_.noise == Settings::Noise::Continuous ? q_[axis] : q_[axis] * q_[axis];
  }

  // Collects converted positions until the state can be formed: two points (two_point; paper000
  // with CV), three (paper000 with CA/Singer).
  // R: the measurement's spherical covariance (at least 3x3), or polar (at least 2x2). A 2-D
  // radar's (Polar) points are taken in its horizontal plane (elevation 0, geometry.hpp): the track
  // lives there, its z at the radar's height with zero variance and no z process noise, so the
  // slant range it predicts is the ground range. A polar and a spherical point do not pair.
  bool add_point(const Measurement& m, const MeasCov& R) {
    const bool polar = m.frame == Frame::Polar;
    if (points_ > 0 && polar != planar_) points_ = 0;
    planar_ = polar;
    if (polar) {
      if (points_ > 0 && m.time == tc_[points_ - 1]) --points_;
      zc_[points_] = measured_position(m);
      const Mat3 Rc = measured_position_covariance(m, R);
      Rc_[points_] = 0.5 * (Rc + Rc.transpose());
      tc_[points_] = m.time;
      ++points_;
      return form_state();
    }
    if (points_ > 0 && m.time == tc_[points_ - 1]) --points_;  // same time stamp: keep the newer one
    // Classical conversion with the exact Jacobian covariance (as convert.classical).
    const double r = m.value(0), az = m.value(1), el = m.value(2);
    // A tilted sensor's offset is in its own axes: turned into the frame's, with its Jacobian.
    const Mat3 J = m.sensor_level ? spherical_to_enu_jacobian(r, az, el, m.azimuth)
                                  : Mat3(m.sensor_axes * spherical_to_enu_jacobian(r, az, el, m.azimuth));
    const Mat3 Rs = R.topLeftCorner(3, 3);
    zc_[points_] = sensor_to_frame(m, spherical_to_enu(r, az, el, m.azimuth)) + m.sensor_position;
    const Mat3 Rc = J * Rs * J.transpose();
    Rc_[points_] = 0.5 * (Rc + Rc.transpose());
    tc_[points_] = m.time;
    ++points_;
    return form_state();
  }
  // One-point start: the converted point (position, covariance J R J' as add_point's) with velocity
  // 0 of variance velocity_sigma^2 per axis (none on z for a 2-D radar's point, whose track lies in
  // its plane), CA/Singer acceleration 0 with initial_sigma_acceleration.
  bool start_at_rest(const Measurement& m, const MeasCov& R, double velocity_sigma) {
    planar_ = m.frame == Frame::Polar;
    points_ = 0;
    const Vec3 z = measured_position(m);
    Mat3 Rc = measured_position_covariance(m, R);
    Rc = 0.5 * (Rc + Rc.transpose());
    x_.setZero();
    P_.setZero();
    for (int a = 0; a < 3; ++a) {
      x_(idx_[a]) = z(a);
      for (int b = 0; b < 3; ++b) P_(idx_[a], idx_[b]) = Rc(a, b);
      if (!(planar_ && a == 2)) P_(idx_[a + 3], idx_[a + 3]) = velocity_sigma * velocity_sigma;
      if constexpr (Order == 3)
        if (!(planar_ && a == 2)) P_(a * 3 + 2, a * 3 + 2) = s_.sa0 * s_.sa0;
    }
    return true;
  }
  bool form_state() {
    const bool three = s_.init == Settings::Init::Paper000 && Order == 3;
    if (points_ < (three ? 3 : 2)) return false;
    x_.setZero();
    P_.setZero();
    if (s_.init == Settings::Init::Paper000)
      paper000_state();
    else
      two_point_state();
    return true;
  }

  // Bar-Shalom, Li & Kirubarajan 2001 §5.5.3 with the full converted covariances.
  void two_point_state() {
    const Vec3 &z1 = zc_[0], &z2 = zc_[1];
    const Mat3 &R1 = Rc_[0], &R2 = Rc_[1];
    const double T = tc_[1] - tc_[0];
    for (int a = 0; a < 3; ++a) {
      const int p = idx_[a], v = idx_[a + 3];
      x_(p) = z2(a);
      x_(v) = (z2(a) - z1(a)) / T;
      for (int b = 0; b < 3; ++b) {
        const int pb = idx_[b], vb = idx_[b + 3];
        P_(p, pb) = R2(a, b);
        P_(p, vb) = P_(vb, p) = R2(a, b) / T;
        P_(v, vb) = (R1(a, b) + R2(a, b)) / (T * T);
      }
      if constexpr (Order == 3)
        if (!(planar_ && a == 2)) P_(a * 3 + 2, a * 3 + 2) = s_.sa0 * s_.sa0;
    }
  }

  // Paper 000 §IV.2.1: per axis, the covariance of finite differences of positions with
  // variance sigma^2 (the latest converted variance of that axis); no cross-axis terms.
  void paper000_state() {
    for (int a = 0; a < 3; ++a) {
      const double s2 = Rc_[points_ - 1](a, a);
      if constexpr (Order == 3) {
        const Eigen::Matrix3d A = three_point_differences(tc_[1] - tc_[0], tc_[2] - tc_[1]);
        const Vec3 za(zc_[0](a), zc_[1](a), zc_[2](a));
        x_.template segment<3>(a * 3) = A * za;
        P_.template block<3, 3>(a * 3, a * 3) = paper000_axis_covariance(s2, tc_[1] - tc_[0], tc_[2] - tc_[1]);
      } else {
        const double T = tc_[1] - tc_[0];
        x_(2 * a) = zc_[1](a);
        x_(2 * a + 1) = (zc_[1](a) - zc_[0](a)) / T;
        P_(2 * a, 2 * a) = s2;
        P_(2 * a, 2 * a + 1) = P_(2 * a + 1, 2 * a) = s2 / T;
        P_(2 * a + 1, 2 * a + 1) = 2 * s2 / (T * T);
      }
    }
  }

  void fill_state(Estimate& e) const { set_estimate_state(e, x_, P_, idx_); }

  Settings s_;
  double q_[3] = {};  // process-noise intensity per ENU axis (adapters may retune it)
  StateN x_ = StateN::Zero();
  MatN P_ = MatN::Identity();
  int idx_[6] = {};  // state indices of [x y z vx vy vz]

 private:
  AxisMatrix axisF_ = AxisMatrix::Identity();
  AxisMatrix axisQ_ = AxisMatrix::Zero();
  double last_T_ = -1.0;
  int points_ = 0;
  bool planar_ = false;  // the track lies in a 2-D radar's horizontal plane
  Vec3 zc_[3];
  Mat3 Rc_[3];
  double tc_[3] = {};
};

}  // namespace trackflow::cartesian_filter
