// Purpose: filter.ekf — extended Kalman filter with a Cartesian ENU state (CV, CA or Singer motion) on spherical [r, az, el(, rdot)] measurements.
#include "three_point_init.hpp"
#include "zenith_linearisation.hpp"

#include <trackflow/geometry.hpp>
#include <trackflow/kalman.hpp>
#include <trackflow/motion.hpp>
#include <trackflow/plugin.hpp>
#include <trackflow/spherical_measurement.hpp>

#include <cmath>
#include <string>

namespace trackflow {
namespace {

struct EkfSettings {
  enum class Motion { ConstantVelocity, ConstantAcceleration, Singer } motion = Motion::ConstantVelocity;
  // Continuous: q (CV, m2/s3) or q_jerk (CA, m2/s5); Discrete: sigma_accel; Singer: singer_sigma.
  enum class Noise { Continuous, Discrete, Singer } noise = Noise::Continuous;
  double intensity = 1.0;
  double singer_alpha = 1.0;
  enum class RangeRate { Auto, Use, Ignore } range_rate = RangeRate::Auto;
  enum class Init { TwoPoint, Explicit, Paper000 } init = Init::TwoPoint;
  Vec3 p0 = Vec3::Zero(), v0 = Vec3::Zero(), a0 = Vec3::Zero();
  double sp0 = 0, sv0 = 0, sa0 = 0;  // initial standard deviations
  std::string node;
};

// State [x vx (ax) y vy (ay) z vz (az)], Order states per axis (motion.hpp layout), absolute ENU.
// The sensor is at rest at Measurement::sensor_position.
template <int Order>
class ExtendedKalmanFilter final : public Filter {
  using Layout = KinematicModel<Order>;
  static constexpr int N = Layout::kDim;
  using StateN = typename Layout::State;
  using MatN = typename Layout::Matrix;
  using AxisMatrix = typename Layout::AxisMatrix;

 public:
  explicit ExtendedKalmanFilter(EkfSettings s) : s_(std::move(s)) {
    for (double& q : q_) q = s_.intensity;
    for (int a = 0; a < 3; ++a) {
      idx_[a] = Layout::position_index(a);
      idx_[a + 3] = Layout::velocity_index(a);
    }
    est_.state.resize(N);
    est_.covariance.resize(N, N);
    R_ = MeasCov::Zero(3, 3);
  }

  NoiseHandles noise() override {
    NoiseHandles h;
    h.measurement_noise = &R_;
    h.process_noise = q_;
    h.process_noise_count = 3;  // east, north, up
    h.measurement_space = "spherical";
    return h;
  }

  void start_run(const RunContext& ctx) override {
    diag_ = ctx.diagnostics;
    points_ = 0;
    last_T_ = -1.0;
    zenith_reported_ = false;
    has_time_ = false;
    initialised_ = s_.init == EkfSettings::Init::Explicit;
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
  }

  void on_measurement(const Measurement& m, int) override {
    if (m.frame != Frame::Spherical)
      throw DataError("filter.ekf (node '" + s_.node +
                      "') takes spherical [r, az, el(, rdot)] measurements; for Cartesian (converted) "
                      "measurements use filter.kalman");
    const int n = static_cast<int>(m.value.size());
    const bool well_formed =
        n == (m.has_range_rate ? 4 : 3) && m.covariance.rows() == n && m.covariance.cols() == n;
    if (m.valid && !well_formed)
      throw DataError("filter.ekf (node '" + s_.node + "'): measurement at t=" + std::to_string(m.time) + " s has " +
                      std::to_string(n) + " values and a " + std::to_string(m.covariance.rows()) + "x" +
                      std::to_string(m.covariance.cols()) + " covariance; expected " +
                      (m.has_range_rate ? "4 (r, az, el, rdot)" : "3 (r, az, el)"));
    if (has_time_ && m.time < time_) {
      if (diag_)
        diag_->skip(s_.node, "measurement at t=" + std::to_string(m.time) + " s is older than the track (t=" +
                                 std::to_string(time_) + " s)");
      return;
    }
    int dim = 3;
    if (s_.range_rate == EkfSettings::RangeRate::Use) {
      if (m.valid && !m.has_range_rate)
        throw DataError("filter.ekf (node '" + s_.node + "'): range_rate: use, but the measurement at t=" +
                        std::to_string(m.time) + " s has no range rate (use range_rate: auto to accept both)");
      dim = 4;
    } else if (s_.range_rate == EkfSettings::RangeRate::Auto) {
      dim = m.has_range_rate ? 4 : 3;
    }
    // An invalid measurement is only coasted through; its R is kept if it is malformed.
    if (well_formed && n >= dim) R_ = m.covariance.topLeftCorner(dim, dim);
    before_update(m);  // adapters may replace R_ and q_
    if (m.valid && (R_.rows() < dim || R_.cols() < dim))
      throw DataError("filter.ekf (node '" + s_.node + "'): an adapter left a " + std::to_string(R_.rows()) + "x" +
                      std::to_string(R_.cols()) + " R for a " + std::to_string(dim) + "-element measurement");
    const bool usable = m.valid && m.value.allFinite();
    if (m.valid && !usable && diag_)
      diag_->warn(s_.node, "non-finite measurement at t=" + std::to_string(m.time) + " s treated as invalid");
    if (!initialised_) {
      initialise(m, usable);
      return;
    }
    if (!has_time_) {  // explicit initial state: it holds at the first measurement's time
      time_ = m.time;
      has_time_ = true;
    }
    predict(m.time);
    est_.updated = false;
    est_.innovation.resize(0);
    est_.innovation_covariance.resize(0, 0);
    est_.nis = 0.0;
    if (usable) {
      if (dim == 4)
        update<4>(m);
      else
        update<3>(m);
    }
    fill_estimate(m.time);
    publish(m, est_);
  }

 private:
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
      if (s_.motion == EkfSettings::Motion::Singer) {
        axisF_ = SingerModel::axis_transition(s_.singer_alpha, T);
        axisQ_ = (2.0 * s_.singer_alpha) * SingerModel::noise_per_psd(s_.singer_alpha, T);
        return;
      }
    }
    axisF_ = Layout::axis_transition(T);
    axisQ_ = s_.noise == EkfSettings::Noise::Continuous ? Layout::axis_noise_continuous(T, 1.0)
                                                        : Layout::axis_noise_discrete(T, 1.0);
  }

  // axisQ_ is for unit intensity; q_ may be retuned by adapters between steps.
  double noise_scale(int axis) const {
    return s_.noise == EkfSettings::Noise::Continuous ? q_[axis] : q_[axis] * q_[axis];
  }

  template <int M>
  void update(const Measurement& m) {
    using MatM = Eigen::Matrix<double, M, M>;
    const Vec3 d = Layout::position(x_) - m.sensor_position;
    const Vec3 v = Layout::velocity(x_);
    SphericalJacobian<M> J;
    const SphericalSingularity sing = spherical_measurement_jacobian<M>(d, v, m.azimuth, J);
    if (sing == SphericalSingularity::AtSensor) {
      if (diag_)
        diag_->warn(s_.node, "predicted position at the sensor at t=" + std::to_string(m.time) +
                                 " s: no direction to linearise about; measurement not used");
      return;
    }
    const SphericalVec<M> z = m.value.template head<M>();
    SphericalVec<M> nu = spherical_residual<M>(z, spherical_measurement<M>(d, v, m.azimuth));
    MatM R = R_.topLeftCorner(M, M);
    Eigen::Matrix<double, M, N> H = Eigen::Matrix<double, M, N>::Zero();
    for (int k = 0; k < 6; ++k) H.col(idx_[k]) = J.col(k);
    // Curvature of the angles over the predicted horizontal uncertainty (zenith_linearisation.hpp):
    // negligible at ordinary ranges, it de-weights the azimuth smoothly as the target nears the
    // zenith. When the zenith itself is within 3 sigma of the predicted horizontal position the
    // azimuth may flip by pi and is dropped: zero row, zero innovation, R decorrelated (an
    // infinitely uncertain azimuth; range, elevation and range rate still update).
    Eigen::Matrix2d Ph;
    Ph << P_(idx_[0], idx_[0]), P_(idx_[0], idx_[1]), P_(idx_[1], idx_[0]), P_(idx_[1], idx_[1]);
    const ekf::AngleCurvature curvature = ekf::angle_curvature_variance(d, Ph, kZenithFraction * d.norm());
    const double raz = R(1, 1);
    R(2, 2) += curvature.elevation;
    const bool drop_azimuth = sing == SphericalSingularity::Zenith || curvature.azimuth_unusable;
    if (drop_azimuth) {
      H.row(1).setZero();
      nu(1) = 0.0;
      R.row(1).setZero();
      R.col(1).setZero();
      R(1, 1) = raz > 0.0 ? raz : 1.0;
    } else {
      R(1, 1) += curvature.azimuth;
    }
    if (!zenith_reported_ && diag_ && (drop_azimuth || curvature.azimuth > raz)) {
      diag_->warn(s_.node, "target near the zenith at t=" + std::to_string(m.time) + " s: azimuth " +
                               (drop_azimuth ? "not used" : "de-weighted") +
                               " (its linearisation fails over the predicted uncertainty); reported once per run");
      zenith_reported_ = true;
    }
    MatM S;
    double nis = 0.0;
    if (joseph_update<N, M>(x_, P_, nu, H, R, S, nis)) {
      est_.updated = true;
      est_.innovation = nu;
      est_.innovation_covariance = S;
      est_.nis = nis;
    } else if (diag_) {
      diag_->warn(s_.node, "innovation covariance not positive definite at t=" + std::to_string(m.time) +
                               " s; measurement not used");
    }
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
    const bool three = s_.init == EkfSettings::Init::Paper000 && Order == 3;
    if (points_ < (three ? 3 : 2)) {
      publish_uninitialised(m);
      return;
    }
    x_.setZero();
    P_.setZero();
    if (s_.init == EkfSettings::Init::Paper000)
      paper000_state();
    else
      two_point_state();
    time_ = m.time;
    has_time_ = true;
    initialised_ = true;
    est_.updated = false;
    est_.innovation.resize(0);
    est_.innovation_covariance.resize(0, 0);
    est_.nis = 0.0;
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
        const Eigen::Matrix3d A = ekf::three_point_differences(tc_[1] - tc_[0], tc_[2] - tc_[1]);
        const Vec3 za(zc_[0](a), zc_[1](a), zc_[2](a));
        x_.template segment<3>(a * 3) = A * za;
        P_.template block<3, 3>(a * 3, a * 3) = ekf::paper000_axis_covariance(s2, tc_[1] - tc_[0], tc_[2] - tc_[1]);
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
    est_.state.setZero();
    est_.covariance.setZero();
    est_.enu.setZero();
    est_.enu_covariance.setZero();
    est_.time = m.time;
    est_.updated = false;
    est_.initialised = false;
    est_.innovation.resize(0);
    est_.innovation_covariance.resize(0, 0);
    est_.nis = 0.0;
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

  EkfSettings s_;
  double q_[3] = {};
  StateN x_ = StateN::Zero();
  MatN P_ = MatN::Identity();
  AxisMatrix axisF_ = AxisMatrix::Identity();
  AxisMatrix axisQ_ = AxisMatrix::Zero();
  MeasCov R_;
  Estimate est_;
  Diagnostics* diag_ = nullptr;
  double time_ = 0.0, last_T_ = -1.0;
  bool has_time_ = false, initialised_ = false, zenith_reported_ = false;
  int points_ = 0;
  Vec3 zc_[3];
  Mat3 Rc_[3];
  double tc_[3] = {};
  int idx_[6] = {};  // state indices of [x y z vx vy vz]
};

std::unique_ptr<Component> create(const Params& p) {
  using S = EkfSettings;
  S s;
  s.node = p.node();
  const std::string& motion = p.text("motion");
  s.motion = motion == "constant_acceleration" ? S::Motion::ConstantAcceleration
             : motion == "singer"              ? S::Motion::Singer
                                               : S::Motion::ConstantVelocity;
  const bool cv = s.motion == S::Motion::ConstantVelocity, ca = s.motion == S::Motion::ConstantAcceleration,
             singer = s.motion == S::Motion::Singer;
  if (!cv && p.given("q"))
    throw p.error("q", "q (m2/s3) is the constant_velocity intensity; constant_acceleration takes q_jerk (m2/s5), "
                       "singer takes singer_alpha and singer_sigma");
  if (!ca && p.given("q_jerk")) throw p.error("q_jerk", "q_jerk is for motion: constant_acceleration");
  if (singer && p.given("sigma_accel"))
    throw p.error("sigma_accel", "sigma_accel is the discrete-noise alternative for constant_velocity and "
                                 "constant_acceleration; the Singer noise is set by singer_sigma");
  for (const char* name : {"singer_alpha", "singer_sigma"}) {
    if (!singer && p.given(name)) throw p.error(name, std::string(name) + " is for motion: singer");
    if (singer && !p.has(name)) throw p.error(name, "required with motion: singer");
  }
  if (p.given("sigma_accel") && (p.given("q") || p.given("q_jerk")))
    throw p.error("sigma_accel", "give either a continuous-noise intensity (q / q_jerk) or sigma_accel, not both");
  if (singer) {
    s.noise = S::Noise::Singer;
    s.intensity = p.real("singer_sigma");
    s.singer_alpha = p.real("singer_alpha");
  } else if (p.given("sigma_accel")) {
    s.noise = S::Noise::Discrete;
    s.intensity = p.real("sigma_accel");
  } else {
    s.intensity = ca ? p.real("q_jerk") : p.real("q");
  }

  const std::string& rr = p.text("range_rate");
  s.range_rate = rr == "use" ? S::RangeRate::Use : rr == "ignore" ? S::RangeRate::Ignore : S::RangeRate::Auto;

  const std::string& init = p.text("init");
  s.init = init == "explicit" ? S::Init::Explicit : init == "paper000" ? S::Init::Paper000 : S::Init::TwoPoint;
  const bool expl = s.init == S::Init::Explicit;
  for (const char* name : {"initial_position", "initial_velocity", "initial_acceleration", "initial_sigma_position",
                           "initial_sigma_velocity"})
    if (!expl && p.given(name)) throw p.error(name, std::string(name) + " is only used with init: explicit");
  if (expl)
    for (const char* req : {"initial_position", "initial_sigma_position", "initial_sigma_velocity"})
      if (!p.has(req)) throw p.error(req, "required with init: explicit");
  if (cv && p.given("initial_acceleration"))
    throw p.error("initial_acceleration", "the constant_velocity state has no acceleration");
  if (p.given("initial_sigma_acceleration")) {
    if (cv) throw p.error("initial_sigma_acceleration", "the constant_velocity state has no acceleration");
    if (s.init == S::Init::Paper000)
      throw p.error("initial_sigma_acceleration", "init: paper000 derives the acceleration variance from sigma and T");
  }
  if (expl) {
    s.p0 = p.vec3("initial_position");
    s.v0 = p.vec3("initial_velocity");
    s.a0 = p.vec3("initial_acceleration");
    s.sp0 = p.real("initial_sigma_position");
    s.sv0 = p.real("initial_sigma_velocity");
  }
  // Unknown initial acceleration: Singer's stationary std is the natural prior.
  s.sa0 = p.real_or("initial_sigma_acceleration", singer ? s.intensity : 50.0);
  if (cv) return std::make_unique<ExtendedKalmanFilter<2>>(s);
  return std::make_unique<ExtendedKalmanFilter<3>>(s);
}

void register_components(Registrar& r) {
  ComponentDecl d;
  d.type = "filter.ekf";
  d.kind = ComponentKind::Filter;
  d.summary = "Extended Kalman filter: Cartesian ENU state (CV, CA or Singer) on spherical [r, az, el(, rdot)] "
              "measurements";
  d.doc =
      "State [x vx (ax) y vy (ay) z vz (az)] in ENU; linear prediction, measurement h(x) = [r, az, el(, rdot)] "
      "relative to the (stationary) sensor in its azimuth convention, analytic Jacobian (paper 000 eq 3.22-3.24, "
      "corrected), azimuth innovation wrapped to (-pi, pi], Joseph-form update. Motion: CV (white acceleration, q), "
      "CA (Wiener-process acceleration, q_jerk, paper 000 eq 3.19), sigma_accel for the discrete white-noise "
      "variants, or Singer (alpha, sigma_m; exact discretisation). Near the zenith the angles' curvature variance is "
      "added to R and the azimuth is dropped while the zenith is within 3 sigma. Invalid measurements: predict only. "
      "R from each measurement in spherical space (adapters may replace it; q per ENU axis). See docs/filters.md.";
  d.accepts = mask(ItemKind::Measurement);
  d.produces = mask(ItemKind::Estimate);
  d.params = {
      ParamSpec::choice("motion", {"constant_velocity", "constant_acceleration", "singer"}, "motion model")
          .def("constant_velocity"),
      ParamSpec::real("q", dim::accel_psd, "constant_velocity: spectral density of the white acceleration noise")
          .def("1 m2/s3")
          .at_least(0),
      ParamSpec::real("q_jerk", dim::jerk_psd,
                      "constant_acceleration: spectral density of the white jerk noise (paper 000 eq 3.19)")
          .def("1 m2/s5")
          .at_least(0),
      ParamSpec::real("sigma_accel", dim::acceleration,
                      "CV/CA discrete white-noise model instead: std of the acceleration (CV) or its increment (CA)")
          .at_least(0),
      ParamSpec::real("singer_alpha", dim::frequency, "singer: inverse correlation time of the acceleration, e.g. 1/s")
          .positive(),
      ParamSpec::real("singer_sigma", dim::acceleration, "singer: standard deviation sigma_m of the acceleration")
          .positive(),
      ParamSpec::choice("range_rate", {"auto", "use", "ignore"},
                        "use the 4th element (range rate): when present (auto), always (use), never (ignore)")
          .def("auto"),
      ParamSpec::choice("init", {"two_point", "explicit", "paper000"},
                        "two-point differencing, the initial_* values, or paper 000's three-point P0 (§IV.2.1)")
          .def("two_point"),
      ParamSpec::real_list("initial_position", dim::length, "init explicit: position (ENU)", 3),
      ParamSpec::real_list("initial_velocity", dim::velocity, "init explicit: velocity", 3).def("[0, 0, 0]"),
      ParamSpec::real_list("initial_acceleration", dim::acceleration, "init explicit, CA/Singer: acceleration", 3)
          .def("[0, 0, 0]"),
      ParamSpec::real("initial_sigma_position", dim::length, "init explicit: position std").positive(),
      ParamSpec::real("initial_sigma_velocity", dim::velocity, "init explicit: velocity std").positive(),
      ParamSpec::real("initial_sigma_acceleration", dim::acceleration,
                      "CA/Singer, two_point or explicit: initial acceleration std (default 50 m/s2; Singer: singer_sigma)")
          .positive(),
  };
  d.create = create;
  r.add(std::move(d));
}

}  // namespace
}  // namespace trackflow

TRACKFLOW_PLUGIN("filter.ekf", trackflow::register_components)
