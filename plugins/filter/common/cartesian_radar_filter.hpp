// Purpose: the skeleton shared by the Cartesian-state radar filters (filter.ekf, filter.ukf): measurement checks, adapters, initialisation, linear prediction, coasting and Estimate filling; the derived filter supplies the update.
#pragma once

#include "cartesian_filter_settings.hpp"
#include "three_point_init.hpp"

#include <trackflow/component.hpp>
#include <trackflow/error.hpp>
#include <trackflow/geometry.hpp>
#include <trackflow/motion.hpp>

#include <Eigen/Core>

#include <string>
#include <utility>

namespace trackflow::cartesian_filter {

// State [x vx (ax) y vy (ay) z vz (az)], Order states per axis (motion.hpp layout), absolute ENU;
// the sensor is at rest at Measurement::sensor_position. The prediction is linear (F x,
// F P F' + Q): the motion models are linear in Cartesian coordinates, so any filter on this state
// predicts exactly this way. Derived (CRTP) provides
//   void on_start_run();                               reset its own per-run state
//   template <int M> void update(const Measurement&);  M = 3 or 4: correct x_ and P_ with the
//       measurement's first M values and R_.topLeftCorner(M, M); call accept_update() on success.
template <int Order, class Derived>
class CartesianRadarFilter : public Filter {
 public:
  using Layout = KinematicModel<Order>;
  static constexpr int N = Layout::kDim;
  using StateN = typename Layout::State;
  using MatN = typename Layout::Matrix;
  using AxisMatrix = typename Layout::AxisMatrix;

  NoiseHandles noise() override {
    NoiseHandles h;
    h.measurement_noise = &R_;
    h.process_noise = q_;
    h.process_noise_count = 3;  // east, north, up
    h.measurement_space = "spherical";
    return h;
  }

  void start_run(const RunContext& ctx) override {
    // Adapters may have retuned q in the previous run on this instance; every run starts from
    // the configured value, or results would depend on which thread ran which run.
    for (double& q : q_) q = s_.intensity;
    diag_ = ctx.diagnostics;
    points_ = 0;
    last_T_ = -1.0;
    has_time_ = false;
    initialised_ = s_.init == Settings::Init::Explicit;
    if (initialised_) {
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
    }
    derived().on_start_run();
  }

  void on_measurement(const Measurement& m, int) override {
    if (m.frame != Frame::Spherical)
      throw DataError(who() + " takes spherical [r, az, el(, rdot)] measurements; for Cartesian (converted) "
                              "measurements use filter.kalman");
    const int n = static_cast<int>(m.value.size());
    const bool well_formed =
        n == (m.has_range_rate ? 4 : 3) && m.covariance.rows() == n && m.covariance.cols() == n;
    if (m.valid && !well_formed)
      throw DataError(who() + ": measurement at t=" + std::to_string(m.time) + " s has " + std::to_string(n) +
                      " values and a " + std::to_string(m.covariance.rows()) + "x" +
                      std::to_string(m.covariance.cols()) + " covariance; expected " +
                      (m.has_range_rate ? "4 (r, az, el, rdot)" : "3 (r, az, el)"));
    if (has_time_ && m.time < time_) {
      if (diag_)
        diag_->skip(s_.node, "measurement at t=" + std::to_string(m.time) + " s is older than the track (t=" +
                                 std::to_string(time_) + " s)");
      return;
    }
    int dim = 3;
    if (s_.range_rate == Settings::RangeRate::Use) {
      if (m.valid && !m.has_range_rate)
        throw DataError(who() + ": range_rate: use, but the measurement at t=" + std::to_string(m.time) +
                        " s has no range rate (use range_rate: auto to accept both)");
      dim = 4;
    } else if (s_.range_rate == Settings::RangeRate::Auto) {
      dim = m.has_range_rate ? 4 : 3;
    }
    // An invalid measurement is only coasted through; its R is kept if it is malformed.
    if (well_formed && n >= dim) R_ = m.covariance.topLeftCorner(dim, dim);
    before_update(m);  // adapters may replace R_ and q_
    if (m.valid && (R_.rows() < dim || R_.cols() < dim))
      throw DataError(who() + ": an adapter left a " + std::to_string(R_.rows()) + "x" + std::to_string(R_.cols()) +
                      " R for a " + std::to_string(dim) + "-element measurement");
    const bool usable = m.valid && m.value.allFinite();
    if (m.valid && !usable) warn("non-finite measurement at t=" + std::to_string(m.time) + " s treated as invalid");
    if (!initialised_) {
      initialise(m, usable);
      return;
    }
    if (!has_time_) {  // explicit initial state: it holds at the first measurement's time
      time_ = m.time;
      has_time_ = true;
    }
    predict(m.time);
    clear_innovation();
    if (usable) {
      if (dim == 4)
        derived().template update<4>(m);
      else
        derived().template update<3>(m);
    }
    fill_estimate(m.time);
    publish(m, est_);
  }

 protected:
  explicit CartesianRadarFilter(Settings s) : s_(std::move(s)) {
    for (double& q : q_) q = s_.intensity;
    for (int a = 0; a < 3; ++a) {
      idx_[a] = Layout::position_index(a);
      idx_[a + 3] = Layout::velocity_index(a);
    }
    est_.state.resize(N);
    est_.covariance.resize(N, N);
    R_ = MeasCov::Zero(3, 3);
  }

  const Settings& settings() const { return s_; }
  std::string who() const { return s_.type + " (node '" + s_.node + "')"; }
  void warn(const std::string& message) const {
    if (diag_) diag_->warn(s_.node, message);
  }
  Diagnostics* diagnostics() const { return diag_; }

  template <int M>
  void accept_update(const Eigen::Matrix<double, M, 1>& nu, const Eigen::Matrix<double, M, M>& S, double nis) {
    est_.updated = true;
    est_.innovation = nu;
    est_.innovation_covariance = S;
    est_.nis = nis;
  }

  StateN x_ = StateN::Zero();
  MatN P_ = MatN::Identity();
  MeasCov R_;
  int idx_[6] = {};  // state indices of [x y z vx vy vz]

 private:
  Derived& derived() { return static_cast<Derived&>(*this); }

  void clear_innovation() {
    est_.updated = false;
    est_.innovation.resize(0);
    est_.innovation_covariance.resize(0, 0);
    est_.nis = 0.0;
  }

  void predict(double t) {
    const double T = t - time_;
    if (T > 0.0) {
      if (T != last_T_) {  // fixed-rate data: F and the unit-intensity Q are computed once
        compute_axis_model(T);
        last_T_ = T;
      }
      for (int a = 0; a < 3; ++a) {
        const Eigen::Matrix<double, Order, 1> xa = axisF_ * x_.template segment<Order>(a * Order);
        x_.template segment<Order>(a * Order) = xa;
      }
      // F is block-diagonal: (F P F')_ab = A P_ab A'.
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
          const AxisMatrix Pab = axisF_ * P_.template block<Order, Order>(a * Order, b * Order) * axisF_.transpose();
          P_.template block<Order, Order>(a * Order, b * Order) = Pab;
        }
      for (int a = 0; a < 3; ++a) P_.template block<Order, Order>(a * Order, a * Order) += noise_scale(a) * axisQ_;
      P_ = 0.5 * (P_ + P_.transpose()).eval();
    }
    time_ = t;
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
    return s_.noise == Settings::Noise::Continuous ? q_[axis] : q_[axis] * q_[axis];
  }

  // Collects converted positions until the state can be formed: two points (two_point; paper000
  // with CV), three (paper000 with CA/Singer).
  void initialise(const Measurement& m, bool usable) {
    if (!usable) {
      publish_uninitialised(m);
      return;
    }
    if (points_ > 0 && m.time < tc_[points_ - 1]) {
      if (diag_) diag_->skip(s_.node, "measurement at t=" + std::to_string(m.time) + " s is older than the previous one");
      return;
    }
    if (points_ > 0 && m.time == tc_[points_ - 1]) --points_;  // same time stamp: keep the newer one
    // Classical conversion with the exact Jacobian covariance (as convert.classical).
    const double r = m.value(0), az = m.value(1), el = m.value(2);
    const Mat3 J = spherical_to_enu_jacobian(r, az, el, m.azimuth);
    const Mat3 Rs = R_.topLeftCorner(3, 3);
    zc_[points_] = spherical_to_enu(r, az, el, m.azimuth) + m.sensor_position;
    const Mat3 Rc = J * Rs * J.transpose();
    Rc_[points_] = 0.5 * (Rc + Rc.transpose());
    tc_[points_] = m.time;
    ++points_;
    const bool three = s_.init == Settings::Init::Paper000 && Order == 3;
    if (points_ < (three ? 3 : 2)) {
      publish_uninitialised(m);
      return;
    }
    x_.setZero();
    P_.setZero();
    if (s_.init == Settings::Init::Paper000)
      paper000_state();
    else
      two_point_state();
    time_ = m.time;
    has_time_ = true;
    initialised_ = true;
    clear_innovation();
    fill_estimate(m.time);
    publish(m, est_);
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
      if constexpr (Order == 3) P_(a * 3 + 2, a * 3 + 2) = s_.sa0 * s_.sa0;
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

  // No state yet: publish zeros rather than whatever the previous run left.
  void publish_uninitialised(const Measurement& m) {
    set_uninitialised(est_, m.time);
    publish(m, est_);
  }

  void fill_estimate(double t) {
    est_.time = t;
    est_.initialised = true;
    est_.state = x_;
    est_.covariance = P_;
    for (int i = 0; i < 6; ++i) {
      est_.enu(i) = x_(idx_[i]);
      for (int j = 0; j < 6; ++j) est_.enu_covariance(i, j) = P_(idx_[i], idx_[j]);
    }
  }

  Settings s_;
  double q_[3] = {};
  AxisMatrix axisF_ = AxisMatrix::Identity();
  AxisMatrix axisQ_ = AxisMatrix::Zero();
  Estimate est_;
  Diagnostics* diag_ = nullptr;
  double time_ = 0.0, last_T_ = -1.0;
  bool has_time_ = false, initialised_ = false;
  int points_ = 0;
  Vec3 zc_[3];
  Mat3 Rc_[3];
  double tc_[3] = {};
};

}  // namespace trackflow::cartesian_filter
